//! The one place that builds the three responses: model documents, metrics, optional outputs,
//! warnings and reports.

use crate::calc::common::Warning;
use crate::numerics::{Budget, SolverReport, StopReason};

use super::boost::{BoostParams, Method};
use super::compute::{AnalyzeOutput, Importance, PredictOutput, ShapSummary, TrainOutput};
use super::data::{Metrics, mean_sd};
use super::document::{FORMAT, OBJECTIVE};
use super::input::{AnalyzeInput, PredictInput, TrainInput, TrainOutputKind};
use super::model::{Model, ModelSource, Routing, Tree};
use super::pca::Pca;
use super::smogn::Smogn;
use super::wire::{
    AnalyzeResponse, ConstantColumn, CvMetrics, FeatureImportance, FeatureShap, GbdtModel,
    GraGrade, GraOut, LevelShap, MetricsOut, ModelSummary, OffGrid, PcaOut, PredictResponse,
    PreprocessingOut, ShapOut, ShapSummary as ShapSummaryWire, SmognBinOut, SmognData, SmognOut,
    SplitMetrics, TestPredictions, TrainParams, TrainResponse, TreeDoc, TreeMethod,
};

/// Local accuracy is flagged when the residual exceeds this share of the output scale (f64
/// sums over ≤ 5000 trees stay ~1e-12 of it).
const LOCAL_ACCURACY_REL: f64 = 1e-9;

/// Below this many holdout rows R² is too noisy to compare models without CV (spec §8.5).
const SMALL_TEST_SET: usize = 50;

/// Consecutive kept eigenvalues closer than this (relative) make components unstable (§8.8).
const NEAR_EQUAL_EIGEN: f64 = 0.05;

/// Cross-validation metrics of `k` folds from the folds' metrics: the folds, the mean and
/// sample sd (ddof 1) of R² (over the folds that have one) and RMSE, the mean MAE. The merge
/// rule of sharded answers: this over the concatenated folds of every shard.
#[must_use]
pub fn cv_metrics(k: u32, folds: Vec<SplitMetrics>) -> CvMetrics {
    let r2: Vec<f64> = folds.iter().filter_map(|m| m.r2).collect();
    let rmse: Vec<f64> = folds.iter().map(|m| m.rmse).collect();
    let mae: Vec<f64> = folds.iter().map(|m| m.mae).collect();
    let (r2_mean, r2_sd) = mean_sd(&r2);
    let (rmse_mean, rmse_sd) = mean_sd(&rmse);
    CvMetrics {
        k,
        folds,
        shard: None,
        r2_mean: (!r2.is_empty()).then_some(r2_mean),
        r2_sd: (!r2.is_empty()).then_some(r2_sd),
        rmse_mean,
        rmse_sd,
        mae_mean: mean_sd(&mae).0,
    }
}

