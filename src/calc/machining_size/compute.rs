//! The three computations: [`train`], [`predict`] and [`analyze`]. Pure and deterministic for
//! given seeds (and bit-identical for any thread count); they never see wire types.

use std::borrow::Cow;

use crate::numerics::{Budget, StopReason, par_map, par_map_while};

use super::boost::{Boosted, ExactIndex, Method, SplitIndex, TrainData, boost};
use super::data::{self, Matrix, Metrics};
use super::error::MachiningSizeError;
use super::gra;
use super::input::{AnalyzeInput, PredictInput, ShapKind, TrainInput, TrainOutputKind};
use super::model::{Model, Tree};
use super::pca::{self, Pca};
use super::rng;
use super::shap::{InterventionalTables, InterventionalWeights, PathBuffer, ShapForest};
use super::smogn::{self, Smogn};

/// Rows of one parallel work item (SHAP, prediction).
const ROW_CHUNK: usize = 32;

/// Most training rows the SHAP summary explains (a seeded sample beyond).
pub const SHAP_SUMMARY_ROWS: usize = 2000;

/// A feature with at most this many distinct values gets per-level SHAP means.
pub const LEVELS_MAX: usize = 20;

/// Result of `/train`.
#[derive(Debug, Clone)]
pub struct TrainOutput {
    /// The model (original column indices).
    pub model: Model,
    /// How the main model's training stopped.
    pub stop: StopReason,
    /// Trees built in all (main model and CV folds).
    pub trees_built: u64,
    /// Training rows (before SMOGN) and holdout rows.
    pub train_rows: Vec<u32>,
    /// Holdout rows.
    pub test_rows: Vec<u32>,
    /// Metrics on the training rows.
    pub train_metrics: Metrics,
    /// Metrics and predictions on the holdout.
    pub test: Option<(Metrics, Vec<f64>)>,
    /// Cross-validation.
    pub cv: Option<Cv>,
    /// SMOGN on the training split.
    pub smogn: Option<Smogn>,
    /// Importances (when asked).
    pub importance: Option<Vec<Importance>>,
    /// SHAP summary (when asked and the budget allowed).
    pub shap_summary: Option<ShapSummary>,
    /// The SHAP summary was asked for but skipped (budget spent).
    pub shap_summary_skipped: bool,
}

/// k-fold cross-validation results.
#[derive(Debug, Clone)]
pub struct Cv {
    /// Test metrics of each fold, when every fold finished.
    pub folds: Option<Vec<Metrics>>,
    /// Why it is incomplete (a fold stopped by the budget).
    pub stopped: Option<StopReason>,
}

/// Importance of one feature.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Importance {
    /// Splits on the feature.
    pub weight: u32,
    /// Total loss change.
    pub gain: f64,
    /// Total cover.
    pub cover: f64,
}

/// SHAP summary over training rows.
#[derive(Debug, Clone)]
pub struct ShapSummary {
    /// φ₀.
    pub expected_value: f64,
    /// Rows explained.
    pub rows: usize,
    /// Rows were sampled from more.
    pub sampled_from: Option<usize>,
    /// Mean |φ| per feature.
    pub mean_abs: Vec<f64>,
    /// Mean φ per feature.
    pub mean: Vec<f64>,
    /// Per feature with ≤ [`LEVELS_MAX`] distinct values: (value, count, mean φ).
    pub levels: Vec<Option<Vec<(f64, usize, f64)>>>,
    /// Largest local-accuracy residual.
    pub local_accuracy: f64,
}

/// A trained model with what its training did.
struct Fitted {
    boosted: Boosted,
    smogn: Option<Smogn>,
}

/// The split index of a model trained on `rows` of `x`.
fn build_index(x: &Matrix, rows: &[u32], input: &TrainInput, threads: usize) -> SplitIndex {
    SplitIndex::build(input.params.method, x, rows, &input.features, threads)
}

