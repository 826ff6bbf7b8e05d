//! The rules between fields of the three requests (spec §2.5), turning them into domain inputs.
//! Every per-field rule (ranges, list lengths, finite numbers) is declared on the wire types and
//! checked at the door; what is left here is what JSON Schema cannot state (a row's width tied
//! to the feature names or the model, orderings, the data's shape against the parameters, the
//! work an answer needs), each rule with its own code ([`TRAIN_RULES`], [`PREDICT_RULES`],
//! [`ANALYZE_RULES`]). Model documents are read by [`super::document`] with the pointer of their
//! first defect (codes `MODEL_INVALID`, `UNSUPPORTED_MODEL`).

use std::collections::HashSet;

use crate::calc::common::{self, RESPONSE_TOO_LARGE_RULE, SHARD_INDEX_BELOW_COUNT};
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, CrossRule, Validator};

use super::boost::{BoostParams, Method};
use super::data::{Matrix, n_train_rows};
use super::doc_tree::Doc;
use super::document::{self, DocLimits};
use super::error::{
    DEADLINE_EXCEEDED, GRA_ZERO_MEAN, MODEL_INVALID, SMOGN_DEGENERATE_RELEVANCE, TOO_LARGE,
    UNSUPPORTED_MODEL,
};
use super::gra::Normalise;
use super::model::Model;
use super::smogn::SmognParams;
use super::wire::{
    AnalyzeRequest, MAX_FEATURES, MAX_INTERACTION_CELLS, MAX_INTERACTION_ROWS,
    MAX_INTERVENTIONAL_PAIRS, MAX_SCORE_CELLS, MAX_SHAP_CELLS, MAX_TREES, PredictRequest,
    RELEVANCE_PHI, TrainRequest, TreeMethod,
};

