//! `POST /v1/machining-size/{train,predict,analyze}`: what drives the machined dimension.
//!
//! * train: mean |SHAP| per feature over the training rows (the paper's SHAP summary);
//! * predict: each row's SHAP values per feature (the first eight rows);
//! * analyze: PCA contribution rates per component beside the grey relational grades.

use plotters::prelude::*;
use serde_json::{Value, json};

use super::style::{SIZE, bar_chart};
use super::{PlotError, numbers};

/// Rows drawn in the predict picture (the legend stays readable).
const MAX_ROWS: usize = 8;

/// Train: ask for the SHAP summary (the other outputs stay as requested).
pub fn prepare_train(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let outputs = obj.entry("outputs").or_insert_with(|| json!([]));
    if outputs.is_null() {
        *outputs = json!([]);
    }
    if let Some(list) = outputs.as_array_mut()
        && !list.iter().any(|o| o == "shap_summary")
    {
        list.push(json!("shap_summary"));
    }
}

/// Train: bars of mean |SHAP| per feature.
pub fn render_train(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let features = answer["shap_summary"]["features"]
        .as_array()
        .ok_or(PlotError::Missing("shap_summary"))?;
    let labels: Vec<String> = features
        .iter()
        .map(|f| f["feature"].as_str().unwrap_or("?").to_owned())
        .collect();
    let values: Vec<f64> = features
        .iter()
        .map(|f| f["mean_abs"].as_f64().unwrap_or(f64::NAN))
        .collect();
    draw(|root| {
        bar_chart(
            root,
            "SHAP summary: mean |SHAP value| per feature over the training rows",
            "mean |SHAP| [target unit]",
            &labels,
            &[("mean |SHAP|", values)],
        )
    })
}

/// Predict: ask for path-dependent SHAP values unless the request chose a kind.
pub fn prepare_predict(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    let none = obj.get("shap").is_none_or(|s| s.is_null() || s == "none");
    if none {
        obj.insert("shap".to_owned(), json!("path_dependent"));
    }
}

/// Predict: grouped bars, one group per feature, one bar per row.
pub fn render_predict(req: &Value, answer: &Value) -> Result<String, PlotError> {
    let values = answer["shap"]["values"]
        .as_array()
        .ok_or(PlotError::Missing("shap"))?;
    let width = values.first().map_or(0, |r| numbers(r).len());
    let names = req["feature_names"]
        .as_array()
        .filter(|n| n.len() == width)
        .map(|n| {
            n.iter()
                .map(|x| x.as_str().unwrap_or("?").to_owned())
                .collect::<Vec<_>>()
        })
        .unwrap_or_else(|| (0..width).map(|j| format!("f{j}")).collect());
    let rows: Vec<String> = (0..values.len().min(MAX_ROWS))
        .map(|i| format!("row {i}"))
        .collect();
    let groups: Vec<(&str, Vec<f64>)> = rows
        .iter()
        .zip(values)
        .map(|(n, r)| (n.as_str(), numbers(r)))
        .collect();
    let kind = answer["shap"]["kind"].as_str().unwrap_or("shap");
    draw(|root| {
        bar_chart(
            root,
            &format!("{kind} SHAP values per feature and row"),
            "SHAP value [target unit]",
            &names,
            &groups,
        )
    })
}

/// Analyze: PCA and grey relational analysis on (the defaults where the request has none).
pub fn prepare_analyze(req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    for key in ["pca", "gra"] {
        if obj.get(key).is_none_or(Value::is_null) {
            obj.insert(key.to_owned(), json!({}));
        }
    }
}

/// Analyze: PCA contribution rates (left) and grey relational grades (right).
pub fn render_analyze(_req: &Value, answer: &Value) -> Result<String, PlotError> {
    let rates = numbers(&answer["pca"]["contribution_rates"]);
    let grades = answer["gra"]["grades"]
        .as_array()
        .ok_or(PlotError::Missing("gra"))?;
    if rates.is_empty() {
        return Err(PlotError::Missing("pca"));
    }
    let components: Vec<String> = (1..=rates.len()).map(|k| format!("PC{k}")).collect();
    let features: Vec<String> = grades
        .iter()
        .map(|g| g["feature"].as_str().unwrap_or("?").to_owned())
        .collect();
    let grade: Vec<f64> = grades
        .iter()
        .map(|g| g["grade"].as_f64().unwrap_or(f64::NAN))
        .collect();
    draw(|root| {
        let (left, right) = root.split_horizontally(SIZE.0 / 2);
        bar_chart(
            &left,
            "PCA contribution rate per component",
            "contribution rate [%]",
            &components,
            &[("contribution rate", rates.clone())],
        )?;
        bar_chart(
            &right,
            "grey relational grade per feature",
            "grade [-]",
            &features,
            &[("grade", grade.clone())],
        )
    })
}

/// An SVG of the picture size, white, drawn by `f`.
fn draw(
    f: impl FnOnce(&DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<(), PlotError>,
) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        f(&root)?;
        root.present()?;
    }
    Ok(svg)
}