fn u32_of(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

fn split_metrics(m: &Metrics) -> SplitMetrics {
    SplitMetrics {
        n: u32_of(m.n),
        mae: m.mae,
        mse: m.mse,
        rmse: m.rmse,
        r2: m.r2,
    }
}

/// The training parameters as the model document echoes them.
fn params_echo(p: &BoostParams) -> TrainParams {
    let (tree_method, max_bin) = match p.method {
        Method::Exact => (TreeMethod::Exact, 256),
        Method::Hist { max_bin } => (TreeMethod::Hist, u32_of(max_bin)),
    };
    TrainParams {
        n_estimators: u32_of(p.n_estimators),
        max_depth: u32_of(p.max_depth),
        learning_rate: p.learning_rate,
        reg_lambda: p.reg_lambda,
        reg_alpha: p.reg_alpha,
        gamma: p.gamma,
        min_child_weight: p.min_child_weight,
        colsample_bytree: p.colsample_bytree,
        subsample: p.subsample,
        seed: p.seed,
        base_score: p.base_score,
        tree_method,
        max_bin,
    }
}

fn tree_doc(t: &Tree) -> TreeDoc {
    let child = |c: u32, leaf: bool| if leaf { -1 } else { i64::from(c) };
    TreeDoc {
        left: t.nodes.iter().map(|n| child(n.left, n.is_leaf())).collect(),
        right: t
            .nodes
            .iter()
            .map(|n| child(n.right, n.is_leaf()))
            .collect(),
        feature: t
            .nodes
            .iter()
            .map(|n| child(n.feature, n.is_leaf()))
            .collect(),
        threshold: t.nodes.iter().map(|n| n.threshold).collect(),
        default_left: t.nodes.iter().map(|n| n.default_left).collect(),
        value: t.nodes.iter().map(|n| n.value).collect(),
        cover: t.nodes.iter().map(|n| n.cover).collect(),
        loss_change: t.nodes.iter().map(|n| n.loss_change).collect(),
    }
}

/// Our model document of a trained model.
#[must_use]
pub fn model_doc(model: &Model, params: Option<&BoostParams>) -> GbdtModel {
    GbdtModel {
        format: FORMAT.to_owned(),
        objective: OBJECTIVE.to_owned(),
        base_score: model.base_score,
        feature_names: model.feature_names.clone(),
        n_features: u32_of(model.n_features),
        params: params.map(params_echo),
        trees: model.trees.iter().map(tree_doc).collect(),
    }
}

fn local_accuracy_warning(residual: f64, scale: f64) -> Option<Warning> {
    (residual > LOCAL_ACCURACY_REL * scale.max(1.0)).then(|| {
        Warning::new(
            "LOCAL_ACCURACY",
            format!(
                "φ₀ + Σφ differs from the prediction by up to {residual:e} (output scale \
                 {scale:e}); the SHAP values are less accurate than expected"
            ),
        )
    })
}

fn shap_summary_out(s: &ShapSummary, names: &[String]) -> ShapSummaryWire {
    ShapSummaryWire {
        expected_value: s.expected_value,
        rows_explained: u32_of(s.rows),
        features: names
            .iter()
            .enumerate()
            .map(|(f, name)| FeatureShap {
                feature: name.clone(),
                mean_abs: s.mean_abs[f],
                mean: s.mean[f],
                levels: s.levels[f].as_ref().map(|lv| {
                    lv.iter()
                        .map(|&(value, count, mean)| LevelShap {
                            value,
                            count: u32_of(count),
                            mean,
                        })
                        .collect()
                }),
            })
            .collect(),
        local_accuracy_max_abs: s.local_accuracy,
    }
}

/// SMOGN's summary; `names` names the columns, `data` the resampled set when asked.
fn smogn_out(s: &Smogn, n_before: usize, names: &[String], data: Option<SmognData>) -> SmognOut {
    let kept = s.kept.len();
    SmognOut {
        n_before: u32_of(n_before),
        n_after: u32_of(kept + s.new_rows.len()),
        n_rare: u32_of(s.rare_count),
        n_interpolated: u32_of(s.interpolated),
        n_perturbed: u32_of(s.perturbed),
        n_removed: u32_of(n_before - kept),
        bins: s
            .bins
            .iter()
            .map(|b| SmognBinOut {
                rare: b.rare,
                size: u32_of(b.size),
                y_min: b.y_range.0,
                y_max: b.y_range.1,
                kept: u32_of(b.kept),
                created: u32_of(b.created),
            })
            .collect(),
        off_grid: s
            .off_grid
            .iter()
            .map(|&(f, count)| OffGrid {
                feature: names[f].clone(),
                count: u32_of(count),
            })
            .collect(),
        data,
    }
}

fn off_grid_warning(s: &SmognOut, pointer: &str) -> Option<Warning> {
    (!s.off_grid.is_empty()).then(|| {
        let list: Vec<String> = s
            .off_grid
            .iter()
            .map(|o| format!("{} ({})", o.feature, o.count))
            .collect();
        Warning::at(
            "SMOGN_OFF_GRID",
            pointer,
            format!(
                "SMOGN created values off the levels of discrete features: {} (spec §8 hazard 6)",
                list.join(", ")
            ),
        )
    })
}

/// The training run's warnings, in order: rounds stopped early (a zero-leaf round) or
/// interrupted, and too few trees with a split.
fn training_warnings(
    p: &BoostParams,
    rounds: usize,
    effective: usize,
    stop: StopReason,
) -> Vec<Warning> {
    let mut warnings = Vec::new();
    match stop {
        StopReason::Converged => warnings.push(Warning::new(
            "ROUNDS_STOPPED_EARLY",
            format!(
                "round {rounds} built a single zero leaf with every feature and row in use, so \
                 every further round would too: the model keeps {rounds} of {} trees and predicts \
                 exactly as the full {} would",
                p.n_estimators, p.n_estimators
            ),
        )),
        StopReason::Completed => {}
        other => warnings.push(Warning::new(
            "TRAINING_STOPPED",
            format!(
                "training stopped ({other:?}) after {rounds} of {} rounds; the model has the trees \
                 built so far",
                p.n_estimators
            ),
        )),
    }
    if effective < p.n_estimators {
        warnings.push(Warning::new(
            "FEW_EFFECTIVE_TREES",
            format!(
                "only {effective} of {} trees contain a split (regularisation vs target scale: λ, \
                 α, γ, min_child_weight and the 1e-6 split threshold are in squared target units, \
                 spec §8 hazard 2)",
                p.n_estimators
            ),
        ));
    }
    warnings
}

/// Feature importances by name, with the per-split means and the share of the total gain.
fn importance_out(imp: &[Importance], names: &[String]) -> Vec<FeatureImportance> {
    let total: f64 = imp.iter().map(|i| i.gain).sum();
    imp.iter()
        .zip(names)
        .map(|(i, name)| {
            let w = f64::from(i.weight.max(1));
            FeatureImportance {
                feature: name.clone(),
                weight: i.weight,
                gain: i.gain,
                gain_mean: if i.weight > 0 { i.gain / w } else { 0.0 },
                gain_share: if total > 0.0 { i.gain / total } else { 0.0 },
                cover: i.cover,
                cover_mean: if i.weight > 0 { i.cover / w } else { 0.0 },
            }
        })
        .collect()
}

/// The `/train` response.
#[must_use]
pub fn respond_train(input: &TrainInput, out: &TrainOutput, budget: &Budget) -> TrainResponse {
    let p = &input.params;
    let model = &out.model;
    let rounds = model.trees.len();
    let effective = model.effective_trees();
    let mut warnings = training_warnings(p, rounds, effective, out.stop);
    let cv = out.cv.as_ref().and_then(|cv| {
        if let Some(stop) = cv.stopped {
            warnings.push(Warning::at(
                "CV_INCOMPLETE",
                "/validation/k_fold",
                format!("cross-validation did not finish ({stop:?}); its metrics are omitted"),
            ));
        }
        cv.folds.as_ref().map(|folds| {
            let k = input.k_fold.unwrap_or(folds.len());
            let mut m = cv_metrics(u32_of(k), folds.iter().map(split_metrics).collect());
            m.shard = input.shard.map(|s| s.out(k));
            m
        })
    });
    if out.test_rows.len() < SMALL_TEST_SET && !out.test_rows.is_empty() && out.cv.is_none() {
        warnings.push(Warning::at(
            "SMALL_TEST_SET",
            "/validation/test_fraction",
            format!(
                "test metrics come from {} rows: R² varies by several hundredths between splits \
                 of this size (spec §8 hazard 5); set validation.k_fold for mean ± sd",
                out.test_rows.len()
            ),
        ));
    }
    let shap_summary = out.shap_summary.as_ref().map(|s| {
        if let Some(from) = s.sampled_from {
            warnings.push(Warning::new(
                "SHAP_SUMMARY_SAMPLED",
                format!(
                    "the SHAP summary explains a seeded sample of {} of the {from} training rows",
                    s.rows
                ),
            ));
        }
        if let Some(w) =
            local_accuracy_warning(s.local_accuracy, super::compute::output_scale(model))
        {
            warnings.push(w);
        }
        shap_summary_out(s, &input.names)
    });
    if out.shap_summary_skipped {
        warnings.push(Warning::at(
            "SHAP_SUMMARY_SKIPPED",
            "/outputs",
            "the time budget was spent before the SHAP summary",
        ));
    }
    let smogn = out.smogn.as_ref().map(|s| {
        let o = smogn_out(s, out.train_rows.len(), &input.names, None);
        if let Some(w) = off_grid_warning(&o, "/preprocessing/smogn") {
            warnings.push(w);
        }
        o
    });
    let importance = out
        .importance
        .as_ref()
        .map(|imp| importance_out(imp, &input.names));
    let test_predictions = input
        .outputs
        .contains(&TrainOutputKind::TestPredictions)
        .then(|| TestPredictions {
            rows: out.test_rows.clone(),
            target: out.test_rows.iter().map(|&r| input.y[r as usize]).collect(),
            prediction: out.test.as_ref().map(|t| t.1.clone()).unwrap_or_default(),
        });
    TrainResponse {
        model: model_doc(model, Some(p)),
        effective_trees: u32_of(effective),
        metrics: MetricsOut {
            train: split_metrics(&out.train_metrics),
            test: out.test.as_ref().map(|t| split_metrics(&t.0)),
            cv,
        },
        preprocessing: PreprocessingOut {
            dropped_constant: input
                .dropped
                .iter()
                .map(|&f| input.names[f].clone())
                .collect(),
            n_train: u32_of(out.train_rows.len()),
            n_test: u32_of(out.test_rows.len()),
            smogn,
        },
        importance,
        shap_summary,
        test_predictions,
        report: SolverReport {
            stop_reason: out.stop,
            iterations: rounds as u64,
            evaluations: out.trees_built,
            elapsed_ms: budget.elapsed_ms(),
        },
        warnings,
    }
}

/// The `/predict` response.
#[must_use]
pub fn respond_predict(
    input: &PredictInput,
    out: &PredictOutput,
    budget: &Budget,
) -> PredictResponse {
    let model = &input.model;
    let d = model.n_features;
    let mut warnings = Vec::new();
    if input.background_ignored {
        warnings.push(Warning::at(
            "BACKGROUND_IGNORED",
            "/background",
            "background rows are used only with shap = \"interventional\"",
        ));
    }
    let shap = out.shap.as_ref().map(|s| {
        if let Some(w) = local_accuracy_warning(s.local_accuracy, s.scale) {
            warnings.push(w);
        }
        ShapOut {
            kind: input.shap,
            expected_value: s.expected_value,
            values: s.values.clone(),
            local_accuracy_max_abs: s.local_accuracy,
        }
    });
    let interactions = out.interactions.as_ref().map(|rows| {
        rows.iter()
            .map(|m| m.chunks(d.max(1)).map(<[f64]>::to_vec).collect())
            .collect()
    });
    PredictResponse {
        predictions: out.predictions.clone(),
        shap,
        interactions,
        model_summary: ModelSummary {
            source: match model.source {
                ModelSource::Native => "native",
                ModelSource::Xgboost => "xgboost_json",
            }
            .to_owned(),
            routing: match model.routing {
                Routing::F64 => "f64",
                Routing::F32 => "f32",
            }
            .to_owned(),
            n_trees: u32_of(model.trees.len()),
            effective_trees: u32_of(model.effective_trees()),
            n_leaves: u32_of(model.n_leaves()),
            max_depth: u32_of(model.max_depth()),
            n_features: u32_of(d),
            base_score: model.base_score,
        },
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations: input.rows.len() as u64,
            evaluations: out.traversals,
            elapsed_ms: budget.elapsed_ms(),
        },
        warnings,
    }
}

