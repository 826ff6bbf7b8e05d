//! `POST /v1/vibration-absorber`: the coupled receptance magnitude |H(f)| per output abscissa
//! (dB re 1 m/N over log frequency) above the exact time response of the deflection (and the
//! absorber stroke when there is one).

use plotters::prelude::*;
use serde_json::{Map, Value, json};

use super::style::{SIZE, Series, line_chart};
use super::{PlotError, numbers};

/// Largest number of time samples drawn.
const MAX_DRAWN: u64 = 4000;

/// Turns on a frequency response (0.5–200 Hz, 400 log points, at the tip) and a time response
/// (5 s at 1 ms) unless the request has them, and asks for the series, decimated for drawing.
pub fn prepare(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let outputs = obj.entry("outputs").or_insert_with(|| json!({}));
    let Some(o) = outputs.as_object_mut() else {
        return;
    };
    o.entry("frequency_response").or_insert_with(
        || json!({"f_min_hz": 0.5, "f_max_hz": 200.0, "n_points": 400, "log": true}),
    );
    let t = o
        .entry("time_response")
        .or_insert_with(|| json!({"t_end_s": 5.0, "dt_s": 0.001}));
    if let Some(t) = t.as_object_mut() {
        t.insert("return_series".to_owned(), json!(true));
        let steps = match (
            t.get("t_end_s").and_then(Value::as_f64),
            t.get("dt_s").and_then(Value::as_f64),
        ) {
            (Some(te), Some(dt)) if dt > 0.0 && te.is_finite() => (te / dt).ceil(),
            _ => 1.0,
        };
        let keep = (steps / MAX_DRAWN as f64).ceil().clamp(1.0, 2e6);
        t.insert("decimate".to_owned(), json!(keep as u64));
    }
}

fn frf_series(frf: &Map<String, Value>) -> Vec<(String, Vec<(f64, f64)>)> {
    let f = numbers(&frf["frequencies_hz"]);
    frf.get("points")
        .and_then(Value::as_array)
        .map(|ps| {
            ps.iter()
                .map(|p| {
                    let pts = f
                        .iter()
                        .zip(p["magnitude_m_per_n"].as_array().into_iter().flatten())
                        .filter_map(|(f, m)| {
                            let m = m.as_f64().filter(|m| *m > 0.0)?;
                            Some((f.log10(), 20.0 * m.log10()))
                        })
                        .collect();
                    (format!("x = {} m", p["x_m"]), pts)
                })
                .collect()
        })
        .unwrap_or_default()
}

/// Two panels: |H| in dB over log10 f, and w(t) (plus stroke) in mm.
pub fn render(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let frf = answer["frequency_response"]
        .as_object()
        .ok_or(PlotError::Missing("frequency_response"))?;
    let time = answer["time_response"]
        .as_object()
        .ok_or(PlotError::Missing("time_response"))?;
    let curves = frf_series(frf);
    // Without `return_series` the answer has the time response's peaks but no samples to draw.
    let t = numbers(
        time.get("t_s")
            .ok_or(PlotError::Missing("time_response.t_s"))?,
    );
    let mut tseries: Vec<(String, Vec<(f64, f64)>)> = time["points"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|p| {
            let w = numbers(&p["w_m"]);
            (
                format!("w at x = {} m", p["x_m"]),
                t.iter().zip(w).map(|(t, w)| (*t, w * 1e3)).collect(),
            )
        })
        .collect();
    if let Some(s) = time.get("stroke_m") {
        tseries.push((
            "absorber stroke r".to_owned(),
            t.iter()
                .zip(numbers(s))
                .map(|(t, r)| (*t, r * 1e3))
                .collect(),
        ));
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, SIZE.1 + 200)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((2, 1));
        let fs = Series::labelled(&curves);
        line_chart(
            &areas[0],
            "receptance |H(x, x_p, f)| (null points at undamped resonances omitted)",
            "log10 frequency f [Hz]",
            "|H| [dB re 1 m/N]",
            &fs,
            &[],
        )?;
        let ts = Series::labelled(&tseries);
        line_chart(
            &areas[1],
            &format!(
                "exact time response ({})",
                time["method"].as_str().unwrap_or("")
            ),
            "time t [s]",
            "displacement [mm]",
            &ts,
            &[],
        )?;
        root.present()?;
    }
    Ok(svg)
}
