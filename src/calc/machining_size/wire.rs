//! Wire types of `POST /v1/machining-size/train`, `/predict` and `/analyze` (spec §2, §5, §10),
//! the module's bound constants and the per-field rules (`#[rule(...)]`, checked at the door and
//! stated in the document).
//!
//! Targets and predictions are in the caller's unit (the paper's sizes are in mm); features in
//! theirs. Field names follow the spec (`n_estimators`, `reg_alpha`, `MAE`, ...), so XGBoost users
//! recognise them.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::common::{Shard, ShardOut, TimeLimited, Warning};
use crate::numerics::SolverReport;

// ---------------------------------------------------------------------------------------------
// Bounds (one source: the `#[rule]`s below read these; the door checks them, the document
// states them)
// ---------------------------------------------------------------------------------------------

/// Most rows of a data set (spec §2.5).
pub const MAX_ROWS: usize = 100_000;
/// Fewest rows of a data set to train on or analyse (spec §2.1).
pub const MIN_ROWS: usize = 10;
/// Most features (spec §2.5); also the widest model accepted by `/predict`.
pub const MAX_FEATURES: usize = 200;
/// Most trees of a model (spec §2.5).
pub const MAX_TREES: usize = 5000;
/// Most rows a `/predict` request may send.
pub const MAX_PREDICT_ROWS: usize = 100_000;
/// Most background rows of interventional SHAP (spec §2.2).
pub const MAX_BACKGROUND: usize = 1000;
/// Most (row, background row) pairs of one interventional request: its cost is
/// O(trees·leaves·pairs) (spec §8 hazard 9).
pub const MAX_INTERVENTIONAL_PAIRS: usize = 1_000_000;
/// Most rows with interaction values (spec §2.2).
pub const MAX_INTERACTION_ROWS: usize = 1000;
/// Most interaction numbers (rows × d²) of one answer (≈ 40 MB of JSON).
pub const MAX_INTERACTION_CELLS: usize = 2_000_000;
/// Most SHAP numbers (rows × d) of one answer (≈ 80 MB of JSON).
pub const MAX_SHAP_CELLS: usize = 4_000_000;
/// Most PCA score numbers (rows × components) of one answer.
pub const MAX_SCORE_CELLS: usize = 4_000_000;

/// Target values (and base_score, leaf values) [target unit]: finite with magnitude ≤ 1e100, so
/// that sums of squared residuals over 100 000 rows stay finite.
pub const TARGET: Range = Range::closed(-1e100, 1e100);
/// Boosting rounds.
pub const N_ESTIMATORS: Range = Range::int(1, 5000);
/// Tree depth.
pub const MAX_DEPTH: Range = Range::int(1, 12);
/// Learning rate η.
pub const LEARNING_RATE: Range = Range::FINITE.gt(0.0).max(1.0);
/// λ, α, γ and min_child_weight [squared target units].
pub const REGULARISATION: Range = Range::closed(0.0, 1e6);
/// colsample_bytree and subsample.
pub const FRACTION: Range = Range::FINITE.gt(0.0).max(1.0);
/// Bins per feature of the hist method.
pub const MAX_BIN: Range = Range::int(2, 1024);
/// Holdout share.
pub const TEST_FRACTION: Range = Range::closed(0.0, 0.5);
/// Folds of k-fold cross-validation.
pub const K_FOLD: Range = Range::int(2, 20);
/// SMOGN relevance threshold.
pub const SMOGN_THRESHOLD: Range = Range::closed(0.0, 1.0);
/// SMOGN relevance φ of a control point `[y, φ]` (stated in the field's description: a bound on
/// the second item of a pair has no JSON Schema form here).
pub const RELEVANCE_PHI: Range = Range::closed(0.0, 1.0);
/// SMOGN neighbours per seed.
pub const SMOGN_K: Range = Range::int(1, 50);
/// SMOGN relative perturbation.
pub const SMOGN_PERTURBATION: Range = Range::closed(0.0, 1.0);
/// Grey relational distinguishing coefficient ρ.
pub const GRA_RHO: Range = Range::FINITE.gt(0.0).max(1.0);
/// PCA components kept.
pub const PCA_COMPONENTS: Range = Range::int(1, 200);
/// Features of a model document.
pub const MODEL_FEATURES: Range = Range::int(1, 200);
/// Child indices of a model document (−1 = none).
pub const CHILD_INDEX: Range = Range::int(-1, 2_147_483_647);
/// Cover of a node of a model document.
pub const COVER: Range = Range::FINITE.min(0.0);

// ---------------------------------------------------------------------------------------------
// /train
// ---------------------------------------------------------------------------------------------