/// The PCA section with its warnings (components clamped to the varying features, near-equal
/// kept eigenvalues) and the cumulative contribution rates.
fn pca_out(
    input: &AnalyzeInput,
    out: &AnalyzeOutput,
    p: &Pca,
    warnings: &mut Vec<Warning>,
) -> PcaOut {
    let asked = input.pca.and_then(|(k, _)| k);
    if let Some(k) = asked.filter(|&k| k > out.varying.len()) {
        warnings.push(Warning::at(
            "PCA_COMPONENTS_CLAMPED",
            "/pca/components",
            format!(
                "{k} components asked, {} non-constant features: all of them are kept",
                out.varying.len()
            ),
        ));
    }
    let kept = p.loadings.len();
    let gap = p.eigenvalues[..kept.min(p.eigenvalues.len())]
        .windows(2)
        .map(|w| (w[0] - w[1]) / w[0].max(f64::MIN_POSITIVE))
        .fold(f64::INFINITY, f64::min);
    if gap < NEAR_EQUAL_EIGEN {
        warnings.push(Warning::at(
            "NEAR_EQUAL_EIGENVALUES",
            "/pca",
            format!(
                "kept eigenvalues differ by as little as {:.1} %: those components are not \
                 well defined and the composite score depends on rounding (spec §8 hazard 8)",
                100.0 * gap
            ),
        ));
    }
    let mut cumulative = Vec::with_capacity(p.rates.len());
    let mut acc = 0.0;
    for r in &p.rates {
        acc += r;
        cumulative.push(acc);
    }
    PcaOut {
        features: out
            .varying
            .iter()
            .map(|&f| input.names[f].clone())
            .collect(),
        eigenvalues: p.eigenvalues.clone(),
        contribution_rates: p.rates.clone(),
        cumulative_rates: cumulative,
        loadings: p.loadings.clone(),
        composite_scores: p.composite.clone(),
        scores: p.scores.clone(),
    }
}

