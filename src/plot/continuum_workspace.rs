//! Continuum manipulator pictures: the rods' shapes of a forward-kinematics solution, and a
//! workspace map coloured by the platform's parasitic angle with the unstable nodes marked.

use plotters::prelude::*;
use serde_json::{Value, json};

use std::ops::Range;

use super::style::{
    Area, Chart, SIZE, colour, framed_chart, legend_box, picture, ramp_legend, range, sequential,
};
use super::{PlotError, numbers};

/// Rod shapes for FK, nodes for a workspace sweep.
pub fn prepare(req: &mut Value) {
    let mode = req["mode"].as_str().unwrap_or("fk").to_owned();
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    match mode.as_str() {
        "workspace" => {
            if let Some(w) = obj.get_mut("workspace").and_then(Value::as_object_mut) {
                w.insert("return_nodes".to_owned(), json!(true));
            }
        }
        "fk" => {
            let outputs = obj.entry("outputs").or_insert_with(|| json!({}));
            if let Some(o) = outputs.as_object_mut() {
                o.insert("rod_shape_points".to_owned(), json!(60));
            }
        }
        _ => {}
    }
}

/// By mode.
pub fn render(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    match answer["mode"].as_str() {
        Some("workspace") => workspace(answer),
        Some("fk") => fk(answer),
        _ => modes(answer),
    }
}

fn equal_axes(points: &[(f64, f64)]) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let xr = range(points.iter().map(|p| p.0));
    let yr = range(points.iter().map(|p| p.1));
    let span = (xr.end - xr.start).max(yr.end - yr.start);
    let (cx, cy) = (0.5 * (xr.start + xr.end), 0.5 * (yr.start + yr.end));
    (
        (cx - 0.5 * span)..(cx + 0.5 * span),
        (cy - 0.5 * span)..(cy + 0.5 * span),
    )
}

