//! `POST /v1/cognates`: the original and its two cognates drawn in the pose of the request, their
//! ground pivots, and the coupler curve all three trace, at equal scale on both axes.

use plotters::prelude::*;
use serde_json::{Value, json};

use super::style::{SIZE, colour, framed_chart, legend_box, range};
use super::{PlotError, points};

/// Curves on (the picture's subject), at the requested density or 360 points per circuit.
pub fn prepare(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let options = obj.entry("options").or_insert_with(|| json!({}));
    if let Some(o) = options.as_object_mut() {
        o.insert("curves".to_owned(), json!(true));
        o.entry("points_per_circuit").or_insert(json!(360));
    }
}

fn joint(j: &Value, name: &str) -> Option<(f64, f64)> {
    let p = &j[name];
    Some((p.get(0)?.as_f64()?, p.get(1)?.as_f64()?))
}

/// Linkages, pivots and the common coupler curve.
pub fn render(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let mechs = answer["mechanisms"]
        .as_array()
        .ok_or(PlotError::Missing("mechanisms"))?;
    let curves: Vec<Vec<(f64, f64)>> = mechs
        .first()
        .and_then(|m| m["curves"].as_array())
        .map(|c| c.iter().map(|c| points(&c["points"])).collect())
        .unwrap_or_default();
    let poses: Vec<Vec<(f64, f64)>> = mechs
        .iter()
        .map(|m| {
            let j = &m["snapshot"]["joints"];
            [
                "input_pivot",
                "crank_joint",
                "P",
                "rocker_joint",
                "output_pivot",
            ]
            .iter()
            .filter_map(|n| joint(j, n))
            .collect()
        })
        .collect();
    let pivots: Vec<(f64, f64)> = mechs
        .iter()
        .flat_map(|m| [points(&json!([m["input_pivot"], m["output_pivot"]]))])
        .flatten()
        .collect();
    // Equal scale: one span for both axes.
    let all: Vec<(f64, f64)> = curves
        .iter()
        .flatten()
        .chain(poses.iter().flatten())
        .chain(pivots.iter())
        .copied()
        .collect();
    let xr = range(all.iter().map(|p| p.0));
    let yr = range(all.iter().map(|p| p.1));
    let span = (xr.end - xr.start).max(yr.end - yr.start);
    let (cx, cy) = (0.5 * (xr.start + xr.end), 0.5 * (yr.start + yr.end));
    let side = SIZE.1;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (side + 60, side)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = framed_chart(
            &root,
            (
                "Roberts–Chebyshev cognates: one coupler curve, three four-bars",
                16,
            ),
            (8, 56),
            (
                (cx - 0.5 * span)..(cx + 0.5 * span),
                (cy - 0.5 * span)..(cy + 0.5 * span),
            ),
            (
                "x [length unit of the request]",
                "y [length unit of the request]",
            ),
        )?;
        for c in &curves {
            chart
                .draw_series(LineSeries::new(
                    c.iter().copied(),
                    colour(6).stroke_width(1),
                ))?
                .label("coupler curve (all three)")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour(6)));
        }
        let names = ["original", "cognate 1", "cognate 2"];
        for (i, pose) in poses.iter().enumerate() {
            let c = colour(i);
            chart
                .draw_series(LineSeries::new(pose.iter().copied(), c.stroke_width(3)))?
                .label(names.get(i).copied().unwrap_or("mechanism"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(3))
                });
            chart.draw_series(pose.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
        }
        chart.draw_series(
            pivots
                .iter()
                .map(|&p| TriangleMarker::new(p, 8, colour(6).filled())),
        )?;
        legend_box(&mut chart, 0.85)?;
        root.present()?;
    }
    Ok(svg)
}