/// Request of `POST /v1/machining-size/train`: a data set (rows of process factors and the
/// measured dimension) and XGBoost-style parameters; returns the model, holdout and k-fold
/// metrics, importances and an optional SHAP summary (spec §2.1).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::TrainRequest)]
#[serde(deny_unknown_fields)]
pub struct TrainRequest {
    /// Column names: 1..200, unique, non-empty.
    #[rule(min_items = 1, max_items = MAX_FEATURES, code = "TOO_LARGE")]
    pub feature_names: Vec<String>,
    /// Feature matrix, row-major: 10..100 000 rows, each with one finite value per name.
    #[rule(min_items = MIN_ROWS, max_items = MAX_ROWS, items_items = Range::FINITE, code = "TOO_LARGE")]
    pub rows: Vec<Vec<f64>>,
    /// Measured dimension y per row [target unit, e.g. mm]: one per row, not all equal.
    #[rule(items = TARGET)]
    pub target: Vec<f64>,
    /// Boosting parameters (defaults: the paper's Table 2).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub params: TrainParams,
    /// Column dropping and SMOGN.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub preprocessing: PreprocessingIn,
    /// Holdout split and k-fold cross-validation.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub validation: ValidationIn,
    /// Optional outputs: `importance` (default), `shap_summary`, `test_predictions`.
    #[serde(default = "default_outputs", deserialize_with = "null_default_outputs")]
    pub outputs: Vec<TrainOutputKind>,
    /// Wall-clock budget of the request \[ms\], 1..600 000 (capped by the server); training stops
    /// at the first round after it and returns the trees built.
    #[serde(default)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false)]
    pub time_limit_ms: Option<u64>,
    /// Evaluate only block `index` of `count` near-equal contiguous blocks of the k
    /// cross-validation folds (needs `validation.k_fold`); the model, holdout metrics and other
    /// outputs are those of the unsharded request. Merge rule: see `metrics.cv.shard`.
    #[serde(default)]
    #[schema(nullable = false)]
    pub shard: Option<Shard>,
}

fn default_outputs() -> Vec<TrainOutputKind> {
    vec![TrainOutputKind::Importance]
}

/// Readers of optional fields whose default is not their type's `Default`: `null` reads as the
/// documented default, exactly as if the field were absent.
macro_rules! null_reads {
    ($($name:ident: $t:ty = $default:expr;)*) => {$(
        fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
            Ok(Option::<$t>::deserialize(d)?.unwrap_or_else(|| $default))
        }
    )*};
}

null_reads! {
    null_default_outputs: Vec<TrainOutputKind> = default_outputs();
    null_n_estimators: u32 = TrainParams::default().n_estimators;
    null_max_depth: u32 = TrainParams::default().max_depth;
    null_learning_rate: f64 = TrainParams::default().learning_rate;
    null_reg_lambda: f64 = TrainParams::default().reg_lambda;
    null_reg_alpha: f64 = TrainParams::default().reg_alpha;
    null_min_child_weight: f64 = TrainParams::default().min_child_weight;
    null_colsample_bytree: f64 = TrainParams::default().colsample_bytree;
    null_subsample: f64 = TrainParams::default().subsample;
    null_max_bin: u32 = TrainParams::default().max_bin;
    null_test_fraction: f64 = ValidationIn::default().test_fraction;
    null_rho: f64 = GraIn::default().rho;
    null_half: f64 = half();
    null_five: u32 = five();
    null_two_percent: f64 = two_percent();
}

impl TimeLimited for TrainRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// Boosting parameters; the defaults are the paper's Table 2 (n_estimators 400, max_depth 6,
/// learning_rate 0.05, colsample_bytree 0.8, reg_alpha 0.05, reg_lambda 0.1).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::TrainParams)]
#[serde(deny_unknown_fields, default)]
pub struct TrainParams {
    /// Boosting rounds (trees), 1..5000. Default 400.
    #[serde(deserialize_with = "null_n_estimators")]
    #[rule(range = N_ESTIMATORS)]
    pub n_estimators: u32,
    /// Tree depth, 1..12. Default 6.
    #[serde(deserialize_with = "null_max_depth")]
    #[rule(range = MAX_DEPTH)]
    pub max_depth: u32,
    /// Shrinkage η, (0, 1]. Default 0.05.
    #[serde(deserialize_with = "null_learning_rate")]
    #[rule(range = LEARNING_RATE)]
    pub learning_rate: f64,
    /// λ, L2 penalty on leaf weights [target unit²], [0, 1e6]. Default 0.1. With
    /// `min_child_weight` = 0 it must be > 0 (an empty child would divide by zero).
    #[serde(deserialize_with = "null_reg_lambda")]
    #[rule(range = REGULARISATION)]
    pub reg_lambda: f64,
    /// α, L1 penalty on leaf weights [target unit], [0, 1e6]. Default 0.05.
    #[serde(deserialize_with = "null_reg_alpha")]
    #[rule(range = REGULARISATION)]
    pub reg_alpha: f64,
    /// γ, minimum loss change of a split [target unit²], [0, 1e6], compared with the un-halved
    /// loss change as XGBoost does. Default 0.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    #[rule(range = REGULARISATION)]
    pub gamma: f64,
    /// Minimum hessian sum (rows) per child, [0, 1e6]. Default 1. The training split needs at
    /// least 2·max(1, min_child_weight) rows.
    #[serde(deserialize_with = "null_min_child_weight")]
    #[rule(range = REGULARISATION)]
    pub min_child_weight: f64,
    /// Fraction of features drawn for each tree, (0, 1]. Default 0.8 (paper); 1.0 makes the
    /// model deterministic with respect to XGBoost. ⌊colsample·d⌋ must be ≥ 1 (d = features
    /// left after dropping constant columns).
    #[serde(deserialize_with = "null_colsample_bytree")]
    #[rule(range = FRACTION)]
    pub colsample_bytree: f64,
    /// Fraction of training rows drawn for each tree (without replacement), (0, 1]. Default 1.
    #[serde(deserialize_with = "null_subsample")]
    #[rule(range = FRACTION)]
    pub subsample: f64,
    /// Seed of column and row sampling. Default 0.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub seed: u64,
    /// Initial prediction [target unit], |b| ≤ 1e100; absent → mean of the training targets
    /// (XGBoost ≥ 2.0 for squared error).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[rule(range = TARGET)]
    #[schema(nullable = false)]
    pub base_score: Option<f64>,
    /// Split search: `exact` (default) or `hist`.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    #[schema(inline)]
    pub tree_method: TreeMethod,
    /// Bins per feature for `hist`, 2..1024. Default 256.
    #[serde(deserialize_with = "null_max_bin")]
    #[rule(range = MAX_BIN)]
    pub max_bin: u32,
}

