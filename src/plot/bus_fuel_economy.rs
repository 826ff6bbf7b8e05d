//! Bus pictures: the drive cycle's speed trace, the motor's operating points over its efficiency
//! map, and the energy drawn per motor × cycle; and a motor's efficiency map with its envelope.

use plotters::prelude::*;
use serde_json::{Value, json};

use super::style::{HeatMap, SIZE, Series, bar_chart, colour, heat_map, line_chart};
use super::{PlotError, numbers};

/// Traces and efficiency maps on.
pub fn prepare(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let options = obj.entry("options").or_insert_with(|| json!({}));
    let Some(o) = options.as_object_mut() else {
        return;
    };
    let outputs = o.entry("outputs").or_insert_with(|| json!([]));
    if let Some(list) = outputs.as_array_mut() {
        for want in ["traces", "efficiency_map"] {
            if !list.iter().any(|v| v == want) {
                list.push(json!(want));
            }
        }
    }
}

/// A motor map's efficiency as a heat map over speed × torque.
fn efficiency_map(m: &Value) -> HeatMap<'static> {
    let z: Vec<Vec<f64>> = m["efficiency"]
        .as_array()
        .map(|rows| {
            rows.iter()
                .map(|r| {
                    numbers(r)
                        .into_iter()
                        .map(|e| if e > 0.0 { e } else { f64::NAN })
                        .collect()
                })
                .collect()
        })
        .unwrap_or_default();
    HeatMap {
        title: "motor efficiency map (grey: outside the envelope)",
        x_desc: "motor speed [rpm]",
        y_desc: "motor torque [N·m]",
        z_desc: "η [-]",
        x: numbers(&m["speed_rpm"]),
        y: numbers(&m["torque_nm"]),
        z,
        log_scale: false,
    }
}

/// Speed trace, operating points over the efficiency map, energy bars.
pub fn render(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let results = answer["results"]
        .as_array()
        .ok_or(PlotError::Missing("results"))?;
    let first = results.first().ok_or(PlotError::Missing("results"))?;
    let tr = &first["traces"];
    let t = numbers(&tr["t_s"]);
    let speed: Vec<(f64, f64)> = t
        .iter()
        .copied()
        .zip(numbers(&tr["v_mps"]).into_iter().map(|v| v * 3.6))
        .collect();
    let ops: Vec<(f64, f64)> = numbers(&tr["omega_rad_s"])
        .into_iter()
        .map(|w| w * 60.0 / std::f64::consts::TAU)
        .zip(numbers(&tr["torque_motor_nm"]))
        .collect();
    let labels: Vec<String> = results
        .iter()
        .map(|r| {
            format!(
                "{}/{}",
                r["motor"].as_str().unwrap_or("?"),
                r["cycle"].as_str().unwrap_or("?")
            )
        })
        .collect();
    let energy: Vec<f64> = results
        .iter()
        .map(|r| r["energy_in_kwh"].as_f64().unwrap_or(f64::NAN))
        .collect();
    let title = format!(
        "speed trace: {} (motor {})",
        first["cycle"].as_str().unwrap_or("?"),
        first["motor"].as_str().unwrap_or("?")
    );
    let map = answer["motor_maps"]
        .as_array()
        .and_then(|m| m.first())
        .map(efficiency_map);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, SIZE.1 + 420)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((3, 1));
        line_chart(
            &areas[0],
            &title,
            "time [s]",
            "speed [km/h]",
            &[Series {
                label: "speed",
                points: speed,
            }],
            &[],
        )?;
        match map {
            Some(m) => heat_map(&areas[1], &m, |chart| {
                chart.draw_series(ops.iter().map(|&p| Circle::new(p, 2, colour(1).filled())))?;
                Ok(())
            })?,
            None => line_chart(
                &areas[1],
                "motor operating points",
                "motor speed [rpm]",
                "motor torque [N·m]",
                &[],
                &ops,
            )?,
        }
        bar_chart(
            &areas[2],
            "energy drawn from the battery per motor and cycle",
            "E_in [kWh]",
            &labels,
            &[("E_in", energy)],
        )?;
        root.present()?;
    }
    Ok(svg)
}

/// Nothing to turn on.
pub fn prepare_map(_req: &mut Value) {}

/// Efficiency map with the torque envelope.
pub fn render_map(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    if answer.get("efficiency").is_none() {
        return Err(PlotError::Missing("efficiency"));
    }
    let envelope: Vec<(f64, f64)> = numbers(&answer["speed_rpm"])
        .into_iter()
        .zip(numbers(&answer["t_max_nm"]))
        .collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut map = efficiency_map(answer);
        map.title = "motor efficiency map; line: torque envelope T_max (grey: outside)";
        heat_map(&root, &map, |chart| {
            chart.draw_series(LineSeries::new(envelope, colour(1).stroke_width(3)))?;
            Ok(())
        })?;
        root.present()?;
    }
    Ok(svg)
}
