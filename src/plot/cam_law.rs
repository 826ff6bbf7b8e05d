//! `POST /v1/cam-law/evaluate`: displacement, velocity, acceleration and jerk over the rise,
//! one panel each, with the knots of the law marked.

use plotters::prelude::*;
use serde_json::{Value, json};

use super::style::{SIZE, Series, line_chart};
use super::{PlotError, numbers};

/// Samples of a picture.
const SAMPLES: u64 = 601;

/// A dense grid over the law's interval and all four quantities.
pub fn prepare(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let given = obj
        .get("abscissa")
        .map(|a| {
            let mut v = numbers(&a["values"]);
            v.extend(a["grid"]["start"].as_f64());
            v.extend(a["grid"]["end"].as_f64());
            v
        })
        .unwrap_or_default();
    let lo = obj["constraints"]["t_a"]
        .as_f64()
        .or_else(|| given.iter().copied().reduce(f64::min))
        .unwrap_or(0.0);
    let hi = obj["constraints"]["t_b"]
        .as_f64()
        .or_else(|| given.iter().copied().reduce(f64::max))
        .unwrap_or(1.0);
    obj.insert(
        "abscissa".to_owned(),
        json!({"grid": {"start": lo, "end": hi, "count": SAMPLES}}),
    );
    obj.insert("quantities".to_owned(), json!(["s", "v", "a", "j"]));
}

/// Four stacked panels; units from the request's labels when given.
pub fn render(req: &Value, answer: &Value) -> Result<String, PlotError> {
    let curves = answer.get("curves").ok_or(PlotError::Missing("curves"))?;
    let x = numbers(&curves["x"]);
    let xu = req["units"]["x"].as_str().unwrap_or("x");
    let su = req["units"]["s"].as_str().unwrap_or("U");
    let knots: Vec<f64> = answer["knots"]
        .as_array()
        .map(|k| k.iter().filter_map(|k| k["x"].as_f64()).collect())
        .unwrap_or_default();
    let panels = [
        ("s", "displacement s", su.to_owned(), "s"),
        ("v", "velocity v", format!("{su}/{xu}"), "v"),
        ("a", "acceleration a", format!("{su}/{xu}²"), "a_right"),
        ("j", "jerk j", format!("{su}/{xu}³"), ""),
    ];
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, SIZE.1 + 380)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((4, 1));
        for (area, (key, name, unit, knot_key)) in areas.iter().zip(panels) {
            let y = numbers(&curves[key]);
            let pts: Vec<(f64, f64)> = x.iter().copied().zip(y).collect();
            let marks: Vec<(f64, f64)> = if knot_key.is_empty() {
                Vec::new()
            } else {
                answer["knots"]
                    .as_array()
                    .map(|k| {
                        k.iter()
                            .filter_map(|k| Some((k["x"].as_f64()?, k[knot_key].as_f64()?)))
                            .collect()
                    })
                    .unwrap_or_default()
            };
            line_chart(
                area,
                &format!("{name} (knots marked: {})", knots.len()),
                &format!("x [{xu}]"),
                &format!("{key} [{unit}]"),
                &[Series {
                    label: name,
                    points: pts,
                }],
                &marks,
            )?;
        }
        root.present()?;
    }
    Ok(svg)
}
