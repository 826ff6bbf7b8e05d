//! The house style of every picture: size, palette, axis ranges and the common line chart.

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::PlotError;

/// Okabe–Ito colours (distinguishable with every common colour-vision deficiency), in the order
/// series use them.
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
];

/// Colour of series `i`.
#[must_use]
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Picture size \[px\].
pub const SIZE: (u32, u32) = (900, 620);

/// A padded range covering `values` (a unit range around a constant; finite values only).
#[must_use]
pub fn range(values: impl IntoIterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1.0)
    };
    (lo - pad)..(hi + pad)
}

/// One series of a line chart.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Points.
    pub points: Vec<(f64, f64)>,
}

impl<'a> Series<'a> {
    /// Series of labelled point lists (each list cloned).
    #[must_use]
    pub fn labelled(owned: &'a [(String, Vec<(f64, f64)>)]) -> Vec<Self> {
        owned
            .iter()
            .map(|(l, p)| Series {
                label: l,
                points: p.clone(),
            })
            .collect()
    }
}

/// A drawing area of an SVG picture.
pub type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// A chart on f64 × f64 axes in an SVG picture.
pub type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A picture of `size` pixels on white, drawn by `draw` on its whole area.
///
/// # Errors
/// What `draw` or the backend returns.
pub fn picture(
    size: (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> Result<(), PlotError>,
) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(svg)
}

/// A picture of [`SIZE`] in two equal panels, drawn by `draw(top, bottom)`.
///
/// # Errors
/// What `draw` or the backend returns.
pub fn top_and_bottom(
    draw: impl FnOnce(&Area<'_>, &Area<'_>) -> Result<(), PlotError>,
) -> Result<String, PlotError> {
    picture(SIZE, |root| {
        let (top, bottom) = root.split_vertically(SIZE.1 / 2);
        draw(&top, &bottom)
    })
}

/// Draws the series legend of `chart` in a grey-bordered white box, `opacity` of it opaque.
///
/// # Errors
/// What the backend returns.
pub fn legend_box<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, opacity: f64) -> Result<(), PlotError> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(opacity))
        .border_style(RGBColor(200, 200, 200))
        .draw()?;
    Ok(())
}

/// A colour-ramp legend in `area`: `title` above five steps of [`sequential`] from t = 0 to 1,
/// each labelled `label(t)`.
///
/// # Errors
/// What the backend returns.
pub fn ramp_legend(
    area: &Area<'_>,
    title: &str,
    label: impl Fn(f64) -> String,
) -> Result<(), PlotError> {
    let legend = area.margin(40, 40, 10, 10);
    legend.draw(&Text::new(
        title.to_owned(),
        (0, 0),
        ("sans-serif", 12).into_font(),
    ))?;
    for k in 0..5 {
        let t = f64::from(k) / 4.0;
        let y = 24 + (4 - k) * 28;
        legend.draw(&Rectangle::new(
            [(0, y), (20, y + 20)],
            sequential(t).filled(),
        ))?;
        legend.draw(&Text::new(
            label(t),
            (26, y + 4),
            ("sans-serif", 11).into_font(),
        ))?;
    }
    Ok(())
}

/// An f64 × f64 chart in `area` in the house frame: the caption `(text, font size)`, the
/// `(margin, y label area)` in pixels (the x label area is 34 px), the axes' ranges and
/// descriptions (quantity [unit]), a light grid.
///
/// # Errors
/// What the backend returns.
pub fn framed_chart<'a, 'b>(
    area: &'a Area<'b>,
    (caption, caption_px): (&str, u32),
    (margin, y_label_px): (u32, u32),
    (xr, yr): (std::ops::Range<f64>, std::ops::Range<f64>),
    (x_desc, y_desc): (&str, &str),
) -> Result<Chart<'a, 'b>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", caption_px))
        .margin(margin)
        .x_label_area_size(34)
        .y_label_area_size(y_label_px)
        .build_cartesian_2d(xr, yr)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    Ok(chart)
}

/// A line chart in `area` with axis descriptions (quantity [unit]), series in palette order and
/// optional marker points (drawn as circles, e.g. knots).
pub fn line_chart(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[Series<'_>],
    markers: &[(f64, f64)],
) -> Result<(), PlotError> {
    let xs = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let ys = range(
        series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .chain(markers.iter().map(|m| m.1)),
    );
    let mut chart = framed_chart(area, (title, 15), (6, 64), (xs, ys), (x_desc, y_desc))?;
    for (i, s) in series.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(s.points.iter().copied(), c.stroke_width(2)))?
            .label(s.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2)));
    }
    if !markers.is_empty() {
        chart.draw_series(
            markers
                .iter()
                .map(|&(x, y)| Circle::new((x, y), 3, colour(6).filled())),
        )?;
    }
    if series.len() > 1 {
        legend_box(&mut chart, 0.8)?;
    }
    Ok(())
}

