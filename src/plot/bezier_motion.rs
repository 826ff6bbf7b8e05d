//! `POST /v1/bezier-motion-law`: the motion law over the move and the residual vibration of the
//! compliant drive after it.

use serde_json::{Value, json};

use super::style::{Series, line_chart, top_and_bottom};
use super::{PlotError, numbers};

/// A time history over the move and half the move's duration after it, unless the request asks
/// for one itself.
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
}

/// Top: the law φ(t) in rad; bottom: the platform lag ψ(t) = β − zφ in rad, during and after the move.
pub fn render(_req: &Value, answer: &Value) -> Result<String, PlotError> {
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