impl Default for TrainParams {
    fn default() -> Self {
        Self {
            n_estimators: 400,
            max_depth: 6,
            learning_rate: 0.05,
            reg_lambda: 0.1,
            reg_alpha: 0.05,
            gamma: 0.0,
            min_child_weight: 1.0,
            colsample_bytree: 0.8,
            subsample: 1.0,
            seed: 0,
            base_score: None,
            tree_method: TreeMethod::Exact,
            max_bin: 256,
        }
    }
}

/// Split search of the trees.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = machining_size::TreeMethod)]
#[serde(rename_all = "snake_case")]
pub enum TreeMethod {
    /// Every boundary between distinct values; threshold = midpoint (XGBoost `exact`).
    #[default]
    Exact,
    /// Boundaries between quantile bins; threshold = the bin's upper cut (XGBoost `hist`).
    Hist,
}

/// Preprocessing of the training data (spec §3 step 1).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::PreprocessingIn)]
#[serde(deny_unknown_fields)]
pub struct PreprocessingIn {
    /// Remove zero-variance columns before training (paper §3.2). Default true. The model keeps
    /// the original column indices.
    #[serde(default = "yes", deserialize_with = "crate::calc::rules::null_true")]
    pub drop_constant: bool,
    /// SMOGN resampling of the TRAINING split only (never the test rows). Default none.
    #[serde(default)]
    #[schema(nullable = false)]
    pub smogn: Option<SmognIn>,
}

fn yes() -> bool {
    true
}

impl Default for PreprocessingIn {
    fn default() -> Self {
        Self {
            drop_constant: true,
            smogn: None,
        }
    }
}

/// SMOGN options (spec §2.4).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::SmognIn)]
#[serde(deny_unknown_fields)]
pub struct SmognIn {
    /// Relevance control points `[[y, φ], ...]`: at least 2, y strictly increasing
    /// [target unit], φ in [0, 1]. Required (the automatic box-plot relevance fails on
    /// quantised targets).
    #[rule(min_items = 2, items_items = Range::FINITE)]
    #[schema(value_type = Vec<[f64; 2]>)]
    pub relevance: Vec<[f64; 2]>,
    /// A sample is rare when φ(y) ≥ threshold, [0, 1]. Default 0.5.
    #[serde(default = "half", deserialize_with = "null_half")]
    #[rule(range = SMOGN_THRESHOLD)]
    pub threshold: f64,
    /// Nearest neighbours per seed, 1..50. Default 5.
    #[serde(default = "five", deserialize_with = "null_five")]
    #[rule(range = SMOGN_K)]
    pub k: u32,
    /// Relative sd of the Gaussian perturbation, [0, 1]. Default 0.02.
    #[serde(default = "two_percent", deserialize_with = "null_two_percent")]
    #[rule(range = SMOGN_PERTURBATION)]
    pub perturbation: f64,
    /// Seed of the resampling. Default 0.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub seed: u64,
}

fn half() -> f64 {
    0.5
}
fn five() -> u32 {
    5
}
fn two_percent() -> f64 {
    0.02
}