crate::calc::rules::cross_rules! {
    invalid FEATURE_NAME_EMPTY ["/feature_names/*"]
        "Every feature name holds a character other than white space.";
    invalid FEATURE_NAME_DUPLICATE ["/feature_names/*"] "Feature names are unique.";
    invalid ROW_WIDTH ["/rows/*", "/feature_names"]
        "Every row of rows has one value per name of feature_names.";
    invalid TARGET_LENGTH ["/target", "/rows"] "target has one value per row of rows.";
    invalid CONSTANT_TARGET ["/target"]
        "Not all targets are equal (else there is nothing to learn).";
    invalid REG_LAMBDA_ZERO ["/params/reg_lambda", "/params/min_child_weight"]
        "params.reg_lambda > 0 when params.min_child_weight is 0 (spec §8 hazard 4).";
    invalid TRAINING_ROWS ["/params/min_child_weight", "/validation/test_fraction", "/rows"]
        "The training split (rows less the holdout) has at least 2·max(1, min_child_weight) rows.";
    invalid FOLD_ROWS ["/validation/k_fold", "/params/min_child_weight", "/rows"]
        "Each k-fold training split (n − ⌈n/k⌉ rows) has at least 2·max(1, min_child_weight) rows.";
    invalid ALL_FEATURES_CONSTANT ["/rows", "/preprocessing/drop_constant"]
        "With preprocessing.drop_constant, at least one feature column is not constant.";
    invalid COLSAMPLE_NO_FEATURE ["/params/colsample_bytree", "/rows"]
        "⌊colsample_bytree · d⌋ ≥ 1 for the d features left after dropping constant columns.";
    invalid SHARD_NOT_APPLICABLE ["/shard", "/validation/k_fold"]
        "shard is given only with validation.k_fold (it splits the folds).";
    invalid TRAIN_RELEVANCE_PHI("RELEVANCE_PHI") ["/preprocessing/smogn/relevance/*/1"]
        "The relevance φ of every SMOGN control point [y, φ] is in [0, 1].";
    invalid TRAIN_RELEVANCE_ORDER("RELEVANCE_ORDER") ["/preprocessing/smogn/relevance/*/0"]
        "The y of the SMOGN control points [y, φ] strictly increase.";
    invalid ANALYZE_RELEVANCE_PHI("RELEVANCE_PHI") ["/smogn/relevance/*/1"]
        "The relevance φ of every SMOGN control point [y, φ] is in [0, 1].";
    invalid ANALYZE_RELEVANCE_ORDER("RELEVANCE_ORDER") ["/smogn/relevance/*/0"]
        "The y of the SMOGN control points [y, φ] strictly increase.";
    /// SMOGN of `/train` finds rare and normal samples (found while computing).
    infeasible TRAIN_SMOGN_DEGENERATE(SMOGN_DEGENERATE_RELEVANCE) ["/preprocessing/smogn/relevance"]
        "SMOGN's relevance marks some but not all training samples as rare.";
    /// SMOGN of `/analyze` finds rare and normal samples (found while computing).
    infeasible ANALYZE_SMOGN_DEGENERATE(SMOGN_DEGENERATE_RELEVANCE) ["/smogn/relevance"]
        "SMOGN's relevance marks some but not all samples as rare.";
    invalid MODEL_DOCUMENT(MODEL_INVALID) ["/model"]
        "The model is our document (format machining-size-gbdt/1) or {\"xgboost_json\": ...}, with \
         children in range, no cycles or shared children, depth ≤ 64, ≤ 5000 trees, ≤ 1 000 000 \
         nodes, finite numbers and split features below n_features.";
    invalid MODEL_SUPPORTED(UNSUPPORTED_MODEL) ["/model"]
        "The model's objective is reg:squarederror, its booster gbtree, with a single output.";
    invalid PREDICT_ROW_WIDTH("ROW_WIDTH") ["/rows/*", "/background/*", "/model"]
        "Every row of rows (and of background) has one value per model feature.";
    invalid FEATURE_NAMES_MISMATCH ["/feature_names", "/model"]
        "feature_names, when given, has one name per model feature and equals the model's names.";
    invalid BACKGROUND_REQUIRED ["/background", "/shap"]
        "background is given when shap is interventional.";
    too_large PREDICT_WORK(TOO_LARGE) ["/rows", "/background", "/interactions"]
        "With SHAP, rows·d ≤ 4 000 000; interventional rows·background ≤ 1 000 000; with \
         interactions, rows ≤ 1000 and rows·d² ≤ 2 000 000 (d: model features).";
    too_large ANALYZE_WORK(TOO_LARGE) ["/pca/scores", "/pca/components", "/rows"]
        "With pca.scores, rows·components ≤ 4 000 000.";
    /// A GRA series can be normalised by its mean (found while computing).
    infeasible GRA_MEAN(GRA_ZERO_MEAN) ["/gra/normalise", "/rows", "/target"]
        "With gra.normalise mean, no series (feature or target) has a mean of 0.";
    /// An answer that cannot be partial is finished within the budget (found while computing).
    too_large DEADLINE(DEADLINE_EXCEEDED) ["/time_limit_ms"]
        "The work of an answer that cannot be partial (SHAP values, an analysis) ends within the \
         request's time limit.";
}

/// The rules between fields of `POST /v1/machining-size/train`, as the document lists them.
pub const TRAIN_RULES: &[CrossRule] = &[
    FEATURE_NAME_EMPTY,
    FEATURE_NAME_DUPLICATE,
    ROW_WIDTH,
    TARGET_LENGTH,
    CONSTANT_TARGET,
    REG_LAMBDA_ZERO,
    TRAINING_ROWS,
    FOLD_ROWS,
    ALL_FEATURES_CONSTANT,
    COLSAMPLE_NO_FEATURE,
    SHARD_INDEX_BELOW_COUNT,
    SHARD_NOT_APPLICABLE,
    TRAIN_RELEVANCE_PHI,
    TRAIN_RELEVANCE_ORDER,
    TRAIN_SMOGN_DEGENERATE,
    DEADLINE,
    RESPONSE_TOO_LARGE_RULE,
];

