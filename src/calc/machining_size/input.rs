//! Validation of the three requests into domain inputs (spec §2.5): every problem is collected
//! with its JSON pointer by the one [`Validator`]; model documents are read by
//! [`super::document`] with the pointer of their first defect.

use std::collections::HashSet;

use crate::calc::common::time_limit;
use crate::calc::{CalcFailure, Range, Validator};

use super::boost::{BoostParams, Method};
use super::data::{Matrix, n_train_rows};
use super::document::{self, DocLimits};
use super::error::{MODEL_INVALID, TOO_LARGE, UNSUPPORTED_MODEL};
use super::gra::Normalise;
use super::model::Model;
use super::smogn::SmognParams;
use super::wire::{
    self, AnalyzeRequest, FRACTION, GRA_RHO, GraNormalise, K_FOLD, LEARNING_RATE, MAX_BACKGROUND,
    MAX_BIN, MAX_DEPTH, MAX_FEATURES, MAX_INTERACTION_CELLS, MAX_INTERACTION_ROWS,
    MAX_INTERVENTIONAL_PAIRS, MAX_PREDICT_ROWS, MAX_ROWS, MAX_SCORE_CELLS, MAX_SHAP_CELLS,
    MAX_TREES, MIN_ROWS, N_ESTIMATORS, PCA_COMPONENTS, PredictRequest, REGULARISATION,
    RELEVANCE_PHI, SMOGN_K, SMOGN_PERTURBATION, SMOGN_THRESHOLD, TARGET, TEST_FRACTION,
    TrainOutputKind, TrainRequest, TreeMethod,
};

/// A validated `/train` request.
#[derive(Debug, Clone)]
pub struct TrainInput {
    /// Column names.
    pub names: Vec<String>,
    /// Feature matrix (all rows).
    pub x: Matrix,
    /// Targets.
    pub y: Vec<f64>,
    /// Boosting parameters.
    pub params: BoostParams,
    /// Candidate features (non-constant ones when `drop_constant`), ascending.
    pub features: Vec<usize>,
    /// Constant columns that were dropped.
    pub dropped: Vec<usize>,
    /// SMOGN on the training split.
    pub smogn: Option<SmognParams>,
    /// Holdout share.
    pub test_fraction: f64,
    /// Folds of cross-validation.
    pub k_fold: Option<usize>,
    /// The block of folds to evaluate (all when `None`).
    pub shard: Option<crate::calc::common::Shard>,
    /// Seed of the holdout and fold permutations.
    pub split_seed: u64,
    /// Optional outputs.
    pub outputs: TrainOutputs,
}

/// Which optional outputs `/train` computes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TrainOutputs {
    /// Importances.
    pub importance: bool,
    /// SHAP summary.
    pub shap_summary: bool,
    /// Holdout predictions.
    pub test_predictions: bool,
}

/// Which SHAP values a `/predict` request asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapKind {
    /// No SHAP values.
    None,
    /// Path-dependent TreeSHAP (cover-weighted conditional expectations).
    PathDependent,
    /// Interventional TreeSHAP against the background rows.
    Interventional,
}

impl From<wire::ShapKind> for ShapKind {
    fn from(k: wire::ShapKind) -> Self {
        match k {
            wire::ShapKind::None => Self::None,
            wire::ShapKind::PathDependent => Self::PathDependent,
            wire::ShapKind::Interventional => Self::Interventional,
        }
    }
}

/// A validated `/predict` request.
#[derive(Debug, Clone)]
pub struct PredictInput {
    /// The model.
    pub model: Model,
    /// Rows, prepared for the model's routing ([`Model::prepare_row`]).
    pub rows: Vec<Vec<f64>>,
    /// SHAP values asked for.
    pub shap: ShapKind,
    /// Prepared background rows (interventional SHAP).
    pub background: Vec<Vec<f64>>,
    /// Interaction values asked for.
    pub interactions: bool,
    /// `background` was sent but is not used.
    pub background_ignored: bool,
}