/// Trains one model on `rows` of the input (SMOGN first, when asked). `shared` is an exact index
/// over all rows of the input, reusable when no SMOGN rows are added.
fn fit(
    input: &TrainInput,
    rows: &[u32],
    shared: Option<&SplitIndex>,
    budget: &Budget,
    threads: usize,
) -> Result<Fitted, MachiningSizeError> {
    let Some(sp) = &input.smogn else {
        let index = match shared {
            Some(ix) => Cow::Borrowed(ix),
            None => Cow::Owned(build_index(&input.x, rows, input, threads)),
        };
        let data = TrainData {
            x: &input.x,
            y: &input.y,
            rows,
            features: &input.features,
            index: &index,
        };
        return Ok(Fitted {
            boosted: boost(&data, &input.params, budget, threads),
            smogn: None,
        });
    };
    let s = smogn::smogn(&input.x, &input.y, rows, sp, budget)
        .map_err(|e| smogn_error(e, "/preprocessing/smogn"))?;
    let kept: Vec<u32> = s.kept.iter().map(|&i| rows[i as usize]).collect();
    let x2 = input.x.select_and_append(&kept, &s.new_rows);
    let y2: Vec<f64> = kept
        .iter()
        .map(|&r| input.y[r as usize])
        .chain(s.new_targets.iter().copied())
        .collect();
    let rows2 = data::all_rows(x2.n_rows());
    let index = build_index(&x2, &rows2, input, threads);
    let data = TrainData {
        x: &x2,
        y: &y2,
        rows: &rows2,
        features: &input.features,
        index: &index,
    };
    Ok(Fitted {
        boosted: boost(&data, &input.params, budget, threads),
        smogn: Some(s),
    })
}

/// SMOGN's failure as the module's error; `pointer` locates the SMOGN options.
fn smogn_error(e: smogn::SmognError, pointer: &'static str) -> MachiningSizeError {
    match e {
        smogn::SmognError::Degenerate { rare, n } => {
            MachiningSizeError::SmognDegenerate { rare, n, pointer }
        }
        smogn::SmognError::Deadline { created } => MachiningSizeError::Deadline {
            stage: "SMOGN",
            done: created as u64,
            total: created as u64 + 1,
        },
    }
}

fn to_model(input: &TrainInput, b: Boosted) -> Model {
    b.into_model(input.x.n_cols(), input.names.clone())
}

/// Predictions of `model` for rows `rows` of `x` (f64 routing).
#[must_use]
pub fn predict_matrix(model: &Model, x: &Matrix, rows: &[u32], threads: usize) -> Vec<f64> {
    let chunks: Vec<&[u32]> = rows.chunks(ROW_CHUNK * 8).collect();
    par_map(threads, &chunks, |_, c| {
        let mut buf = Vec::with_capacity(x.n_cols());
        c.iter()
            .map(|&r| {
                x.row_into(r as usize, &mut buf);
                model.predict_prepared(&buf)
            })
            .collect::<Vec<f64>>()
    })
    .concat()
}

fn metrics_on(
    model: &Model,
    input: &TrainInput,
    rows: &[u32],
    threads: usize,
) -> (Metrics, Vec<f64>) {
    let pred = predict_matrix(model, &input.x, rows, threads);
    let y: Vec<f64> = rows.iter().map(|&r| input.y[r as usize]).collect();
    (data::metrics(&pred, &y), pred)
}