/// The rules between fields of `POST /v1/machining-size/predict`, as the document lists them.
pub const PREDICT_RULES: &[CrossRule] = &[
    MODEL_DOCUMENT,
    MODEL_SUPPORTED,
    PREDICT_ROW_WIDTH,
    FEATURE_NAMES_MISMATCH,
    BACKGROUND_REQUIRED,
    PREDICT_WORK,
    DEADLINE,
    RESPONSE_TOO_LARGE_RULE,
];

/// The rules between fields of `POST /v1/machining-size/analyze`, as the document lists them.
pub const ANALYZE_RULES: &[CrossRule] = &[
    FEATURE_NAME_EMPTY,
    FEATURE_NAME_DUPLICATE,
    ROW_WIDTH,
    TARGET_LENGTH,
    ANALYZE_RELEVANCE_PHI,
    ANALYZE_RELEVANCE_ORDER,
    ANALYZE_WORK,
    GRA_MEAN,
    ANALYZE_SMOGN_DEGENERATE,
    DEADLINE,
    RESPONSE_TOO_LARGE_RULE,
];

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
    /// Optional outputs asked for.
    pub outputs: Vec<TrainOutputKind>,
}

/// An optional output of `/train`: the request's output kind.
pub use super::wire::TrainOutputKind;

/// Which SHAP values `/predict` computes: the request's `shap`.
pub use super::wire::ShapKind;

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

/// Names (1..200 of them: checked at the door): unique, not blank.
fn check_names(v: &mut Validator, names: &[String]) {
    let mut seen = HashSet::new();
    for (i, n) in names.iter().enumerate() {
        if n.trim().is_empty() {
            rule!(v, FEATURE_NAME_EMPTY, format!("/feature_names/{i}"); "must not be empty");
        } else if !seen.insert(n.as_str()) {
            rule!(v, FEATURE_NAME_DUPLICATE, format!("/feature_names/{i}");
                "duplicate feature name \"{n}\"");
        }
    }
}

/// Rows (their count and finite values: checked at the door): each of width `d`. Reports the
/// first ragged row (with a count).
fn check_widths(v: &mut Validator, rule: &CrossRule, at: &str, rows: &[Vec<f64>], d: usize) {
    let mut ragged = rows.iter().enumerate().filter(|(_, r)| r.len() != d);
    if let Some((i, r)) = ragged.next() {
        let more = ragged.count();
        let tail = if more > 0 {
            format!(" ({more} more rows of the wrong length follow)")
        } else {
            String::new()
        };
        rule!(v, rule, format!("{at}/{i}");
            "must have {d} values (one per feature), got {}{tail}", r.len());
    }
}

/// Names, rows and target of `/train` and `/analyze`.
fn check_data(v: &mut Validator, names: &[String], rows: &[Vec<f64>], target: &[f64]) {
    check_names(v, names);
    check_widths(v, &ROW_WIDTH, "/rows", rows, names.len());
    ensure_rule!(v, target.len() == rows.len(), TARGET_LENGTH, "/target";
        "must have one value per row ({}), got {}", rows.len(), target.len());
}

/// SMOGN's parameters (ranges and the count of control points: checked at the door); the
/// control points' φ in [0, 1] and increasing y (`rules`: φ rule, order rule of the endpoint).
fn smogn_params(
    v: &mut Validator,
    at: &str,
    (phi_rule, order_rule): (&CrossRule, &CrossRule),
    relevance: &[[f64; 2]],
    (threshold, k, perturbation, seed): (f64, u32, f64, u64),
) -> SmognParams {
    for (i, p) in relevance.iter().enumerate() {
        ensure_rule!(v, RELEVANCE_PHI.contains(p[1]), phi_rule, format!("{at}/relevance/{i}/1");
            "φ must be {RELEVANCE_PHI}, got {}", p[1]);
        if i > 0 && p[0] <= relevance[i - 1][0] {
            rule!(v, order_rule, format!("{at}/relevance/{i}/0");
                "control points must be strictly increasing in y: {} after {}", p[0],
                relevance[i - 1][0]);
        }
    }
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
    v.finish()
        .err()
        .unwrap_or_else(|| MODEL_DOCUMENT.fail_general("invalid request"))
}