/// Holdout split and cross-validation.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::ValidationIn)]
#[serde(deny_unknown_fields, default)]
pub struct ValidationIn {
    /// Holdout share, [0, 0.5]. Default 0.2 (the paper's 80/20). The first
    /// ⌊(1 − test_fraction)·n⌋ rows of a seeded permutation train.
    #[serde(deserialize_with = "null_test_fraction")]
    #[rule(range = TEST_FRACTION)]
    pub test_fraction: f64,
    /// k-fold cross-validation over all rows (seeded permutation, folds of near-equal size),
    /// 2..20; absent → none.
    #[rule(range = K_FOLD)]
    #[schema(nullable = false)]
    pub k_fold: Option<u32>,
    /// Seed of the holdout and fold permutations. Default 0.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub seed: u64,
}

impl Default for ValidationIn {
    fn default() -> Self {
        Self {
            test_fraction: 0.2,
            k_fold: None,
            seed: 0,
        }
    }
}

/// An optional output of `/train`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::TrainOutputKind)]
#[serde(rename_all = "snake_case")]
pub enum TrainOutputKind {
    /// Split counts, gain and cover per feature.
    Importance,
    /// Mean |SHAP| per feature over the training rows (≤ 2000, seeded sample beyond), per-level
    /// means of discrete features.
    ShapSummary,
    /// The test rows' targets and predictions.
    TestPredictions,
}

/// Answer of `POST /v1/machining-size/train`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::TrainResponse)]
pub struct TrainResponse {
    /// The trained model (send it to `/predict`).
    pub model: GbdtModel,
    /// Trees with at least one split (spec §8 hazard 2).
    pub effective_trees: u32,
    /// Metrics of the training rows, the holdout and k-fold CV.
    pub metrics: MetricsOut,
    /// What preprocessing did.
    pub preprocessing: PreprocessingOut,
    /// Per-feature importances (when `outputs` has `importance`), in column order.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub importance: Option<Vec<FeatureImportance>>,
    /// SHAP summary (when `outputs` has `shap_summary`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub shap_summary: Option<ShapSummary>,
    /// Test rows with targets and predictions (when `outputs` has `test_predictions`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub test_predictions: Option<TestPredictions>,
    /// How training stopped (`completed`: all rounds; `converged`: a round built a zero leaf
    /// with every feature and row in use, so all further rounds would too; `deadline`,
    /// `cancelled`), rounds of the returned model and trees built in all (with CV folds).
    pub report: SolverReport,
    /// Warnings `{code, message, pointer?}`.
    pub warnings: Vec<Warning>,
}

/// Our model document (spec §5): arrays indexed by node id, root 0, leaves have
/// `left = right = −1`. Prediction = base_score + Σ trees; `x[feature] < threshold` goes left.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::GbdtModel)]
#[serde(deny_unknown_fields)]
pub struct GbdtModel {
    /// Always `machining-size-gbdt/1`.
    pub format: String,
    /// Always `reg:squarederror` (v1).
    pub objective: String,
    /// Initial prediction [target unit], |b| ≤ 1e100.
    #[rule(range = TARGET)]
    pub base_score: f64,
    /// Column names, one per feature (may be empty).
    pub feature_names: Vec<String>,
    /// Number of input columns a row must have, 1..200.
    #[rule(range = MODEL_FEATURES)]
    pub n_features: u32,
    /// Training parameters (informational; `/predict` ignores them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub params: Option<TrainParams>,
    /// The trees, at most 5000.
    #[rule(max_items = MAX_TREES)]
    pub trees: Vec<TreeDoc>,
}

/// One tree as parallel arrays indexed by node id (root 0).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::TreeDoc)]
#[serde(deny_unknown_fields)]
pub struct TreeDoc {
    /// Left child per node, −1 at leaves. Every node is reached from the root exactly once (no
    /// cycles, no shared children); both children are −1 or both are node indices.
    #[rule(items = CHILD_INDEX)]
    pub left: Vec<i64>,
    /// Right child per node, −1 at leaves.
    #[rule(items = CHILD_INDEX)]
    pub right: Vec<i64>,
    /// Split feature per node (0..n_features−1 at internal nodes; −1 at leaves).
    #[rule(items = CHILD_INDEX)]
    pub feature: Vec<i64>,
    /// Threshold θ per node (finite; `x < θ` goes left; 0 at leaves).
    pub threshold: Vec<f64>,
    /// Direction of a missing value per node (unused in v1: rows are finite).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub default_left: Vec<bool>,
    /// Node value [target unit], |v| ≤ 1e100: the leaf output (already × η) at leaves, the
    /// node's own weight × η at internal nodes.
    #[rule(items = TARGET)]
    pub value: Vec<f64>,
    /// Cover (training rows, = hessian sum) per node, ≥ 0.
    #[rule(items = COVER)]
    pub cover: Vec<f64>,
    /// Loss change Δ of the split per node (0 at leaves) [target unit²].
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub loss_change: Vec<f64>,
}