/// A validated `/analyze` request.
#[derive(Debug, Clone)]
pub struct AnalyzeInput {
    /// Column names.
    pub names: Vec<String>,
    /// Feature matrix.
    pub x: Matrix,
    /// Targets.
    pub y: Vec<f64>,
    /// GRA: ρ and normalisation.
    pub gra: Option<(f64, Normalise)>,
    /// PCA: components asked for (None = all) and whether to return scores.
    pub pca: Option<(Option<usize>, bool)>,
    /// SMOGN preview and whether to return the data.
    pub smogn: Option<(SmognParams, bool)>,
}

/// Names: 1..200, unique, non-empty.
fn check_names(v: &mut Validator, names: &[String]) {
    if names.is_empty() || names.len() > MAX_FEATURES {
        v.push_code(
            TOO_LARGE,
            "/feature_names",
            format!("must name 1..{MAX_FEATURES} features, got {}", names.len()),
        );
    }
    let mut seen = HashSet::new();
    for (i, n) in names.iter().enumerate() {
        if n.trim().is_empty() {
            v.push(format!("/feature_names/{i}"), "must not be empty");
        } else if !seen.insert(n.as_str()) {
            v.push(
                format!("/feature_names/{i}"),
                format!("duplicate feature name \"{n}\""),
            );
        }
    }
}

/// Rows: count in `lo..=hi`, each of width `d`, finite. Reports the first ragged row (with a
/// count) and the first non-finite value.
fn check_rows(v: &mut Validator, at: &str, rows: &[Vec<f64>], d: usize, lo: usize, hi: usize) {
    if rows.len() < lo || rows.len() > hi {
        let code = if rows.len() > hi {
            TOO_LARGE
        } else {
            crate::calc::INVALID_INPUT
        };
        v.push_code(
            code,
            at,
            format!("must have {lo}..{hi} rows, got {}", rows.len()),
        );
    }
    let mut ragged = rows.iter().enumerate().filter(|(_, r)| r.len() != d);
    if let Some((i, r)) = ragged.next() {
        let more = ragged.count();
        let tail = if more > 0 {
            format!(" ({more} more rows of the wrong length follow)")
        } else {
            String::new()
        };
        v.push(
            format!("{at}/{i}"),
            format!(
                "must have {d} values (one per feature), got {}{tail}",
                r.len()
            ),
        );
    }
    if let Some((i, j)) = rows
        .iter()
        .enumerate()
        .find_map(|(i, r)| r.iter().position(|x| !x.is_finite()).map(|j| (i, j)))
    {
        v.push(
            format!("{at}/{i}/{j}"),
            format!("must be a finite number, got {}", rows[i][j]),
        );
    }
}

/// Names, rows and target of `/train` and `/analyze`.
fn check_data(v: &mut Validator, names: &[String], rows: &[Vec<f64>], target: &[f64]) {
    check_names(v, names);
    check_rows(v, "/rows", rows, names.len(), MIN_ROWS, MAX_ROWS);
    if target.len() != rows.len() {
        v.push(
            "/target",
            format!(
                "must have one value per row ({}), got {}",
                rows.len(),
                target.len()
            ),
        );
    }
    v.all_in("/target", "target", target, TARGET);
}

fn smogn_params(
    v: &mut Validator,
    at: &str,
    relevance: &[[f64; 2]],
    (threshold, k, perturbation, seed): (f64, u32, f64, u64),
) -> SmognParams {
    if relevance.len() < 2 {
        v.push(
            format!("{at}/relevance"),
            format!(
                "needs at least 2 control points [y, φ], got {}",
                relevance.len()
            ),
        );
    }
    for (i, p) in relevance.iter().enumerate() {
        v.range(&format!("{at}/relevance/{i}/0"), "y", p[0], Range::FINITE);
        v.range(&format!("{at}/relevance/{i}/1"), "φ", p[1], RELEVANCE_PHI);
        if i > 0 && p[0] <= relevance[i - 1][0] {
            v.push(
                format!("{at}/relevance/{i}/0"),
                format!(
                    "control points must be strictly increasing in y: {} after {}",
                    p[0],
                    relevance[i - 1][0]
                ),
            );
        }
    }
    v.range(
        &format!("{at}/threshold"),
        "threshold",
        threshold,
        SMOGN_THRESHOLD,
    );
    v.uint(&format!("{at}/k"), "k", u64::from(k), SMOGN_K);
    v.range(
        &format!("{at}/perturbation"),
        "perturbation",
        perturbation,
        SMOGN_PERTURBATION,
    );
    SmognParams {
        relevance: relevance.iter().map(|p| (p[0], p[1])).collect(),
        threshold,
        k: k as usize,
        perturbation,
        seed,
    }
}

