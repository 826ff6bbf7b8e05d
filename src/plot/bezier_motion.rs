//! `POST /v1/bezier-motion-law`: the motion law over the move and the residual vibration of the
//! compliant drive after it.

use serde_json::{Value, json};

use super::style::{Series, line_chart, top_and_bottom};
use super::{PlotError, numbers};
use crate::calc::bezier_motion::law::de_casteljau;
use crate::calc::bezier_motion::shaper::{Baseline, Impulse, ShapedMove};

/// Stiffness factors the picture of a shaper comparison sweeps when the request gives none.
const PICTURE_FACTORS: usize = 41;
/// Samples of the motor accelerations in the shaper picture.
const ACCEL_SAMPLES: usize = 600;
/// Decades shown below the largest residual energy (ZV/ZVD reach round-off at the design point).
const DECADES: f64 = 16.0;

/// A time history over the move and half the move's duration after it, unless the request asks
/// for one itself; with a shaper comparison, a stiffness sweep over ±20 % unless one is given.
pub fn prepare(req: &mut Value) {
    let t = req["motion"]["T_s"].as_f64().unwrap_or(1.0);
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let outputs = obj.entry("outputs").or_insert_with(|| json!({}));
    if !outputs.is_object() {
        *outputs = json!({});
    }
    if let Some(o) = outputs.as_object_mut()
        && o.get("time_history").is_none_or(Value::is_null)
    {
        o.insert(
            "time_history".to_owned(),
            json!({"n_samples": 400, "t_after_s": 0.5 * t, "n_after": 200}),
        );
    }
    if let Some(o) = outputs.as_object_mut()
        && o.get("shaper_comparison").is_some_and(|v| !v.is_null())
        && o.get("sensitivity").is_none_or(Value::is_null)
    {
        let factors: Vec<f64> = (0..PICTURE_FACTORS)
            .map(|i| 0.8 + 0.4 * i as f64 / (PICTURE_FACTORS - 1) as f64)
            .collect();
        o.insert(
            "sensitivity".to_owned(),
            json!({"stiffness_factors": factors}),
        );
    }
}

/// Top: log10 of the residual energy against the stiffness factor for every shaper and the
/// Bezier law; bottom: their motor accelerations overlaid.
fn render_shapers(req: &Value, answer: &Value, sc: &Value) -> Result<String, PlotError> {
    let t_end = req["motion"]["T_s"].as_f64().unwrap_or(1.0);
    let phi = numbers(&answer["law"]["S_rad"])
        .last()
        .copied()
        .unwrap_or(0.0);
    let baseline = if sc["baseline"].as_str() == Some("cycloidal") {
        Baseline::Cycloidal
    } else {
        Baseline::Trapezoid
    };
    let sweep = |row: &Value| -> Vec<(f64, f64)> {
        row["sensitivity"]
            .as_array()
            .map(|v| {
                v.iter()
                    .filter_map(|p| Some((p["factor"].as_f64()?, p["E_T_J"].as_f64()?)))
                    .collect()
            })
            .unwrap_or_default()
    };
    let mut energies: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    let mut accels: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    let times: Vec<f64> = (0..=ACCEL_SAMPLES)
        .map(|i| t_end * i as f64 / ACCEL_SAMPLES as f64)
        .collect();
    for row in sc["rows"].as_array().into_iter().flatten() {
        let Some(name) = row["shaper"].as_str() else {
            continue;
        };
        energies.push((name.to_owned(), sweep(row)));
        let motion = ShapedMove {
            baseline,
            phi,
            t0: row["baseline_time_s"].as_f64().unwrap_or(t_end),
            impulses: row["impulses"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|i| {
                    Some(Impulse {
                        t: i["t_s"].as_f64()?,
                        amplitude: i["amplitude"].as_f64()?,
                    })
                })
                .collect(),
        };
        accels.push((
            name.to_owned(),
            times.iter().map(|&t| (t, motion.at(t).0)).collect(),
        ));
    }
    energies.push(("bezier".to_owned(), sweep(&sc["bezier"])));
    let a = numbers(&answer["law"]["A_rad_s2"]);
    accels.push((
        "bezier".to_owned(),
        times
            .iter()
            .map(|&t| (t, de_casteljau(&a, (t / t_end).clamp(0.0, 1.0))))
            .collect(),
    ));
    let top = energies
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .fold(0.0_f64, f64::max);
    let floor = top.log10() - DECADES;
    let logged: Vec<(String, Vec<(f64, f64)>)> = energies
        .into_iter()
        .map(|(l, p)| {
            let q = p
                .into_iter()
                .map(|(f, e)| (f, if e > 0.0 { e.log10().max(floor) } else { floor }))
                .collect();
            (l, q)
        })
        .collect();
    top_and_bottom(|upper, lower| {
        line_chart(
            upper,
            "residual vibration energy against stiffness error",
            "stiffness factor k/k_nominal",
            "log10 E(T) [J]",
            &Series::labelled(&logged),
            &[],
        )?;
        line_chart(
            lower,
            "motor acceleration: shaped baselines and the Bezier law",
            "time t [s]",
            "acceleration [rad/s²]",
            &Series::labelled(&accels),
            &[],
        )
    })
}

/// Top: the law φ(t) in rad; bottom: the platform lag ψ(t) = β − zφ in rad, during and after the move.
/// With a shaper comparison in the answer: the comparison picture instead.
pub fn render(req: &Value, answer: &Value) -> Result<String, PlotError> {
    let sc = &answer["shaper_comparison"];
    if sc.is_object() {
        return render_shapers(req, answer, sc);
    }
    let th = &answer["time_history"];
    let t = numbers(&th["t_s"]);
    if t.is_empty() {
        return Err(PlotError::Missing("time_history"));
    }
    let pair =
        |key: &str| -> Vec<(f64, f64)> { t.iter().copied().zip(numbers(&th[key])).collect() };
    top_and_bottom(|top, bottom| {
        line_chart(
            top,
            "Bezier motion law: motor angle",
            "time t [s]",
            "angle φ [rad]",
            &[Series {
                label: "φ(t)",
                points: pair("phi_rad"),
            }],
            &[],
        )?;
        line_chart(
            bottom,
            "residual vibration: platform lag behind the rigid law",
            "time t [s]",
            "lag ψ = β − zφ [rad]",
            &[Series {
                label: "ψ(t)",
                points: pair("psi_rad"),
            }],
            &[],
        )
    })
}