/// Metrics of the training rows, the holdout and cross-validation (paper eq. 12–14).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::MetricsOut)]
pub struct MetricsOut {
    /// On the original training rows (synthetic SMOGN rows excluded).
    pub train: SplitMetrics,
    /// On the holdout rows (absent when `test_fraction` is 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub test: Option<SplitMetrics>,
    /// k-fold cross-validation (when `validation.k_fold` is given and every fold finished).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub cv: Option<CvMetrics>,
}

/// Regression metrics on one set of rows.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::SplitMetrics)]
pub struct SplitMetrics {
    /// Rows evaluated.
    pub n: u32,
    /// Mean absolute error [target unit].
    #[serde(rename = "MAE")]
    pub mae: f64,
    /// Mean squared error [target unit²].
    #[serde(rename = "MSE")]
    pub mse: f64,
    /// Root mean squared error [target unit].
    #[serde(rename = "RMSE")]
    pub rmse: f64,
    /// Coefficient of determination 1 − Σ(ŷ−y)²/Σ(ȳ−y)² (ȳ of the evaluated rows); absent when
    /// the evaluated targets are all equal.
    #[serde(rename = "R2", skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub r2: Option<f64>,
}

/// k-fold cross-validation: per-fold metrics and their mean and sample sd (ddof 1).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::CvMetrics)]
pub struct CvMetrics {
    /// Folds (of the whole cross-validation, also in a sharded answer).
    pub k: u32,
    /// Test metrics of each fold (trained on the other folds); with `shard` the folds
    /// `shard.start..shard.end`.
    pub folds: Vec<SplitMetrics>,
    /// Which folds this answer holds (only when the request gave `shard`); the means and sds
    /// below are then over these folds. Merged: `folds` concatenated in shard order, and
    /// `R2_mean`, `R2_sd`, `RMSE_mean`, `RMSE_sd`, `MAE_mean` recomputed over the merged folds
    /// (mean, and sample sd with ddof 1; R² over the folds that have one).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub shard: Option<ShardOut>,
    /// Mean R² over folds with a defined R².
    #[serde(rename = "R2_mean", skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub r2_mean: Option<f64>,
    /// Sample sd of R² over those folds.
    #[serde(rename = "R2_sd", skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub r2_sd: Option<f64>,
    /// Mean RMSE [target unit].
    #[serde(rename = "RMSE_mean")]
    pub rmse_mean: f64,
    /// Sample sd of RMSE [target unit].
    #[serde(rename = "RMSE_sd")]
    pub rmse_sd: f64,
    /// Mean MAE [target unit].
    #[serde(rename = "MAE_mean")]
    pub mae_mean: f64,
}

/// What preprocessing did.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::PreprocessingOut)]
pub struct PreprocessingOut {
    /// Constant columns left out of training (when `drop_constant`).
    pub dropped_constant: Vec<String>,
    /// Training rows (before SMOGN).
    pub n_train: u32,
    /// Holdout rows.
    pub n_test: u32,
    /// SMOGN on the training split (when asked).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub smogn: Option<SmognOut>,
}

/// Importance of one feature over all trees.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::FeatureImportance)]
pub struct FeatureImportance {
    /// Column name.
    pub feature: String,
    /// Splits on the feature (XGBoost "weight").
    pub weight: u32,
    /// Total loss change of its splits [target unit²] (XGBoost "total_gain").
    pub gain: f64,
    /// Mean loss change per split (XGBoost "gain"); 0 without splits.
    pub gain_mean: f64,
    /// Share of the total loss change of all features, [0, 1].
    pub gain_share: f64,
    /// Total cover of its splits (XGBoost "total_cover").
    pub cover: f64,
    /// Mean cover per split (XGBoost "cover"); 0 without splits.
    pub cover_mean: f64,
}

/// SHAP summary over (a sample of) the training rows (spec §4.4; paper Fig. 8–9).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::ShapSummary)]
pub struct ShapSummary {
    /// φ₀: base + cover-weighted tree expectations [target unit].
    pub expected_value: f64,
    /// Rows explained.
    pub rows_explained: u32,
    /// Per feature, in column order.
    pub features: Vec<FeatureShap>,
    /// Largest |φ₀ + Σφ − f(x)| over the explained rows [target unit] (local accuracy).
    pub local_accuracy_max_abs: f64,
}

/// SHAP statistics of one feature.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::FeatureShap)]
pub struct FeatureShap {
    /// Column name.
    pub feature: String,
    /// Mean |φ| [target unit] (the paper's ranking, Fig. 8a).
    pub mean_abs: f64,
    /// Mean φ [target unit].
    pub mean: f64,
    /// Mean φ per value, for features with at most 20 distinct values among the explained rows
    /// (the paper's per-level statements, Fig. 9).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub levels: Option<Vec<LevelShap>>,
}

/// Mean SHAP value at one level of a discrete feature.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::LevelShap)]
pub struct LevelShap {
    /// The feature value [feature unit].
    pub value: f64,
    /// Rows with that value.
    pub count: u32,
    /// Mean φ at that value [target unit].
    pub mean: f64,
}