/// The failure of a validator known to hold problems.
fn failure(v: Validator) -> CalcFailure {
    v.finish().err().unwrap_or_else(|| {
        CalcFailure::general(
            crate::calc::ProblemClass::InvalidInput,
            crate::calc::INVALID_INPUT,
            "invalid request",
        )
    })
}

/// Columns of `x` that are constant.
fn constant_columns(x: &Matrix) -> Vec<usize> {
    (0..x.n_cols()).filter(|&f| x.is_constant(f)).collect()
}

impl TryFrom<TrainRequest> for TrainInput {
    type Error = CalcFailure;

    #[expect(
        clippy::too_many_lines,
        reason = "one flat list of the spec's §2.5 rejections, each with its pointer; splitting it \
                  would scatter the cross-field rules"
    )]
    fn try_from(req: TrainRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        time_limit(&mut v, req.time_limit_ms);
        check_data(&mut v, &req.feature_names, &req.rows, &req.target);
        let p = &req.params;
        v.uint(
            "/params/n_estimators",
            "n_estimators",
            u64::from(p.n_estimators),
            N_ESTIMATORS,
        );
        v.uint(
            "/params/max_depth",
            "max_depth",
            u64::from(p.max_depth),
            MAX_DEPTH,
        );
        v.range(
            "/params/learning_rate",
            "learning_rate",
            p.learning_rate,
            LEARNING_RATE,
        );
        v.range(
            "/params/reg_lambda",
            "reg_lambda",
            p.reg_lambda,
            REGULARISATION,
        );
        v.range(
            "/params/reg_alpha",
            "reg_alpha",
            p.reg_alpha,
            REGULARISATION,
        );
        v.range("/params/gamma", "gamma", p.gamma, REGULARISATION);
        v.range(
            "/params/min_child_weight",
            "min_child_weight",
            p.min_child_weight,
            REGULARISATION,
        );
        v.range(
            "/params/colsample_bytree",
            "colsample_bytree",
            p.colsample_bytree,
            FRACTION,
        );
        v.range("/params/subsample", "subsample", p.subsample, FRACTION);
        if let Some(b) = p.base_score {
            v.range("/params/base_score", "base_score", b, TARGET);
        }
        v.uint("/params/max_bin", "max_bin", u64::from(p.max_bin), MAX_BIN);
        if p.reg_lambda == 0.0 && p.min_child_weight == 0.0 {
            v.push(
                "/params/reg_lambda",
                "reg_lambda must be > 0 when min_child_weight is 0 (an empty child would divide \
                 by zero, spec §8 hazard 4)",
            );
        }
        let val = &req.validation;
        v.range(
            "/validation/test_fraction",
            "test_fraction",
            val.test_fraction,
            TEST_FRACTION,
        );
        if let Some(k) = val.k_fold {
            v.uint("/validation/k_fold", "k_fold", u64::from(k), K_FOLD);
        }
        let shard = crate::calc::common::shard(&mut v, req.shard);
        v.ensure(
            req.shard.is_none() || val.k_fold.is_some(),
            "/shard",
            || "shard splits the k-fold cross-validation: set validation.k_fold".to_owned(),
        );
        let smogn = req.preprocessing.smogn.as_ref().map(|s| {
            smogn_params(
                &mut v,
                "/preprocessing/smogn",
                &s.relevance,
                (s.threshold, s.k, s.perturbation, s.seed),
            )
        });
        if !v.is_clean() {
            return Err(failure(v));
        }
        // Rules that need the data's shape.
        let n = req.rows.len();
        let min_rows = 2.0 * p.min_child_weight.max(1.0);
        let n_train = n_train_rows(n, val.test_fraction);
        if (n_train as f64) < min_rows {
            v.push(
                "/params/min_child_weight",
                format!(
                    "the training split has {n_train} rows but needs at least \
                     2·max(1, min_child_weight) = {min_rows} (spec §2.5)"
                ),
            );
        }
        if let Some(k) = val.k_fold {
            let k = k as usize;
            let smallest = n - n.div_ceil(k);
            if (smallest as f64) < min_rows {
                v.push(
                    "/validation/k_fold",
                    format!(
                        "{k} folds of {n} rows leave {smallest} training rows in a fold, fewer than \
                         2·max(1, min_child_weight) = {min_rows}"
                    ),
                );
            }
        }
        let d = req.feature_names.len();
        let x = Matrix::from_rows(req.rows, d);
        let y = req.target;
        if y.iter().all(|&t| (t - y[0]) == 0.0) {
            v.push(
                "/target",
                "all targets are equal: there is nothing to learn (spec §2.5)",
            );
        }
        let dropped = if req.preprocessing.drop_constant {
            constant_columns(&x)
        } else {
            Vec::new()
        };
        let features: Vec<usize> = (0..d).filter(|f| !dropped.contains(f)).collect();
        if features.is_empty() {
            v.push(
                "/rows",
                "every feature is constant: there is nothing to split on (set \
                 preprocessing.drop_constant to false to fit the mean only)",
            );
        } else if (p.colsample_bytree * features.len() as f64).floor() < 1.0 {
            v.push(
                "/params/colsample_bytree",
                format!(
                    "colsample_bytree {} leaves 0 of {} features per tree (⌊colsample·d⌋ must be \
                     ≥ 1, as XGBoost requires)",
                    p.colsample_bytree,
                    features.len()
                ),
            );
        }
        v.finish()?;
        let outputs = TrainOutputs {
            importance: req.outputs.contains(&TrainOutputKind::Importance),
            shap_summary: req.outputs.contains(&TrainOutputKind::ShapSummary),
            test_predictions: req.outputs.contains(&TrainOutputKind::TestPredictions),
        };
        Ok(Self {
            names: req.feature_names,
            x,
            y,
            params: BoostParams {
                n_estimators: p.n_estimators as usize,
                max_depth: p.max_depth as usize,
                learning_rate: p.learning_rate,
                reg_lambda: p.reg_lambda,
                reg_alpha: p.reg_alpha,
                gamma: p.gamma,
                min_child_weight: p.min_child_weight,
                colsample_bytree: p.colsample_bytree,
                subsample: p.subsample,
                seed: p.seed,
                base_score: p.base_score,
                method: match p.tree_method {
                    TreeMethod::Exact => Method::Exact,
                    TreeMethod::Hist => Method::Hist {
                        max_bin: p.max_bin as usize,
                    },
                },
            },
            features,
            dropped,
            smogn,
            test_fraction: val.test_fraction,
            k_fold: val.k_fold.map(|k| k as usize),
            shard,
            split_seed: val.seed,
            outputs,
        })
    }
}