/// `/train` (spec §3): holdout split, SMOGN on the training split, boosting, metrics, k-fold CV,
/// importances and the SHAP summary.
///
/// # Errors
/// Degenerate SMOGN relevance; the budget spent inside SMOGN.
pub fn train(input: &TrainInput, budget: &Budget) -> Result<TrainOutput, MachiningSizeError> {
    let threads = budget.threads();
    let n = input.x.n_rows();
    let (train_rows, test_rows) = data::train_test_split(n, input.test_fraction, input.split_seed);
    let shared = (input.params.method == Method::Exact && input.smogn.is_none())
        .then(|| SplitIndex::Exact(ExactIndex::build(&input.x, &input.features, threads)));
    let main = fit(input, &train_rows, shared.as_ref(), budget, threads)?;
    let stop = main.boosted.stop;
    let mut trees_built = main.boosted.trees.len() as u64;
    let model = to_model(input, main.boosted);
    let (train_metrics, _) = metrics_on(&model, input, &train_rows, threads);
    let test = (!test_rows.is_empty()).then(|| metrics_on(&model, input, &test_rows, threads));
    let cv = input.k_fold.map(|k| {
        let (cv, built) = cross_validate(input, k, shared.as_ref(), budget, threads);
        trees_built += built;
        cv
    });
    let importance = input
        .outputs
        .contains(&TrainOutputKind::Importance)
        .then(|| importance(&model));
    let want_shap = input.outputs.contains(&TrainOutputKind::ShapSummary);
    let shap_summary = if want_shap && !budget.expired() {
        shap_summary(
            &model,
            &input.x,
            &train_rows,
            input.split_seed,
            budget,
            threads,
        )
    } else {
        None
    };
    Ok(TrainOutput {
        shap_summary_skipped: want_shap && shap_summary.is_none(),
        model,
        stop,
        trees_built,
        train_rows,
        test_rows,
        train_metrics,
        test,
        cv,
        smogn: main.smogn,
        importance,
        shap_summary,
    })
}

/// k-fold CV over all rows, folds in parallel (each fold trains single-threaded); returns the
/// results and the trees built.
fn cross_validate(
    input: &TrainInput,
    k: usize,
    shared: Option<&SplitIndex>,
    budget: &Budget,
    threads: usize,
) -> (Cv, u64) {
    let n = input.x.n_rows();
    let mut folds = data::folds(n, k, input.split_seed);
    // A shard evaluates its block of the folds, each exactly as in the whole cross-validation.
    if let Some(shard) = input.shard {
        let mine = shard.range(folds.len());
        folds = folds.drain(mine).collect();
    }
    let results = par_map(threads, &folds, |_, fold| {
        if budget.expired() {
            return Err(budget.check(0).unwrap_or(StopReason::Deadline));
        }
        let rows = data::complement(n, fold);
        let fitted = fit(input, &rows, shared, budget, 1).map_err(|_| StopReason::Deadline)?;
        let stop = fitted.boosted.stop;
        let built = fitted.boosted.trees.len() as u64;
        if !matches!(stop, StopReason::Completed | StopReason::Converged) {
            return Err(stop);
        }
        let model = to_model(input, fitted.boosted);
        Ok((metrics_on(&model, input, fold, 1).0, built))
    });
    let built = results
        .iter()
        .map(|r| r.as_ref().map_or(0, |(_, b)| *b))
        .sum();
    let stopped = results.iter().find_map(|r| r.as_ref().err().copied());
    let folds = stopped.is_none().then(|| {
        results
            .into_iter()
            .filter_map(Result::ok)
            .map(|(m, _)| m)
            .collect()
    });
    (Cv { folds, stopped }, built)
}

/// Split counts, total loss change and total cover per feature.
#[must_use]
pub fn importance(model: &Model) -> Vec<Importance> {
    let mut out = vec![Importance::default(); model.n_features];
    for t in &model.trees {
        for node in t.nodes.iter().filter(|n| !n.is_leaf()) {
            let imp = &mut out[node.feature as usize];
            imp.weight += 1;
            imp.gain += node.loss_change;
            imp.cover += node.cover;
        }
    }
    out
}