/// Holdout rows with their targets and predictions.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::TestPredictions)]
pub struct TestPredictions {
    /// Row indices into the request's `rows`.
    pub rows: Vec<u32>,
    /// Targets [target unit].
    pub target: Vec<f64>,
    /// Predictions [target unit].
    pub prediction: Vec<f64>,
}

/// What SMOGN did.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::SmognOut)]
pub struct SmognOut {
    /// Samples before.
    pub n_before: u32,
    /// Samples after (kept + new).
    pub n_after: u32,
    /// Samples with φ ≥ threshold.
    pub n_rare: u32,
    /// New cases by interpolation.
    pub n_interpolated: u32,
    /// New cases by Gaussian perturbation.
    pub n_perturbed: u32,
    /// Normal samples removed by undersampling.
    pub n_removed: u32,
    /// Bins in ascending target order.
    pub bins: Vec<SmognBinOut>,
    /// Discrete features (≤ 20 levels) whose new values leave their original levels, with the
    /// number of such values (spec §8 hazard 6).
    pub off_grid: Vec<OffGrid>,
    /// The resampled set (when `include_data`; `/analyze` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub data: Option<SmognData>,
}

/// One SMOGN bin.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::SmognBinOut)]
pub struct SmognBinOut {
    /// Rare (φ ≥ threshold) or normal.
    pub rare: bool,
    /// Samples in the bin.
    pub size: u32,
    /// Smallest target [target unit].
    pub y_min: f64,
    /// Largest target [target unit].
    pub y_max: f64,
    /// Original samples kept.
    pub kept: u32,
    /// New cases.
    pub created: u32,
}

/// Off-grid values of a discrete feature.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::OffGrid)]
pub struct OffGrid {
    /// Column name.
    pub feature: String,
    /// New values not among the feature's original levels.
    pub count: u32,
}

/// A resampled data set.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::SmognData)]
pub struct SmognData {
    /// Rows (kept originals first, in input order, then new cases).
    pub rows: Vec<Vec<f64>>,
    /// Targets [target unit].
    pub target: Vec<f64>,
}

// ---------------------------------------------------------------------------------------------
// /predict
// ---------------------------------------------------------------------------------------------

/// Request of `POST /v1/machining-size/predict`: a model (ours, or an XGBoost JSON model) and
/// rows; optional SHAP values and interaction values (spec §2.2).
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::PredictRequest)]
#[serde(deny_unknown_fields)]
pub struct PredictRequest {
    /// The model: our document as `/train` returns it, or `{"xgboost_json": <XGBoost JSON
    /// model>}` (objective `reg:squarederror`, booster `gbtree`, single output). Hostile
    /// documents (child out of range, a cycle, depth > 64, > 1 000 000 nodes, non-finite numbers)
    /// are rejected with a pointer.
    #[schema(value_type = ModelDocument)]
    pub model: super::doc_tree::Doc,
    /// Rows to predict, 1..100 000, each with one finite value per model feature.
    #[rule(min_items = 1, max_items = MAX_PREDICT_ROWS, items_items = Range::FINITE, code = "TOO_LARGE")]
    pub rows: Vec<Vec<f64>>,
    /// Column names of `rows`; when given they must equal the model's.
    #[serde(default)]
    #[schema(nullable = false)]
    pub feature_names: Option<Vec<String>>,
    /// SHAP values: `none` (default), `path_dependent` (= XGBoost `pred_contribs`, shap
    /// TreeExplainer without data) or `interventional` (needs `background`).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub shap: ShapKind,
    /// Background rows of interventional SHAP, 1..1000; rows × background ≤ 1 000 000.
    #[serde(default)]
    #[rule(min_items = 1, max_items = MAX_BACKGROUND, items_items = Range::FINITE, code = "TOO_LARGE")]
    #[schema(nullable = false)]
    pub background: Option<Vec<Vec<f64>>>,
    /// SHAP interaction values (path-dependent; rows ≤ 1000 and rows·d² ≤ 2 000 000).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub interactions: bool,
    /// Wall-clock budget of the request \[ms\], 1..600 000 (capped by the server).
    #[serde(default)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false)]
    pub time_limit_ms: Option<u64>,
}

impl TimeLimited for PredictRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// A model document (schema of `model`): ours, or a wrapped XGBoost JSON model. Documents the
/// shape of [`PredictRequest::model`], which `document.rs` reads from JSON so that every defect is
/// reported with its exact pointer.
#[derive(Serialize, ToSchema)]
#[schema(as = machining_size::ModelDocument)]
#[serde(untagged)]
pub enum ModelDocument {
    /// Our model document.
    Native(GbdtModel),
    /// An XGBoost JSON model.
    Xgboost(XgboostModel),
}