const LIMITS: DocLimits = DocLimits {
    max_trees: MAX_TREES,
    max_features: MAX_FEATURES,
};

/// Reads the `model` member: `{"xgboost_json": ...}` or our document.
fn read_model(v: &mut Validator, doc: &serde_json::Value) -> Option<Model> {
    let wrapped = doc.as_object().filter(|o| o.contains_key("xgboost_json"));
    let result = match wrapped {
        Some(o) => {
            if let Some(k) = o.keys().find(|k| *k != "xgboost_json") {
                v.push(
                    format!("/model/{k}"),
                    format!("unknown field `{k}` next to `xgboost_json`"),
                );
                return None;
            }
            document::read_xgboost(&o["xgboost_json"], "/model/xgboost_json", LIMITS)
        }
        None => document::read_native(doc, "/model", LIMITS),
    };
    match result {
        Ok(m) => Some(m),
        Err(e) => {
            let unsupported = e.detail.contains("supported");
            v.push_code(
                if unsupported {
                    UNSUPPORTED_MODEL
                } else {
                    MODEL_INVALID
                },
                e.pointer,
                e.detail,
            );
            None
        }
    }
}

impl TryFrom<PredictRequest> for PredictInput {
    type Error = CalcFailure;

    fn try_from(req: PredictRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        time_limit(&mut v, req.time_limit_ms);
        let Some(model) = read_model(&mut v, &req.model) else {
            return Err(failure(v));
        };
        let d = model.n_features;
        check_rows(&mut v, "/rows", &req.rows, d, 1, MAX_PREDICT_ROWS);
        if let Some(names) = &req.feature_names {
            if names.len() != d {
                v.push(
                    "/feature_names",
                    format!("the model has {d} features, got {} names", names.len()),
                );
            } else if !model.feature_names.is_empty()
                && let Some(i) = (0..d).find(|&i| names[i] != model.feature_names[i])
            {
                v.push(
                    format!("/feature_names/{i}"),
                    format!(
                        "must be the model's feature \"{}\", got \"{}\"",
                        model.feature_names[i], names[i]
                    ),
                );
            }
        }
        let n = req.rows.len();
        let shap = ShapKind::from(req.shap);
        if shap != ShapKind::None && n * d > MAX_SHAP_CELLS {
            v.push_code(
                TOO_LARGE,
                "/rows",
                format!(
                    "SHAP values for {n} rows × {d} features exceed {MAX_SHAP_CELLS} numbers; \
                     send fewer rows per request"
                ),
            );
        }
        let background_ignored = req.background.is_some() && shap != ShapKind::Interventional;
        let mut background = Vec::new();
        if shap == ShapKind::Interventional {
            match &req.background {
                None => v.push(
                    "/background",
                    "interventional SHAP needs background rows (spec §2.5)",
                ),
                Some(b) => {
                    check_rows(&mut v, "/background", b, d, 1, MAX_BACKGROUND);
                    if n * b.len() > MAX_INTERVENTIONAL_PAIRS {
                        v.push_code(
                            TOO_LARGE,
                            "/background",
                            format!(
                                "{n} rows × {} background rows exceed {MAX_INTERVENTIONAL_PAIRS} \
                                 pairs",
                                b.len()
                            ),
                        );
                    }
                    background = b.iter().map(|r| model.prepare_row(r)).collect();
                }
            }
        }
        if req.interactions && (n > MAX_INTERACTION_ROWS || n * d * d > MAX_INTERACTION_CELLS) {
            v.push_code(
                TOO_LARGE,
                "/interactions",
                format!(
                    "interaction values need rows ≤ {MAX_INTERACTION_ROWS} and rows·d² ≤ \
                     {MAX_INTERACTION_CELLS}, got {n} rows and d = {d}"
                ),
            );
        }
        v.finish()?;
        let rows = req
            .rows
            .into_iter()
            .map(|r| model.prepare_owned(r))
            .collect();
        Ok(Self {
            model,
            rows,
            shap,
            background,
            interactions: req.interactions,
            background_ignored,
        })
    }
}