/// Path-dependent SHAP values of prepared rows, with the largest local-accuracy residual;
/// `None` when the budget ran out.
fn shap_rows(
    model: &Model,
    rows: &[Vec<f64>],
    budget: &Budget,
    threads: usize,
) -> Option<(Vec<Vec<f64>>, f64)> {
    let d = model.n_features;
    let phi0 = model.expected_value();
    let depth = model.max_depth();
    let forest = ShapForest::new(model);
    let chunks: Vec<&[Vec<f64>]> = rows.chunks(ROW_CHUNK).collect();
    let parts = par_map_while(threads, &chunks, |_, chunk| {
        if budget.expired() {
            return None;
        }
        let mut buf = PathBuffer::for_depth(depth);
        let mut worst = 0.0f64;
        let vals: Vec<Vec<f64>> = chunk
            .iter()
            .map(|x| {
                let mut phi = vec![0.0; d];
                forest.path_dependent(x, &mut phi, &mut buf);
                let f = model.predict_prepared(x);
                worst = worst.max((phi0 + phi.iter().sum::<f64>() - f).abs());
                phi
            })
            .collect();
        Some((vals, worst))
    });
    let mut values = Vec::with_capacity(rows.len());
    let mut worst = 0.0f64;
    for p in parts {
        let (v, w) = p?;
        values.extend(v);
        worst = worst.max(w);
    }
    Some((values, worst))
}

/// SHAP summary over the training rows (a seeded sample of [`SHAP_SUMMARY_ROWS`] beyond).
fn shap_summary(
    model: &Model,
    x: &Matrix,
    train_rows: &[u32],
    seed: u64,
    budget: &Budget,
    threads: usize,
) -> Option<ShapSummary> {
    let (rows, sampled_from): (Vec<u32>, Option<usize>) = if train_rows.len() > SHAP_SUMMARY_ROWS {
        let mut r = rng::stream(seed, rng::STREAM_SHAP_ROWS);
        let pick = rng::sample_sorted(&mut r, train_rows.len(), SHAP_SUMMARY_ROWS);
        (
            pick.iter().map(|&i| train_rows[i]).collect(),
            Some(train_rows.len()),
        )
    } else {
        (train_rows.to_vec(), None)
    };
    let prepared: Vec<Vec<f64>> = rows.iter().map(|&r| x.row(r as usize)).collect();
    let (values, worst) = shap_rows(model, &prepared, budget, threads)?;
    let d = model.n_features;
    let m = values.len().max(1) as f64;
    let mean_abs = (0..d)
        .map(|f| values.iter().map(|v| v[f].abs()).sum::<f64>() / m)
        .collect();
    let mean = (0..d)
        .map(|f| values.iter().map(|v| v[f]).sum::<f64>() / m)
        .collect();
    let levels = (0..d)
        .map(|f| {
            let mut lv: Vec<(f64, usize, f64)> = Vec::new();
            for (x, v) in prepared.iter().zip(&values) {
                let key = x[f];
                if let Some(e) = lv.iter_mut().find(|(k, _, _)| (*k - key) == 0.0) {
                    e.1 += 1;
                    e.2 += v[f];
                } else if lv.len() < LEVELS_MAX {
                    lv.push((key, 1, v[f]));
                } else {
                    return None;
                }
            }
            lv.sort_by(|a, b| a.0.total_cmp(&b.0));
            Some(
                lv.into_iter()
                    .map(|(k, c, s)| (k, c, s / c as f64))
                    .collect(),
            )
        })
        .collect();
    Some(ShapSummary {
        expected_value: model.expected_value(),
        rows: values.len(),
        sampled_from,
        mean_abs,
        mean,
        levels,
        local_accuracy: worst,
    })
}

/// Result of `/predict`.
#[derive(Debug, Clone)]
pub struct PredictOutput {
    /// Prediction per row.
    pub predictions: Vec<f64>,
    /// SHAP values.
    pub shap: Option<ShapValues>,
    /// Interaction values per row (row-major d × d).
    pub interactions: Option<Vec<Vec<f64>>>,
    /// Tree traversals (a measure of the work).
    pub traversals: u64,
}