/// An XGBoost JSON model (as `Booster.save_model("m.json")` writes it), wrapped.
#[derive(Serialize, ToSchema)]
#[schema(as = machining_size::XgboostModel)]
#[serde(deny_unknown_fields)]
pub struct XgboostModel {
    /// The XGBoost JSON document: `learner.gradient_booster.model.trees` (left_children,
    /// right_children, split_indices, split_conditions, sum_hessian, ...),
    /// `learner.learner_model_param.base_score` (e.g. `"[1.9962889E1]"`) and
    /// `learner.objective.name`.
    #[schema(value_type = Object)]
    pub xgboost_json: serde_json::Value,
}

/// Kind of SHAP values.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = machining_size::ShapKind)]
#[serde(rename_all = "snake_case")]
pub enum ShapKind {
    /// No SHAP values.
    #[default]
    None,
    /// Path-dependent TreeSHAP (cover-weighted conditional expectations).
    PathDependent,
    /// Interventional TreeSHAP against `background`.
    Interventional,
}

/// Answer of `POST /v1/machining-size/predict`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::PredictResponse)]
pub struct PredictResponse {
    /// Prediction per row [target unit].
    pub predictions: Vec<f64>,
    /// SHAP values (when `shap` is not `none`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub shap: Option<ShapOut>,
    /// Interaction values per row, `d × d` (when `interactions`): Φ_ij off the diagonal,
    /// Φ_ii the main effect; each row of the matrix sums to φ_i [target unit].
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub interactions: Option<Vec<Vec<Vec<f64>>>>,
    /// The model that was evaluated.
    pub model_summary: ModelSummary,
    /// Cost: rows evaluated (iterations) and tree traversals (evaluations).
    pub report: SolverReport,
    /// Warnings `{code, message, pointer?}`.
    pub warnings: Vec<Warning>,
}

/// SHAP values of every row.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::ShapOut)]
pub struct ShapOut {
    /// Which values.
    pub kind: ShapKind,
    /// φ₀ [target unit]: cover-weighted expectation (path-dependent) or the mean prediction
    /// over the background (interventional).
    pub expected_value: f64,
    /// φ per row and feature [target unit]; φ₀ + Σφ = prediction.
    pub values: Vec<Vec<f64>>,
    /// Largest |φ₀ + Σφ − prediction| over the rows [target unit] (local accuracy, checked on
    /// every answer).
    pub local_accuracy_max_abs: f64,
}

/// Facts about the evaluated model.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::ModelSummary)]
pub struct ModelSummary {
    /// `native` or `xgboost_json`.
    pub source: String,
    /// Threshold comparison: `f64`, or `f32` (XGBoost: rows rounded to f32, as XGBoost does).
    pub routing: String,
    /// Trees.
    pub n_trees: u32,
    /// Trees with at least one split.
    pub effective_trees: u32,
    /// Leaves over all trees.
    pub n_leaves: u32,
    /// Deepest tree.
    pub max_depth: u32,
    /// Input columns.
    pub n_features: u32,
    /// Intercept [target unit].
    pub base_score: f64,
}

// ---------------------------------------------------------------------------------------------
// /analyze
// ---------------------------------------------------------------------------------------------

/// Request of `POST /v1/machining-size/analyze`: the paper's data diagnostics (spec §2.3, §6):
/// constant columns always; PCA, grey relational grades and a SMOGN preview when asked.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::AnalyzeRequest)]
#[serde(deny_unknown_fields)]
pub struct AnalyzeRequest {
    /// Column names: 1..200, unique, non-empty.
    #[rule(min_items = 1, max_items = MAX_FEATURES, code = "TOO_LARGE")]
    pub feature_names: Vec<String>,
    /// Feature matrix, row-major: 10..100 000 rows, each with one finite value per name.
    #[rule(min_items = MIN_ROWS, max_items = MAX_ROWS, items_items = Range::FINITE, code = "TOO_LARGE")]
    pub rows: Vec<Vec<f64>>,
    /// Measured dimension per row [target unit] (the GRA reference series, SMOGN's target).
    #[rule(items = TARGET)]
    pub target: Vec<f64>,
    /// Grey relational grades of every non-constant feature against the target.
    #[serde(default)]
    #[schema(nullable = false)]
    pub gra: Option<GraIn>,
    /// PCA of the non-constant features.
    #[serde(default)]
    #[schema(nullable = false)]
    pub pca: Option<PcaIn>,
    /// SMOGN preview over all rows.
    #[serde(default)]
    #[schema(nullable = false)]
    pub smogn: Option<SmognPreviewIn>,
    /// Wall-clock budget of the request \[ms\], 1..600 000 (capped by the server).
    #[serde(default)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false)]
    pub time_limit_ms: Option<u64>,
}

impl TimeLimited for AnalyzeRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// Grey relational analysis options.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::GraIn)]
#[serde(deny_unknown_fields, default)]
pub struct GraIn {
    /// Distinguishing coefficient ρ, (0, 1]. Default 0.5.
    #[serde(deserialize_with = "null_rho")]
    #[rule(range = GRA_RHO)]
    pub rho: f64,
    /// `mean` (default: each series divided by its mean; a series with mean 0 is rejected) or
    /// `none`.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    #[schema(inline)]
    pub normalise: GraNormalise,
}