/// A sequential colour map for values in [0, 1] (cividis: perceptually uniform and readable with
/// every common colour-vision deficiency), by linear interpolation between its stops.
#[must_use]
pub fn sequential(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 9] = [
        (0, 34, 78),
        (35, 62, 108),
        (76, 85, 107),
        (108, 109, 114),
        (138, 135, 121),
        (168, 162, 116),
        (201, 190, 104),
        (234, 220, 78),
        (254, 232, 56),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let lerp = |a: u8, b: u8| (f64::from(a) + f * (f64::from(b) - f64::from(a))).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    RGBColor(lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2))
}

/// A scalar field on a rectangular grid: cells coloured by value (NaN cells light grey), with a
/// colour legend of five labelled steps on the right.
pub struct HeatMap<'a> {
    /// Title.
    pub title: &'a str,
    /// Axis descriptions (quantity [unit]).
    pub x_desc: &'a str,
    /// Axis descriptions (quantity [unit]).
    pub y_desc: &'a str,
    /// Value description (quantity [unit]).
    pub z_desc: &'a str,
    /// Cell centres along x.
    pub x: Vec<f64>,
    /// Cell centres along y.
    pub y: Vec<f64>,
    /// Values, `z[ix][iy]` (NaN = no value).
    pub z: Vec<Vec<f64>>,
    /// Colour by the logarithm of the value (positive values spanning decades).
    pub log_scale: bool,
}

fn edges(c: &[f64]) -> Vec<f64> {
    match c.len() {
        0 => vec![0.0, 1.0],
        1 => vec![c[0] - 0.5, c[0] + 0.5],
        n => {
            let mut e = Vec::with_capacity(n + 1);
            e.push(c[0] - 0.5 * (c[1] - c[0]));
            for w in c.windows(2) {
                e.push(0.5 * (w[0] + w[1]));
            }
            e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
            e
        }
    }
}

/// Draw a heat map into `area`; extra series (an envelope, operating points) can be drawn on the
/// returned chart's coordinates by the caller through `overlay`.
pub fn heat_map(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    map: &HeatMap<'_>,
    overlay: impl FnOnce(&mut Chart<'_, '_>) -> Result<(), PlotError>,
) -> Result<(), PlotError> {
    let (plot, legend) = area.split_horizontally(area.dim_in_pixel().0.saturating_sub(150));
    let xe = edges(&map.x);
    let ye = edges(&map.y);
    let (zlo, zhi) = map
        .z
        .iter()
        .flatten()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let log = map.log_scale && zlo > 0.0;
    let tr = |v: f64| if log { v.ln() } else { v };
    let untr = |v: f64| if log { v.exp() } else { v };
    let (tlo, thi) = (tr(zlo), tr(zhi));
    let norm = |v: f64| {
        if thi > tlo {
            (tr(v) - tlo) / (thi - tlo)
        } else {
            0.5
        }
    };
    let mut chart = ChartBuilder::on(&plot)
        .caption(map.title, ("sans-serif", 15))
        .margin(6)
        .x_label_area_size(34)
        .y_label_area_size(64)
        .build_cartesian_2d(
            xe[0]..xe[xe.len() - 1],
            ye[0].min(ye[ye.len() - 1])..ye[0].max(ye[ye.len() - 1]),
        )?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(map.x_desc)
        .y_desc(map.y_desc)
        .draw()?;
    let mut cells = Vec::new();
    for (ix, col) in map.z.iter().enumerate() {
        for (iy, &v) in col.iter().enumerate() {
            if ix + 1 >= xe.len() || iy + 1 >= ye.len() {
                continue;
            }
            let fill = if v.is_finite() {
                sequential(norm(v)).filled()
            } else {
                RGBColor(225, 225, 225).filled()
            };
            cells.push(Rectangle::new(
                [(xe[ix], ye[iy]), (xe[ix + 1], ye[iy + 1])],
                fill,
            ));
        }
    }
    chart.draw_series(cells)?;
    overlay(&mut chart)?;
    // Legend: five steps from the lowest to the highest value.
    ramp_legend(&legend, map.z_desc, |t| {
        let v = untr(tlo + t * (thi - tlo));
        if v.is_finite() {
            format!("{v:.4}")
        } else {
            "—".to_owned()
        }
    })
}

/// Bars of `values` (one per label) in `area`, labels under the bars.
pub fn bar_chart(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    y_desc: &str,
    labels: &[String],
    groups: &[(&str, Vec<f64>)],
) -> Result<(), PlotError> {
    let n = labels.len().max(1);
    let ys = range(groups.iter().flat_map(|g| g.1.iter().copied()).chain([0.0]));
    let lab = labels.to_vec();
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 15))
        .margin(6)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), ys)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n)
        .x_label_formatter(&move |x| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 {
                lab.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .y_desc(y_desc)
        .draw()?;
    let g = groups.len().max(1) as f64;
    let w = 0.8 / g;
    for (k, (name, vals)) in groups.iter().enumerate() {
        let c = colour(k);
        let x0 = -0.4 + w * k as f64;
        chart
            .draw_series(vals.iter().enumerate().map(|(i, &v)| {
                let x = i as f64 + x0;
                Rectangle::new([(x, 0.0), (x + w * 0.95, v)], c.filled())
            }))?
            .label(*name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled()));
    }
    if groups.len() > 1 {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(200, 200, 200))
            .draw()?;
    }
    Ok(())
}