impl TryFrom<AnalyzeRequest> for AnalyzeInput {
    type Error = CalcFailure;

    fn try_from(req: AnalyzeRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        time_limit(&mut v, req.time_limit_ms);
        check_data(&mut v, &req.feature_names, &req.rows, &req.target);
        let gra = req.gra.as_ref().map(|g| {
            v.range("/gra/rho", "rho", g.rho, GRA_RHO);
            (
                g.rho,
                match g.normalise {
                    GraNormalise::Mean => Normalise::Mean,
                    GraNormalise::None => Normalise::None,
                },
            )
        });
        let pca = req.pca.as_ref().map(|p| {
            if let Some(k) = p.components {
                v.uint(
                    "/pca/components",
                    "components",
                    u64::from(k),
                    PCA_COMPONENTS,
                );
            }
            if p.scores {
                let k = p.components.map_or(req.feature_names.len(), |k| k as usize);
                if req.rows.len() * k > MAX_SCORE_CELLS {
                    v.push_code(
                        TOO_LARGE,
                        "/pca/scores",
                        format!(
                            "scores of {} rows × {k} components exceed {MAX_SCORE_CELLS} numbers",
                            req.rows.len()
                        ),
                    );
                }
            }
            (p.components.map(|k| k as usize), p.scores)
        });
        let smogn = req.smogn.as_ref().map(|s| {
            (
                smogn_params(
                    &mut v,
                    "/smogn",
                    &s.relevance,
                    (s.threshold, s.k, s.perturbation, s.seed),
                ),
                s.include_data,
            )
        });
        v.finish()?;
        let d = req.feature_names.len();
        Ok(Self {
            names: req.feature_names,
            x: Matrix::from_rows(req.rows, d),
            y: req.target,
            gra,
            pca,
            smogn,
        })
    }
}
