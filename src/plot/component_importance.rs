//! `POST /v1/component-importance`: the importance of every component at each operating time.

use plotters::prelude::*;
use serde_json::Value;

use super::style::{SIZE, bar_chart};
use super::{PlotError, numbers};

/// Nothing to turn on: the ranking is always returned.
pub fn prepare(_req: &mut Value) {}

/// Grouped bars: one group per component, one bar per operating time.
pub fn render(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let labels: Vec<String> = answer["components"]
        .as_array()
        .ok_or(PlotError::Missing("components"))?
        .iter()
        .map(|c| c.as_str().unwrap_or("?").to_owned())
        .collect();
    let results = answer["results"]
        .as_array()
        .ok_or(PlotError::Missing("results"))?;
    let names: Vec<String> = results
        .iter()
        .map(|r| format!("t = {} h", r["time_h"].as_f64().unwrap_or(f64::NAN)))
        .collect();
    let groups: Vec<(&str, Vec<f64>)> = names
        .iter()
        .zip(results)
        .map(|(n, r)| (n.as_str(), numbers(&r["ci"])))
        .collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        bar_chart(
            &root,
            "component importance CI by component and operating time",
            "CI [-]",
            &labels,
            &groups,
        )?;
        root.present()?;
    }
    Ok(svg)
}