fn fk(answer: &Value) -> Result<String, PlotError> {
    let rods = answer["rods"]
        .as_array()
        .ok_or(PlotError::Missing("rods"))?;
    let shapes: Vec<Vec<(f64, f64)>> = rods
        .iter()
        .map(|r| {
            r["shape"]
                .as_array()
                .map(|s| {
                    s.iter()
                        .filter_map(|p| Some((p.get(0)?.as_f64()?, p.get(1)?.as_f64()?)))
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    if shapes.iter().all(Vec::is_empty) {
        return Err(PlotError::Missing("rods/shape"));
    }
    let platform = numbers(&answer["platform"]["position_m"]);
    let all: Vec<(f64, f64)> = shapes.iter().flatten().copied().collect();
    let (xr, yr) = equal_axes(&all);
    picture((SIZE.1 + 60, SIZE.1), |root| {
        let caption = format!(
            "rod shapes; platform parasitic angle {:.3} deg",
            answer["platform"]["parasitic_angle_deg"]
                .as_f64()
                .unwrap_or(f64::NAN)
        );
        let mut chart = framed(root, &caption, (xr, yr), ("x [m]", "y [m]"))?;
        for (i, s) in shapes.iter().enumerate() {
            let c = colour(i);
            chart
                .draw_series(LineSeries::new(s.iter().copied(), c.stroke_width(3)))?
                .label(format!("rod {}", i + 1))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(3))
                });
        }
        if let [px, py] = platform[..] {
            chart.draw_series([TriangleMarker::new((px, py), 8, colour(6).filled())])?;
        }
        legend_box(&mut chart, 0.85)
    })
}

/// A chart in `area` with the frame of the workspace pictures: `caption`, the axes' ranges and
/// descriptions, a light grid.
fn framed<'a, 'b>(
    area: &'a Area<'b>,
    caption: &str,
    ranges: (Range<f64>, Range<f64>),
    descs: (&str, &str),
) -> Result<Chart<'a, 'b>, PlotError> {
    framed_chart(area, (caption, 15), (8, 60), ranges, descs)
}

/// The nodes of the answer's first wave: at the top level, or the first of `waves` in a
/// sharded answer.
fn workspace(answer: &Value) -> Result<String, PlotError> {
    let nodes = match answer.get("nodes") {
        Some(n) => n,
        None => &answer["waves"][0]["nodes"],
    };
    let px = numbers(&nodes["px_m"]);
    let py = numbers(&nodes["py_m"]);
    let ang = numbers(&nodes["parasitic_angle_deg"]);
    let status: Vec<&str> = nodes["status"]
        .as_array()
        .ok_or(PlotError::Missing("nodes"))?
        .iter()
        .map(|s| s.as_str().unwrap_or(""))
        .collect();
    let ok: Vec<(f64, f64, f64)> = (0..px.len().min(py.len()).min(ang.len()).min(status.len()))
        .filter(|&i| status[i] == "ok")
        .map(|i| (px[i], py[i], ang[i]))
        .collect();
    let unstable: Vec<(f64, f64)> = (0..px.len().min(py.len()).min(status.len()))
        .filter(|&i| status[i].contains("unstable") && px[i].is_finite() && py[i].is_finite())
        .map(|i| (px[i], py[i]))
        .collect();
    let pts: Vec<(f64, f64)> = ok
        .iter()
        .map(|p| (p.0, p.1))
        .chain(unstable.iter().copied())
        .collect();
    if pts.is_empty() {
        return Err(PlotError::Missing("nodes"));
    }
    let (xr, yr) = equal_axes(&pts);
    let amax = ok.iter().map(|p| p.2.abs()).fold(0.0, f64::max).max(1e-12);
    picture((SIZE.1 + 200, SIZE.1), |root| {
        let (plot, legend) = root.split_horizontally(SIZE.1 + 60);
        let mut chart = framed(
            &plot,
            "workspace: platform positions coloured by |parasitic angle|",
            (xr, yr),
            ("platform x [m]", "platform y [m]"),
        )?;
        chart.draw_series(
            ok.iter()
                .map(|&(x, y, a)| Circle::new((x, y), 3, sequential(a.abs() / amax).filled())),
        )?;
        chart
            .draw_series(
                unstable
                    .iter()
                    .map(|&p| Cross::new(p, 4, colour(1).stroke_width(2))),
            )?
            .label("unstable (beyond the stability boundary)")
            .legend(|(x, y)| Cross::new((x + 6, y), 4, colour(1).stroke_width(2)));
        legend_box(&mut chart, 0.85)?;
        ramp_legend(&legend, "|parasitic angle| [deg]", |t| {
            format!("{:.3}", t * amax)
        })
    })
}

/// Assembly modes: each solution's parasitic angle against its stability margin, stable ones
/// filled.
fn modes(answer: &Value) -> Result<String, PlotError> {
    let sols = answer["solutions"]
        .as_array()
        .ok_or(PlotError::Missing("solutions"))?;
    let pts: Vec<(f64, f64, bool)> = sols
        .iter()
        .filter_map(|s| {
            Some((
                s["parasitic_angle_deg"].as_f64()?,
                s["margin"].as_f64().unwrap_or(0.0),
                s["stable"].as_bool().unwrap_or(false),
            ))
        })
        .collect();
    if pts.is_empty() {
        return Err(PlotError::Missing("solutions"));
    }
    let xr = range(pts.iter().map(|p| p.0));
    let yr = range(pts.iter().map(|p| p.1).chain([0.0]));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "assembly modes at one actuator input (filled: stable)",
                ("sans-serif", 15),
            )
            .margin(8)
            .x_label_area_size(34)
            .y_label_area_size(60)
            .build_cartesian_2d(xr, yr)?;
        chart
            .configure_mesh()
            .x_desc("platform parasitic angle [deg]")
            .y_desc("stability margin [-]")
            .draw()?;
        chart.draw_series(pts.iter().map(|&(a, m, stable)| {
            Circle::new(
                (a, m),
                6,
                if stable {
                    colour(0).filled()
                } else {
                    colour(1).stroke_width(2)
                },
            )
        }))?;
        root.present()?;
    }
    Ok(svg)
}
