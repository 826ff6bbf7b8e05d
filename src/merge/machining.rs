//! `/v1/machining-size/train` with k-fold cross-validation (rule: `CvMetrics::shard`): the
//! model, holdout metrics and other outputs are those of the unsharded request (the same in
//! every shard); `metrics.cv.folds` concatenated in shard order and `R2_mean`, `R2_sd`,
//! `RMSE_mean`, `RMSE_sd`, `MAE_mean` recomputed over the merged folds with
//! `output::cv_metrics`, the function the endpoint uses.

use serde_json::Value;

use crate::calc::machining_size::output::cv_metrics;
use crate::calc::machining_size::wire::SplitMetrics;

use super::{MergeError, Part, concat, report, set, sum_u64, warnings};

pub(super) fn merge(parts: &[Part]) -> Result<Value, MergeError> {
    let first = &parts[0];
    let bad = |name: &str, what: String| MergeError::Malformed {
        name: name.to_owned(),
        what,
    };
    let folds = concat(parts, "/metrics/cv/folds")?
        .iter()
        .map(|f| {
            split_metrics(f).ok_or_else(|| {
                bad(
                    &first.name,
                    format!("a fold is not {{n, MAE, MSE, RMSE, R2?}}: {f}"),
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let k = first
        .answer
        .pointer("/metrics/cv/k")
        .and_then(Value::as_u64)
        .and_then(|k| u32::try_from(k).ok())
        .ok_or_else(|| bad(&first.name, "/metrics/cv/k is missing".to_owned()))?;
    if u64::from(k) != first.block.total || folds.len() as u64 != first.block.total {
        return Err(bad(
            &first.name,
            format!(
                "{} folds merged of k = {k}, but the shards split {} folds",
                folds.len(),
                first.block.total
            ),
        ));
    }
    let cv = serde_json::to_value(cv_metrics(k, folds))
        .map_err(|e| bad(&first.name, format!("cannot encode the merged folds: {e}")))?;
    let mut out = first.answer.clone();
    set(&mut out, "/metrics/cv", cv);
    set(&mut out, "/warnings", warnings(parts, "/warnings"));
    // Every shard trains the model (its `iterations` rounds, `model.trees` trees) and then its
    // folds: the unsharded run builds the model's trees once.
    let iterations = first
        .answer
        .pointer("/report/iterations")
        .and_then(Value::as_u64)
        .ok_or_else(|| bad(&first.name, "/report/iterations is missing".to_owned()))?;
    let model_trees = first
        .answer
        .pointer("/model/trees")
        .and_then(Value::as_array)
        .map_or(0, Vec::len) as u64;
    let evaluations = sum_u64(parts, "/report/evaluations")?
        .saturating_sub((parts.len() as u64 - 1).saturating_mul(model_trees));
    set(
        &mut out,
        "/report",
        report(parts, "/report", (iterations, evaluations))?,
    );
    Ok(out)
}

/// A fold's metrics from its JSON (`{n, MAE, MSE, RMSE, R2?}`).
fn split_metrics(v: &Value) -> Option<SplitMetrics> {
    let f = |k: &str| v.get(k).and_then(Value::as_f64);
    Some(SplitMetrics {
        n: u32::try_from(v.get("n")?.as_u64()?).ok()?,
        mae: f("MAE")?,
        mse: f("MSE")?,
        rmse: f("RMSE")?,
        r2: match v.get("R2") {
            None => None,
            Some(r) => Some(r.as_f64()?),
        },
    })
}