/// SHAP values of every row.
#[derive(Debug, Clone)]
pub struct ShapValues {
    /// φ₀.
    pub expected_value: f64,
    /// φ per row.
    pub values: Vec<Vec<f64>>,
    /// Largest |φ₀ + Σφ − f(x)|.
    pub local_accuracy: f64,
    /// The scale the residual is judged against (|base| + Σ trees max |leaf|).
    pub scale: f64,
}

/// Magnitude of a model's output: |base| + Σ over trees of the largest |leaf|.
#[must_use]
pub fn output_scale(model: &Model) -> f64 {
    model.base_score.abs()
        + model
            .trees
            .iter()
            .map(|t: &Tree| {
                t.nodes
                    .iter()
                    .filter(|n| n.is_leaf())
                    .fold(0.0f64, |a, n| a.max(n.value.abs()))
            })
            .sum::<f64>()
}

/// `/predict` (spec §2.2, §4): predictions, SHAP values and interaction values, with local
/// accuracy checked on every row.
///
/// # Errors
/// [`MachiningSizeError::Deadline`] when the budget runs out (SHAP answers are never partial).
pub fn predict(input: &PredictInput, budget: &Budget) -> Result<PredictOutput, MachiningSizeError> {
    let threads = budget.threads();
    let model = &input.model;
    let n = input.rows.len();
    let trees = model.trees.len() as u64;
    let deadline = |stage, done: usize| MachiningSizeError::Deadline {
        stage,
        done: done as u64,
        total: n as u64,
    };
    let chunks: Vec<&[Vec<f64>]> = input.rows.chunks(ROW_CHUNK * 8).collect();
    let predictions: Vec<f64> = par_map_while(threads, &chunks, |_, c| {
        (!budget.expired()).then(|| {
            c.iter()
                .map(|x| model.predict_prepared(x))
                .collect::<Vec<f64>>()
        })
    })
    .into_iter()
    .collect::<Option<Vec<Vec<f64>>>>()
    .ok_or_else(|| deadline("prediction", 0))?
    .concat();
    let mut traversals = n as u64 * trees;
    let shap = match input.shap {
        ShapKind::None => None,
        ShapKind::PathDependent => {
            let (values, worst) = shap_rows(model, &input.rows, budget, threads)
                .ok_or_else(|| deadline("SHAP", 0))?;
            traversals += n as u64 * trees;
            Some(ShapValues {
                expected_value: model.expected_value(),
                values,
                local_accuracy: worst,
                scale: output_scale(model),
            })
        }
        ShapKind::Interventional => {
            let bg = &input.background;
            let wt = InterventionalWeights::new(model.max_depth());
            let phi0 = bg.iter().map(|r| model.predict_prepared(r)).sum::<f64>() / bg.len() as f64;
            let tables = InterventionalTables::new(model, bg, &wt, budget)
                .ok_or_else(|| deadline("interventional SHAP", 0))?;
            let chunks: Vec<&[Vec<f64>]> = input.rows.chunks(ROW_CHUNK).collect();
            let parts = par_map_while(threads, &chunks, |_, chunk| {
                let mut out = Vec::with_capacity(chunk.len());
                let mut worst = 0.0f64;
                for (i, x) in chunk.iter().enumerate() {
                    if i % 4 == 0 && budget.expired() {
                        return None;
                    }
                    let mut phi = vec![0.0; model.n_features];
                    tables.shap(x, &mut phi);
                    let f = model.predict_prepared(x);
                    worst = worst.max((phi0 + phi.iter().sum::<f64>() - f).abs());
                    out.push(phi);
                }
                Some((out, worst))
            });
            let mut values = Vec::with_capacity(n);
            let mut worst = 0.0f64;
            for p in parts {
                let (v, w) = p.ok_or_else(|| deadline("interventional SHAP", values.len()))?;
                values.extend(v);
                worst = worst.max(w);
            }
            traversals += tables.traversals(n);
            Some(ShapValues {
                expected_value: phi0,
                values,
                local_accuracy: worst,
                scale: output_scale(model),
            })
        }
    };
    let interactions = if input.interactions {
        let d = model.n_features;
        let depth = model.max_depth();
        let forest = ShapForest::new(model);
        let chunks: Vec<&[Vec<f64>]> = input.rows.chunks(4).collect();
        let parts = par_map_while(threads, &chunks, |_, chunk| {
            if budget.expired() {
                return None;
            }
            let mut buf = PathBuffer::for_depth(depth);
            let mut scratch = [vec![0.0; d], vec![0.0; d]];
            Some(
                chunk
                    .iter()
                    .map(|x| {
                        let mut phi = vec![0.0; d];
                        let mut out = vec![0.0; d * d];
                        forest.interactions(x, &mut phi, &mut out, &mut buf, &mut scratch);
                        out
                    })
                    .collect::<Vec<Vec<f64>>>(),
            )
        });
        let rows: Vec<Vec<f64>> = parts
            .into_iter()
            .collect::<Option<Vec<Vec<Vec<f64>>>>>()
            .ok_or_else(|| deadline("interaction values", 0))?
            .concat();
        traversals += n as u64 * trees * (1 + 2 * d as u64);
        Some(rows)
    } else {
        None
    };
    Ok(PredictOutput {
        predictions,
        shap,
        interactions,
        traversals,
    })
}