/// Columns of `x` that are constant.
fn constant_columns(x: &Matrix) -> Vec<usize> {
    (0..x.n_cols()).filter(|&f| x.is_constant(f)).collect()
}

impl TryFrom<TrainRequest> for TrainInput {
    type Error = CalcFailure;

    fn try_from(req: TrainRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        check_data(&mut v, &req.feature_names, &req.rows, &req.target);
        let p = &req.params;
        ensure_rule!(v, !(p.reg_lambda == 0.0 && p.min_child_weight == 0.0),
            REG_LAMBDA_ZERO, "/params/reg_lambda";
            "reg_lambda must be > 0 when min_child_weight is 0 (an empty child would divide \
                 by zero, spec §8 hazard 4)");
        let val = &req.validation;
        let shard = common::shard_rule(&mut v, req.shard);
        ensure_rule!(v, req.shard.is_none() || val.k_fold.is_some(), SHARD_NOT_APPLICABLE, "/shard";
            "shard splits the k-fold cross-validation: set validation.k_fold");
        let smogn = req.preprocessing.smogn.as_ref().map(|s| {
            smogn_params(
                &mut v,
                "/preprocessing/smogn",
                (&TRAIN_RELEVANCE_PHI, &TRAIN_RELEVANCE_ORDER),
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
            rule!(v, TRAINING_ROWS, "/params/min_child_weight";
                "the training split has {n_train} rows but needs at least \
                     2·max(1, min_child_weight) = {min_rows} (spec §2.5)");
        }
        if let Some(k) = val.k_fold {
            let k = k as usize;
            let smallest = n - n.div_ceil(k);
            if (smallest as f64) < min_rows {
                rule!(v, FOLD_ROWS, "/validation/k_fold";
                    "{k} folds of {n} rows leave {smallest} training rows in a fold, fewer than \
                         2·max(1, min_child_weight) = {min_rows}");
            }
        }
        let d = req.feature_names.len();
        let x = Matrix::from_rows(req.rows, d);
        let y = req.target;
        if y.iter().all(|&t| (t - y[0]) == 0.0) {
            rule!(v, CONSTANT_TARGET, "/target";
                "all targets are equal: there is nothing to learn (spec §2.5)");
        }
        let dropped = if req.preprocessing.drop_constant {
            constant_columns(&x)
        } else {
            Vec::new()
        };
        let features: Vec<usize> = (0..d).filter(|f| !dropped.contains(f)).collect();
        if features.is_empty() {
            rule!(v, ALL_FEATURES_CONSTANT, "/rows";
                "every feature is constant: there is nothing to split on (set \
                 preprocessing.drop_constant to false to fit the mean only)");
        } else if (p.colsample_bytree * features.len() as f64).floor() < 1.0 {
            rule!(v, COLSAMPLE_NO_FEATURE, "/params/colsample_bytree";
                "colsample_bytree {} leaves 0 of {} features per tree (⌊colsample·d⌋ must be \
                     ≥ 1, as XGBoost requires)",
                p.colsample_bytree, features.len());
        }
        v.finish()?;
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
            outputs: req.outputs,
        })
    }
}

const LIMITS: DocLimits = DocLimits {
    max_trees: MAX_TREES,
    max_features: MAX_FEATURES,
};

