//! `POST /v1/spatial-coupling`: output angle θ2 and the relative rotations θ31, θ32 over θ1 (top),
//! transmission ratio i12 over θ1 with the Cardan bounds ∓cos 2α, ∓1/cos 2α (bottom).

use plotters::prelude::*;
use serde_json::{Value, json};

use super::PlotError;
use super::style::{SIZE, Series, line_chart};

/// Most points drawn per curve (longer sweeps are decimated for the picture).
const MAX_DRAWN: u64 = 1000;

/// A sweep (the request's, else one revolution) with its series and both relative groups.
pub fn prepare(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let sweep = obj
        .entry("sweep")
        .or_insert_with(|| json!({"start_deg": 0, "end_deg": 360, "n_points": 721}));
    let n = sweep["n_points"].as_u64().unwrap_or(721);
    let outputs = obj.entry("outputs").or_insert_with(|| json!({}));
    if let Some(o) = outputs.as_object_mut() {
        o.insert("series".to_owned(), json!(true));
        o.insert("relative_1".to_owned(), json!(true));
        o.insert("relative_2".to_owned(), json!(true));
        o.insert("decimate".to_owned(), json!(n.div_ceil(MAX_DRAWN).max(1)));
    }
}

fn curve(series: &[Value], f: impl Fn(&Value) -> Option<f64>) -> Vec<(f64, f64)> {
    series
        .iter()
        .filter_map(|p| Some((p["theta1_deg"].as_f64()?, f(p)?)))
        .collect()
}

/// Two stacked panels over the sweep's θ1.
pub fn render(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let series = answer["series"]
        .as_array()
        .ok_or(PlotError::Missing("series"))?;
    let bounds = &answer["configuration"]["ratio_range_abs"];
    let sign = answer["configuration"]["i12_mean"].as_f64().unwrap_or(-1.0);
    let theta = [
        Series {
            label: "θ2 output shaft",
            points: curve(series, |p| p["theta2_deg"].as_f64()),
        },
        Series {
            label: "θ31 body 3 rel. shaft 1",
            points: curve(series, |p| p["relative_1"]["theta31_deg"].as_f64()),
        },
        Series {
            label: "θ32 body 3 rel. shaft 2",
            points: curve(series, |p| p["relative_2"]["theta32_deg"].as_f64()),
        },
    ];
    let i12 = curve(series, |p| p["i12"].as_f64());
    let (x0, x1) = (
        i12.first().map_or(0.0, |p| p.0),
        i12.last().map_or(360.0, |p| p.0),
    );
    let level = |k: usize, label: &'static str| Series {
        label,
        points: bounds[k]
            .as_f64()
            .map(|b| vec![(x0, sign * b), (x1, sign * b)])
            .unwrap_or_default(),
    };
    let ratio = [
        Series {
            label: "i12 = ω2/ω1",
            points: i12.clone(),
        },
        level(0, "Cardan bound |cos 2α|"),
        level(1, "Cardan bound 1/|cos 2α|"),
    ];
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, SIZE.1 + 200)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((2, 1));
        line_chart(
            &areas[0],
            "RP1PR coupling: output angle and relative rotations of body 3",
            "input angle θ1 [deg]",
            "angle [deg]",
            &theta,
            &[],
        )?;
        line_chart(
            &areas[1],
            "transmission ratio (Hooke-joint law, bend 2α)",
            "input angle θ1 [deg]",
            "i12 [–]",
            &ratio,
            &[],
        )?;
        root.present()?;
    }
    Ok(svg)
}