/// Result of `/analyze`.
#[derive(Debug, Clone)]
pub struct AnalyzeOutput {
    /// Constant columns.
    pub constant: Vec<usize>,
    /// Non-constant columns (those PCA and GRA analyse).
    pub varying: Vec<usize>,
    /// PCA and the components kept.
    pub pca: Option<Pca>,
    /// GRA grade per varying column.
    pub gra: Option<Vec<f64>>,
    /// SMOGN preview (positions are row indices).
    pub smogn: Option<Smogn>,
}

/// `/analyze` (spec §2.3, §6).
///
/// # Errors
/// GRA with a zero-mean series; degenerate SMOGN relevance; the budget spent.
pub fn analyze(input: &AnalyzeInput, budget: &Budget) -> Result<AnalyzeOutput, MachiningSizeError> {
    let threads = budget.threads();
    let x = &input.x;
    let d = x.n_cols();
    let constant: Vec<usize> = (0..d).filter(|&f| x.is_constant(f)).collect();
    let varying: Vec<usize> = (0..d).filter(|f| !constant.contains(f)).collect();
    let pca = match input.pca {
        Some((k, scores)) if !varying.is_empty() => Some(
            pca::pca(
                x,
                &varying,
                k.unwrap_or(varying.len()),
                scores,
                budget,
                threads,
            )
            .ok_or(MachiningSizeError::Deadline {
                stage: "PCA",
                done: 0,
                total: varying.len() as u64,
            })?,
        ),
        _ => None,
    };
    let gra = match input.gra {
        Some((rho, norm)) => {
            let mut series: Vec<&[f64]> = vec![&input.y];
            series.extend(varying.iter().map(|&f| x.col(f)));
            Some(gra::grades(&series, rho, norm).map_err(|e| {
                let gra::GraError::ZeroMean { series } = e;
                MachiningSizeError::GraZeroMean {
                    series: if series == 0 {
                        "target".to_owned()
                    } else {
                        input.names[varying[series - 1]].clone()
                    },
                }
            })?)
        }
        None => None,
    };
    let smogn = match &input.smogn {
        Some((p, _)) => Some(
            smogn::smogn(x, &input.y, &data::all_rows(x.n_rows()), p, budget)
                .map_err(|e| smogn_error(e, "/smogn"))?,
        ),
        None => None,
    };
    Ok(AnalyzeOutput {
        constant,
        varying,
        pca,
        gra,
        smogn,
    })
}
