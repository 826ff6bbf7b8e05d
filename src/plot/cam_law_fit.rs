//! `POST /v1/fit-cam-law`: the fitted law against the data it was fitted to, and the residual.

use plotters::prelude::*;
use serde_json::{Value, json};

use super::style::{SIZE, Series, line_chart};
use super::{PlotError, numbers};

/// Dense curve of the fitted quantity (at least 2001 points, or the data's count).
pub fn prepare(req: &mut Value) {
    let n_data = data_x(req).len() as u64;
    let q = quantity_key(req);
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let outputs = obj.entry("outputs").or_insert_with(|| json!({}));
    if let Some(o) = outputs.as_object_mut() {
        o.insert(
            "curves".to_owned(),
            json!({"count": n_data.clamp(2001, 100_000), "quantities": [q]}),
        );
    }
}

/// `s`, `v`, `a` or `j` for the channel fitted on.
fn quantity_key(req: &Value) -> &'static str {
    match req["fit_on"].as_str().unwrap_or("displacement") {
        "velocity" => "v",
        "acceleration" => "a",
        "jerk" => "j",
        _ => "s",
    }
}

fn data_x(req: &Value) -> Vec<f64> {
    let a = &req["abscissa"];
    if a.get("values").is_some() {
        return numbers(&a["values"]);
    }
    let g = &a["grid"];
    let (Some(s), Some(e), Some(n)) = (g["start"].as_f64(), g["end"].as_f64(), g["count"].as_u64())
    else {
        return Vec::new();
    };
    let n = n.max(2);
    (0..n)
        .map(|i| s + (e - s) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Linear interpolation of `(xs, ys)` at `x` (xs increasing).
fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let i = xs
        .partition_point(|&v| v < x)
        .clamp(1, xs.len().saturating_sub(1).max(1));
    let (x0, x1) = (xs[i - 1], xs[i.min(xs.len() - 1)]);
    let (y0, y1) = (ys[i - 1], ys[i.min(ys.len() - 1)]);
    if x1 > x0 {
        y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    } else {
        y0
    }
}

/// Data and fit on top, residual below.
pub fn render(req: &Value, answer: &Value) -> Result<String, PlotError> {
    let q = quantity_key(req);
    let channel = req["fit_on"].as_str().unwrap_or("displacement");
    let xs = data_x(req);
    let ys = numbers(&req["channels"][channel]);
    let curves = answer.get("curves").ok_or(PlotError::Missing("curves"))?;
    let cx = numbers(&curves["x"]);
    let cy = numbers(&curves[q]);
    if cx.len() < 2 || cy.len() != cx.len() {
        return Err(PlotError::Missing("curves"));
    }
    let xu = req["units"]["x"].as_str().unwrap_or("x");
    let su = req["units"]["s"].as_str().unwrap_or("U");
    let unit = match q {
        "v" => format!("{su}/{xu}"),
        "a" => format!("{su}/{xu}²"),
        "j" => format!("{su}/{xu}³"),
        _ => su.to_owned(),
    };
    let data: Vec<(f64, f64)> = xs.iter().copied().zip(ys.iter().copied()).collect();
    let residual: Vec<(f64, f64)> = data
        .iter()
        .map(|&(x, y)| (x, y - interp(&cx, &cy, x)))
        .collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let (top, bottom) = root.split_vertically(SIZE.1 * 3 / 5);
        line_chart(
            &top,
            &format!("{channel}: data and fitted law"),
            &format!("x [{xu}]"),
            &format!("{q} [{unit}]"),
            &[
                Series {
                    label: "data",
                    points: data,
                },
                Series {
                    label: "fitted law",
                    points: cx.iter().copied().zip(cy.iter().copied()).collect(),
                },
            ],
            &[],
        )?;
        line_chart(
            &bottom,
            "residual: data − fitted law",
            &format!("x [{xu}]"),
            &format!("Δ{q} [{unit}]"),
            &[Series {
                label: "residual",
                points: residual,
            }],
            &[],
        )?;
        root.present()?;
    }
    Ok(svg)
}