/// The `/analyze` response.
#[must_use]
pub fn respond_analyze(
    input: &AnalyzeInput,
    out: &AnalyzeOutput,
    budget: &Budget,
) -> AnalyzeResponse {
    let names = &input.names;
    let mut warnings = Vec::new();
    if out.varying.is_empty() && (input.pca.is_some() || input.gra.is_some()) {
        warnings.push(Warning::new(
            "NO_VARYING_FEATURES",
            "every feature is constant: PCA and GRA have nothing to analyse",
        ));
    }
    let pca = out
        .pca
        .as_ref()
        .map(|p| pca_out(input, out, p, &mut warnings));
    let gra = out
        .gra
        .as_ref()
        .zip(input.gra)
        .map(|(grades, (rho, norm))| {
            let ranks = ranks(grades);
            GraOut {
                rho,
                normalise: norm,
                grades: out
                    .varying
                    .iter()
                    .zip(grades)
                    .zip(ranks)
                    .map(|((&f, &grade), rank)| GraGrade {
                        feature: names[f].clone(),
                        grade,
                        rank,
                    })
                    .collect(),
            }
        });
    let smogn = out
        .smogn
        .as_ref()
        .zip(input.smogn.as_ref())
        .map(|(s, (_, include))| {
            let data = include.then(|| SmognData {
                rows: s
                    .kept
                    .iter()
                    .map(|&r| input.x.row(r as usize))
                    .chain(s.new_rows.iter().cloned())
                    .collect(),
                target: s
                    .kept
                    .iter()
                    .map(|&r| input.y[r as usize])
                    .chain(s.new_targets.iter().copied())
                    .collect(),
            });
            let o = smogn_out(s, input.x.n_rows(), names, data);
            if let Some(w) = off_grid_warning(&o, "/smogn") {
                warnings.push(w);
            }
            o
        });
    AnalyzeResponse {
        constant_columns: out
            .constant
            .iter()
            .map(|&f| ConstantColumn {
                feature: names[f].clone(),
                index: u32_of(f),
                value: input.x.get(0, f),
            })
            .collect(),
        pca,
        gra,
        smogn,
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations: 1,
            evaluations: input.x.n_rows() as u64,
            elapsed_ms: budget.elapsed_ms(),
        },
        warnings,
    }
}

/// Rank by descending value, ties sharing the better rank (1-based).
fn ranks(v: &[f64]) -> Vec<u32> {
    v.iter()
        .map(|&g| u32_of(1 + v.iter().filter(|&&o| o > g).count()))
        .collect()
}