/// Reads the `model` member: `{"xgboost_json": ...}` or our document.
fn read_model(v: &mut Validator, doc: &Doc) -> Option<Model> {
    let wrapped = doc.as_object().filter(|o| o.contains_key("xgboost_json"));
    let result = match wrapped {
        Some(o) => {
            if let Some(k) = o.keys().find(|k| *k != "xgboost_json") {
                // A member the published schema does not allow (`additionalProperties: false`):
                // a per-field rule the door cannot see inside the untyped model, so it keeps the
                // per-field code.
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
            if e.detail.starts_with("unknown field") {
                // An unknown member fails the published shape (`additionalProperties: false`),
                // a per-field rule the door cannot see inside the untyped model: the per-field
                // code.
                v.push(e.pointer, e.detail);
            } else {
                rule!(v, if unsupported { MODEL_SUPPORTED } else { MODEL_DOCUMENT }, e.pointer;
                    "{}", e.detail);
            }
            None
        }
    }
}

impl TryFrom<PredictRequest> for PredictInput {
    type Error = CalcFailure;

    fn try_from(mut req: PredictRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let model = read_model(&mut v, &req.model);
        // The document's tree is not needed once read: free it before the work is queued.
        req.model = Doc::Null;
        let Some(model) = model else {
            return Err(failure(v));
        };
        let d = model.n_features;
        check_widths(&mut v, &PREDICT_ROW_WIDTH, "/rows", &req.rows, d);
        if let Some(names) = &req.feature_names {
            if names.len() != d {
                rule!(v, FEATURE_NAMES_MISMATCH, "/feature_names";
                    "the model has {d} features, got {} names", names.len());
            } else if !model.feature_names.is_empty()
                && let Some(i) = (0..d).find(|&i| names[i] != model.feature_names[i])
            {
                rule!(v, FEATURE_NAMES_MISMATCH, format!("/feature_names/{i}");
                    "must be the model's feature \"{}\", got \"{}\"", model.feature_names[i],
                    names[i]);
            }
        }
        let n = req.rows.len();
        let shap = req.shap;
        if shap != ShapKind::None && n * d > MAX_SHAP_CELLS {
            rule!(v, PREDICT_WORK, "/rows";
                "SHAP values for {n} rows × {d} features exceed {MAX_SHAP_CELLS} numbers; \
                     send fewer rows per request");
        }
        let background_ignored = req.background.is_some() && shap != ShapKind::Interventional;
        let mut background = Vec::new();
        if shap == ShapKind::Interventional {
            match &req.background {
                None => rule!(v, BACKGROUND_REQUIRED, "/background";
                    "interventional SHAP needs background rows (spec §2.5)"),
                Some(b) => {
                    check_widths(&mut v, &PREDICT_ROW_WIDTH, "/background", b, d);
                    if n * b.len() > MAX_INTERVENTIONAL_PAIRS {
                        rule!(v, PREDICT_WORK, "/background";
                            "{n} rows × {} background rows exceed {MAX_INTERVENTIONAL_PAIRS} \
                                 pairs",
                            b.len());
                    }
                    background = b.iter().map(|r| model.prepare_row(r)).collect();
                }
            }
        }
        if req.interactions && (n > MAX_INTERACTION_ROWS || n * d * d > MAX_INTERACTION_CELLS) {
            rule!(v, PREDICT_WORK, "/interactions";
                "interaction values need rows ≤ {MAX_INTERACTION_ROWS} and rows·d² ≤ \
                     {MAX_INTERACTION_CELLS}, got {n} rows and d = {d}");
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
        check_data(&mut v, &req.feature_names, &req.rows, &req.target);
        let gra = req.gra.as_ref().map(|g| (g.rho, g.normalise));
        let pca = req.pca.as_ref().map(|p| {
            if p.scores {
                let k = p.components.map_or(req.feature_names.len(), |k| k as usize);
                if req.rows.len() * k > MAX_SCORE_CELLS {
                    rule!(v, ANALYZE_WORK, "/pca/scores";
                        "scores of {} rows × {k} components exceed {MAX_SCORE_CELLS} numbers",
                        req.rows.len());
                }
            }
            (p.components.map(|k| k as usize), p.scores)
        });
        let smogn = req.smogn.as_ref().map(|s| {
            (
                smogn_params(
                    &mut v,
                    "/smogn",
                    (&ANALYZE_RELEVANCE_PHI, &ANALYZE_RELEVANCE_ORDER),
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