impl Default for GraIn {
    fn default() -> Self {
        Self {
            rho: 0.5,
            normalise: GraNormalise::Mean,
        }
    }
}

/// Normalisation of the GRA series.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = machining_size::GraNormalise)]
#[serde(rename_all = "snake_case")]
pub enum GraNormalise {
    /// x(k)/mean(x).
    #[default]
    Mean,
    /// Raw values.
    None,
}

/// PCA options.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::PcaIn)]
#[serde(deny_unknown_fields, default)]
pub struct PcaIn {
    /// Components kept for loadings and the composite score, 1..200; absent → all (more than
    /// the non-constant features → all, with a warning).
    #[rule(range = PCA_COMPONENTS)]
    #[schema(nullable = false)]
    pub components: Option<u32>,
    /// Also return the scores S (rows × components ≤ 4 000 000). Default false.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub scores: bool,
}

/// SMOGN preview options: the SMOGN options plus whether to return the resampled data.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = machining_size::SmognPreviewIn)]
#[serde(deny_unknown_fields)]
pub struct SmognPreviewIn {
    /// Relevance control points `[[y, φ], ...]`: at least 2, y strictly increasing
    /// [target unit], φ in [0, 1].
    #[rule(min_items = 2, items_items = Range::FINITE)]
    #[schema(value_type = Vec<[f64; 2]>)]
    pub relevance: Vec<[f64; 2]>,
    /// A sample is rare when φ(y) ≥ threshold, [0, 1]. Default 0.5.
    #[serde(default = "half", deserialize_with = "null_half")]
    #[rule(range = SMOGN_THRESHOLD)]
    pub threshold: f64,
    /// Nearest neighbours per seed, 1..50. Default 5.
    #[serde(default = "five", deserialize_with = "null_five")]
    #[rule(range = SMOGN_K)]
    pub k: u32,
    /// Relative sd of the Gaussian perturbation, [0, 1]. Default 0.02.
    #[serde(default = "two_percent", deserialize_with = "null_two_percent")]
    #[rule(range = SMOGN_PERTURBATION)]
    pub perturbation: f64,
    /// Seed of the resampling. Default 0.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub seed: u64,
    /// Return the resampled rows and targets. Default false.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub include_data: bool,
}

/// Answer of `POST /v1/machining-size/analyze`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::AnalyzeResponse)]
pub struct AnalyzeResponse {
    /// Columns with zero peak-to-peak (paper §3.2: 10 of its 15 factors).
    pub constant_columns: Vec<ConstantColumn>,
    /// PCA (when asked).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub pca: Option<PcaOut>,
    /// Grey relational grades (when asked).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub gra: Option<GraOut>,
    /// SMOGN preview (when asked).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub smogn: Option<SmognOut>,
    /// Cost of the analysis.
    pub report: SolverReport,
    /// Warnings `{code, message, pointer?}`.
    pub warnings: Vec<Warning>,
}

/// A constant column.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::ConstantColumn)]
pub struct ConstantColumn {
    /// Column name.
    pub feature: String,
    /// Column index.
    pub index: u32,
    /// Its value [feature unit].
    pub value: f64,
}

/// PCA of the non-constant features (spec §6; paper eq. 1, 16).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::PcaOut)]
pub struct PcaOut {
    /// Analysed columns (non-constant), the order of every loading vector.
    pub features: Vec<String>,
    /// Eigenvalues of the correlation matrix, descending.
    pub eigenvalues: Vec<f64>,
    /// Contribution rate of each component [%] (100·λ_j/Σλ).
    pub contribution_rates: Vec<f64>,
    /// Cumulative contribution [%].
    pub cumulative_rates: Vec<f64>,
    /// Loadings of the kept components (one vector per component; largest |entry| positive).
    pub loadings: Vec<Vec<f64>>,
    /// Composite score of each row: Σ_j S_ij·rate_j/100 over the kept components.
    pub composite_scores: Vec<f64>,
    /// Scores S = Z·V per row (when `scores`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub scores: Option<Vec<Vec<f64>>>,
}

/// Grey relational grades against the target (spec §6; paper eq. 2–4).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::GraOut)]
pub struct GraOut {
    /// ρ used.
    pub rho: f64,
    /// Normalisation used.
    pub normalise: GraNormalise,
    /// Grade of each non-constant feature, in column order.
    pub grades: Vec<GraGrade>,
}

/// The grade of one feature.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = machining_size::GraGrade)]
pub struct GraGrade {
    /// Column name.
    pub feature: String,
    /// Grade r_i in (0, 1].
    pub grade: f64,
    /// Rank by grade (1 = most related; ties share the better rank).
    pub rank: u32,
}
