//! IREFC pictures: one design's force and contact stresses over the mesh cycle φ2, a design
//! sweep's maximum stress over (Z2, χ), and the efficiency's per-element losses.

use plotters::prelude::*;
use serde_json::{Value, json};

use super::style::{HeatMap, SIZE, Series, heat_map, line_chart, top_and_bottom};
use super::{PlotError, numbers};

/// Curves on for a single design.
pub fn prepare_stress(req: &mut Value) {
    if req["mode"].as_str() == Some("sweep") {
        return;
    }
    if let Some(obj) = req.as_object_mut() {
        let include = obj.entry("include").or_insert_with(|| json!({}));
        if let Some(i) = include.as_object_mut() {
            i.insert("curves".to_owned(), json!(true));
        }
    }
}

/// Single design: F over φ2 and both contact stresses; sweep: heat map of the maximum stress.
pub fn render_stress(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    if answer["mode"].as_str() == Some("sweep") {
        return sweep(answer);
    }
    let c = answer.get("curves").ok_or(PlotError::Missing("curves"))?;
    let phi = numbers(&c["phi2_deg"]);
    let zip =
        |key: &str| -> Vec<(f64, f64)> { phi.iter().copied().zip(numbers(&c[key])).collect() };
    top_and_bottom(|top, bottom| {
        line_chart(
            top,
            "rolling-element force over the mesh cycle",
            "φ2 [deg]",
            "F [N]",
            &[Series {
                label: "F",
                points: zip("F_N"),
            }],
            &[],
        )?;
        line_chart(
            bottom,
            "Hertz contact stress",
            "φ2 [deg]",
            "σ [MPa]",
            &[
                Series {
                    label: "cam contact",
                    points: zip("sigma_cam_MPa"),
                },
                Series {
                    label: "crown contact",
                    points: zip("sigma_crown_MPa"),
                },
            ],
            &[],
        )
    })
}

/// The lowest maximum stress over the other swept parameters, per (Z2, χ).
fn sweep(answer: &Value) -> Result<String, PlotError> {
    let records = answer["records"]
        .as_array()
        .ok_or(PlotError::Missing("records"))?;
    let mut z2: Vec<f64> = records.iter().filter_map(|r| r["Z2"].as_f64()).collect();
    let mut chi: Vec<f64> = records.iter().filter_map(|r| r["chi"].as_f64()).collect();
    for v in [&mut z2, &mut chi] {
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs().max(1.0));
    }
    let mut z = vec![vec![f64::NAN; chi.len()]; z2.len()];
    for r in records {
        let (Some(a), Some(b), Some(s)) = (
            r["Z2"].as_f64(),
            r["chi"].as_f64(),
            r["sigma_max_MPa"].as_f64(),
        ) else {
            continue;
        };
        let ia = z2.partition_point(|&v| v < a - 1e-9);
        let ib = chi.partition_point(|&v| v < b - 1e-9);
        if let Some(cell) = z.get_mut(ia).and_then(|c| c.get_mut(ib)) {
            *cell = if cell.is_nan() { s } else { cell.min(s) };
        }
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        heat_map(
            &root,
            &HeatMap {
                title: "maximum contact stress over the sweep (log colour scale; grey: invalid design)",
                x_desc: "Z2 [teeth]",
                y_desc: "χ [-]",
                z_desc: "σ max [MPa]",
                x: z2,
                y: chi,
                z,
                log_scale: true,
            },
            |_| Ok(()),
        )?;
        root.present()?;
    }
    Ok(svg)
}

/// Nothing to turn on: the elements are always returned.
pub fn prepare_efficiency(_req: &mut Value) {}

/// Per-element efficiency and sliding loss over φ2.
pub fn render_efficiency(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let el = answer["elements"]
        .as_array()
        .ok_or(PlotError::Missing("elements"))?;
    let pts = |key: &str| -> Vec<(f64, f64)> {
        el.iter()
            .filter_map(|e| Some((e["phi2_deg"].as_f64()?, e[key].as_f64()?)))
            .collect()
    };
    top_and_bottom(|top, bottom| {
        line_chart(
            top,
            "per-element efficiency over the mesh cycle",
            "φ2 [deg]",
            "η_k [-]",
            &[Series {
                label: "η_k",
                points: pts("eta_k"),
            }],
            &[],
        )?;
        line_chart(
            bottom,
            "per-element sliding loss",
            "φ2 [deg]",
            "N_S [W]",
            &[Series {
                label: "N_S",
                points: pts("NS_W"),
            }],
            &[],
        )
    })
}
