//! Wire types of `POST /v1/fit-cam-law` (spec §2 inputs, §4 outputs, §8 JSON example).
//!
//! Units are not converted (spec §2): the abscissa `x` is time or cam angle (unit "x"), the
//! displacement has unit U; velocity U/x, acceleration U/x², jerk U/x³. The optional `units`
//! labels are echoed back.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::cam_law::catalogue::NamedLaw;
use crate::calc::cam_law::law::{Jump, Knot, Peaks};
use crate::calc::cam_law::wire::{Curves, Units, Warning};
use crate::numerics::StopReason;

/// Smallest number of samples (7 unknowns, spec §2).
pub const MIN_SAMPLES: usize = 8;
/// Largest number of samples (spec §2).
pub const MAX_SAMPLES: usize = 200_000;
/// Largest dense-curve count (spec §2 `outputs.curves.count`).
pub const MAX_CURVE_COUNT: u64 = 100_000;

/// Request of `POST /v1/fit-cam-law`: identify the 7 duration coefficients of the general
/// modified-trapezoidal law from sampled motion of one segment (spec §2).
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::FitCamLawRequest)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "abscissa": {"grid": {"start": 0.0, "end": 1.0, "count": 8}},
    "channels": {"displacement": [0.0, 0.0265, 0.1203, 0.3019, 0.5369, 0.7665, 0.9360, 1.0]},
    "fit_on": "displacement",
    "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0},
    "objective": {"metric": "euclidean"},
    "optimizer": {"method": "auto", "seed": 0, "max_evaluations": 50000, "time_limit_ms": 10000},
    "outputs": {"curves": {"count": 0}, "error_table": true, "classify": true, "history": false}
}))]
pub struct FitCamLawRequest {
    /// Sample abscissae: exactly one of `values` or `grid`.
    pub abscissa: FitAbscissa,
    /// Measured channels (at least one), each with one value per abscissa.
    pub channels: Channels,
    /// Quantity compared by the objective (default `acceleration`, the paper's best case on
    /// clean data).
    #[serde(default)]
    #[schema(nullable = false)]
    pub fit_on: Option<FitQuantity>,
    /// Differentiate a lower channel numerically when the `fit_on` channel is absent
    /// (s → v → a only; second-order differences as numpy `gradient`, spec §3.3). Default false.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub derive_missing: bool,
    /// Boundary conditions of the segment (paper constraint vector λ).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub constraints: FitConstraints,
    /// Distance used by the objective.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub objective: ObjectiveIn,
    /// Optimizer choice and budgets.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub optimizer: OptimizerIn,
    /// Starting coefficients (7 numbers ≥ 0, normalized internally; both pulses c0..c2 and
    /// c4..c6 non-empty). Default all 1/7 (the paper's initial solution). Exclusive with
    /// `initial_law`.
    #[serde(default)]
    #[rule(items = INITIAL_COEFFICIENT, min_items = 7, max_items = 7)]
    #[schema(example = json!([1, 1, 1, 1, 1, 1, 1]))]
    pub initial_coefficients: Option<Vec<f64>>,
    /// Starting law by Appendix-A name; only laws of the 7-segment class (constant_acceleration,
    /// simple_harmonic, cycloidal, modified_trapezoid, modified_sine). Exclusive with
    /// `initial_coefficients`.
    #[serde(default)]
    #[schema(nullable = false)]
    pub initial_law: Option<NamedLaw>,
    /// 7 flags forcing segments to zero length; both pulses must keep a free segment.
    /// Default all false.
    #[serde(default)]
    #[rule(min_items = 7, max_items = 7)]
    pub fixed_zero: Option<Vec<bool>>,
    /// Which expensive outputs to compute.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub outputs: OutputsIn,
    /// Free-text unit labels, echoed back.
    #[serde(default)]
    #[schema(nullable = false)]
    pub units: Option<Units>,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false, example = 2000)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for FitCamLawRequest {
    /// The smaller of `time_limit_ms` and `optimizer.time_limit_ms` (10 000 ms when neither is
    /// given): see [`super::time_limit`].
    fn time_limit(&self) -> Option<std::time::Duration> {
        super::time_limit(self)
    }
}

/// Sample abscissae \[x\]: exactly one of `values` or `grid`.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::FitAbscissa)]
#[serde(deny_unknown_fields)]
#[rules(one_of_object("values", "grid"))]
pub struct FitAbscissa {
    /// Explicit abscissae \[x\]: strictly increasing, finite, 8..200 000 values, inside
    /// `[t_a − 1e-9·Δt, t_b + 1e-9·Δt]`.
    #[serde(default)]
    #[rule(min_items = MIN_SAMPLES, max_items = MAX_SAMPLES)]
    pub values: Option<Vec<f64>>,
    /// Uniform grid `x_k = start + k·(end − start)/(count − 1)`, `k = 0..count−1`.
    #[serde(default)]
    #[schema(nullable = false)]
    pub grid: Option<FitGrid>,
}

/// A uniform grid including both ends.
#[derive(Debug, Clone, Copy, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::FitGrid)]
#[serde(deny_unknown_fields)]
pub struct FitGrid {
    /// First abscissa \[x\].
    #[schema(example = 0.0)]
    pub start: f64,
    /// Last abscissa \[x\], `> start`.
    #[schema(example = 1.0)]
    pub end: f64,
    /// Number of samples N, 8..200 000.
    #[rule(range = GRID_COUNT)]
    #[schema(example = 300)]
    pub count: u64,
}

/// Measured channels, each of length N (same as the abscissa).
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::Channels)]
#[serde(deny_unknown_fields)]
pub struct Channels {
    /// Displacement samples `s_k` \[U\].
    #[serde(default)]
    #[rule(items = DATA_VALUE)]
    pub displacement: Option<Vec<f64>>,
    /// Velocity samples `v_k = ds/dx` [U/x].
    #[serde(default)]
    #[rule(items = DATA_VALUE)]
    pub velocity: Option<Vec<f64>>,
    /// Acceleration samples `a_k = d²s/dx²` [U/x²].
    #[serde(default)]
    #[rule(items = DATA_VALUE)]
    pub acceleration: Option<Vec<f64>>,
}

/// A measured quantity.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cam_law_fit::FitQuantity)]
#[serde(rename_all = "snake_case")]
pub enum FitQuantity {
    /// Displacement `s` \[U\].
    Displacement,
    /// Velocity `v` [U/x].
    Velocity,
    /// Acceleration `a` [U/x²].
    Acceleration,
}

/// Boundary conditions of the segment (spec §2). Every field is optional.
#[derive(Debug, Clone, Copy, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::FitConstraints)]
#[serde(deny_unknown_fields)]
pub struct FitConstraints {
    /// Segment start `t_a` \[x\]. Default: first abscissa.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 0.0)]
    pub t_a: Option<f64>,
    /// Segment end `t_b` \[x\], `> t_a`. Default: last abscissa.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 1.0)]
    pub t_b: Option<f64>,
    /// Displacement at the start `s_a` \[U\]. Default: first displacement sample; required
    /// without a displacement channel.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 0.0)]
    pub s_a: Option<f64>,
    /// Displacement at the end `s_b` \[U\]. Default: last displacement sample; required without
    /// a displacement channel.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 1.0)]
    pub s_b: Option<f64>,
    /// Velocity at the start `v_a` [U/x]. Default 0.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 0.2)]
    pub v_a: Option<f64>,
    /// Velocity at the end `v_b` [U/x]. Default 0.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 0.5)]
    pub v_b: Option<f64>,
    /// Acceleration at the start `a_a` [U/x²]. Default 0.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 1.4)]
    pub a_a: Option<f64>,
    /// Acceleration at the end `a_b` [U/x²]. Default 0.
    #[rule(range = DATA_VALUE)]
    #[schema(example = 1.2)]
    pub a_b: Option<f64>,
}

/// Distance between model and data (spec §3.4).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cam_law_fit::MetricName)]
#[serde(rename_all = "snake_case")]
pub enum MetricName {
    /// `sqrt(Σ(ŷ_k − y_k)²)` (paper Eq. 7), not divided by N.
    #[default]
    Euclidean,
    /// The paper's DTW: L1 local cost, Sakoe–Chiba band `|i − j| ≤ w`, `D(N, N)` without
    /// square root or normalization.
    Dtw,
}

/// Objective settings.
#[derive(Debug, Clone, Copy, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::ObjectiveIn)]
#[serde(deny_unknown_fields)]
pub struct ObjectiveIn {
    /// `euclidean` (default) or `dtw`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub metric: MetricName,
    /// DTW band radius `w` \[samples\], `0 ≤ w ≤ N`; default 1 (reproduces the paper). Ignored
    /// for `euclidean`.
    #[serde(default)]
    #[rule(range = DTW_WINDOW)]
    #[schema(example = 1)]
    pub dtw_window: Option<i64>,
}

/// Optimizer (spec §3.5).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cam_law_fit::Method)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Deterministic multi-start least squares with zero-snapping (+ CMA-ES polish and IPOP
    /// restarts for DTW); the recommended default (spec §3.5.2).
    #[default]
    Auto,
    /// The paper's elitist GA with its Table-2 settings (spec §3.5.1).
    Ga,
    /// Differential evolution DE/best/1/bin (scipy defaults).
    De,
    /// CMA-ES, σ0 = 0.1 from the initial solution, bounds [0, 1].
    Cmaes,
    /// One least-squares run from the initial solution (Euclidean only).
    Lsq,
}

/// Optimizer settings and budgets.
#[derive(Debug, Clone, Copy, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::OptimizerIn)]
#[serde(deny_unknown_fields)]
pub struct OptimizerIn {
    /// Method (default `auto`).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub method: Method,
    /// RNG seed; every stochastic method is reproducible per seed (default 0).
    #[serde(default)]
    #[schema(example = 0)]
    pub seed: Option<u64>,
    /// Hard cap on objective evaluations, 1..10⁷ (default 50 000).
    #[serde(default)]
    #[rule(range = MAX_EVALUATIONS)]
    #[schema(example = 50000)]
    pub max_evaluations: Option<u64>,
    /// Wall-clock cap \[ms\], 1..600 000 (default 10 000); the best-so-far is returned with
    /// `stop_reason: "deadline"` when it ends.
    #[serde(default)]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(example = 10000)]
    pub time_limit_ms: Option<u64>,
    /// GA settings (paper Table 2 defaults).
    #[serde(default)]
    #[schema(nullable = false)]
    pub ga: Option<GaIn>,
    /// IPOP-CMA-ES restarts of `auto` when the metric is DTW, 0..9 (default 3).
    #[serde(default)]
    #[rule(range = DTW_RESTARTS)]
    #[schema(example = 3)]
    pub dtw_global_restarts: Option<u32>,
    /// Run the least-squares + zero-snap polish after `ga`, `de`, `cmaes` (and the snap after
    /// `lsq`); Euclidean only. Default true; false reproduces the paper's GA alone.
    #[serde(default)]
    pub polish: Option<bool>,
    /// Zero-snap threshold on normalized coefficients, 0..0.05 (default 2e-3).
    #[serde(default)]
    #[rule(range = SNAP_TOL)]
    #[schema(example = 0.002)]
    pub snap_tol: Option<f64>,
}

/// GA settings (paper Table 2; spec §3.5.1). Every field is optional.
#[derive(Debug, Clone, Copy, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::GaIn)]
#[serde(deny_unknown_fields)]
pub struct GaIn {
    /// Individuals per generation, 4..10 000 (paper 100).
    #[rule(range = POPULATION)]
    #[schema(example = 100)]
    pub population: Option<u64>,
    /// Maximum generations, 1..100 000 (paper 500).
    #[rule(range = GENERATIONS)]
    #[schema(example = 500)]
    pub generations: Option<u64>,
    /// Crossover probability per pair, 0..1 (paper 0.85).
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.85)]
    pub p_crossover: Option<f64>,
    /// Inversion probability per child, 0..1 (paper 0.1).
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.1)]
    pub p_inversion: Option<f64>,
    /// Probability per gene of mutation around the range, 0..1 (paper 0.1).
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.1)]
    pub p_range_mutation: Option<f64>,
    /// Initial mutation range (absolute, genes in \[0,1\]), 0..1 (paper 0.10).
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.1)]
    pub range0: Option<f64>,
    /// Range factor applied every `range_every` generations, 0..1 (spec 0.25: "reduced by 75 %").
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.25)]
    pub range_factor: Option<f64>,
    /// Generations between range reductions, 1..100 000 (paper 50).
    #[rule(range = GENERATIONS)]
    #[schema(example = 50)]
    pub range_every: Option<u64>,
    /// Classic mutation probability per gene, 0..1 (spec 0.01).
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.01)]
    pub p_mutation: Option<f64>,
    /// Stop after this many generations without relative improvement > 1e-12, 1..100 000
    /// (spec 100).
    #[rule(range = GENERATIONS)]
    #[schema(example = 100)]
    pub stall_generations: Option<u64>,
}

/// Optional outputs (spec §4).
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::OutputsIn)]
#[serde(deny_unknown_fields)]
pub struct OutputsIn {
    /// Dense curves of the fitted law (default none).
    #[serde(default)]
    #[schema(nullable = false)]
    pub curves: Option<CurvesIn>,
    /// EN and DTW of the fitted law against every supplied or derived channel (default true).
    #[serde(default)]
    pub error_table: Option<bool>,
    /// Best objective per generation/iteration (default false).
    #[serde(default)]
    pub history: Option<bool>,
    /// Nearest Table-3 catalogue law (default true).
    #[serde(default)]
    pub classify: Option<bool>,
}

/// Dense-curve request.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law_fit::CurvesIn)]
#[serde(deny_unknown_fields)]
pub struct CurvesIn {
    /// Number of uniformly spaced points over `[t_a, t_b]`, 0..100 000 (0 = none; 1 gives `t_a`).
    #[rule(range = CURVE_COUNT)]
    #[schema(example = 0)]
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub count: u64,
    /// Quantities to return (default all: s, v, a, j).
    #[serde(default)]
    pub quantities: Option<Vec<crate::calc::cam_law::law::Quantity>>,
}

/// Response of `POST /v1/fit-cam-law` (spec §4).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law_fit::FitCamLawResponse)]
pub struct FitCamLawResponse {
    /// Identified normalized coefficients `ĉ0..ĉ6` (Σ = 1; paper c1..c7).
    pub coefficients: Vec<f64>,
    /// Segment durations `c_k = ĉ_k·Δt` \[x\].
    pub durations: Vec<f64>,
    /// The 8 knots `t_0..t_7` with displacement, velocity and one-sided accelerations.
    pub knots: Vec<Knot>,
    /// Exact peaks of the fitted law (spec §3.2).
    pub peaks: Peaks,
    /// Acceleration jumps (jerk impulses) of the fitted law; may be empty.
    pub acceleration_jumps: Vec<Jump>,
    /// Objective at the initial coefficients and at the solution.
    pub objective: ObjectiveOut,
    /// EN and DTW of the fitted law against every supplied or derived channel (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub error_table: Option<ErrorTable>,
    /// Nearest Table-3 law (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub classification: Option<Classification>,
    /// Dense curves of the fitted law (when `outputs.curves.count` > 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub curves: Option<Curves>,
    /// Best objective after each generation/iteration (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub history: Option<Vec<f64>>,
    /// How the optimizer ran and stopped.
    pub optimizer_report: OptimizerReport,
    /// Warning codes (may be empty).
    pub warnings: Vec<Warning>,
    /// The request's unit labels, echoed.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub units: Option<Units>,
}

/// Objective values (spec §3.6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law_fit::ObjectiveOut)]
pub struct ObjectiveOut {
    /// Metric used.
    pub metric: MetricName,
    /// Quantity compared.
    pub quantity: FitQuantity,
    /// DTW band radius \[samples\]; null for `euclidean`.
    pub dtw_window: Option<u64>,
    /// Objective at the initial coefficients [channel unit].
    pub initial: f64,
    /// Objective at the solution [channel unit]; ≤ `initial`.
    #[serde(rename = "final")]
    pub final_value: f64,
}

/// EN and DTW of one channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law_fit::ChannelErrors)]
pub struct ChannelErrors {
    /// Euclidean norm of the difference [channel unit].
    pub euclidean: f64,
    /// The paper's DTW with the request's band radius (1 for Euclidean fits) [channel unit].
    pub dtw: f64,
}

/// Errors of the fitted law per channel (paper Tables 5, 7, 9).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law_fit::ErrorTable)]
pub struct ErrorTable {
    /// Displacement errors \[U\] (when the channel was supplied).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub displacement: Option<ChannelErrors>,
    /// Velocity errors [U/x] (when supplied or derived).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub velocity: Option<ChannelErrors>,
    /// Acceleration errors [U/x²] (when supplied or derived).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub acceleration: Option<ChannelErrors>,
}

/// Nearest catalogue law by `max_k |ĉ_k − c_ref,k|` (spec §3.6).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law_fit::Classification)]
pub struct Classification {
    /// Paper id and name, e.g. "L5 modified trapezoid".
    #[schema(example = "L5 modified trapezoid")]
    pub nearest: String,
    /// `max_k |ĉ_k − c_ref,k|`.
    pub max_coef_diff: f64,
}

/// How the optimizer ran (spec §4).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law_fit::OptimizerReport)]
pub struct OptimizerReport {
    /// Method used.
    pub method: Method,
    /// RNG seed used.
    pub seed: u64,
    /// Objective/model evaluations actually performed (each a full model curve).
    pub evaluations: u64,
    /// Iterations: GA/DE/CMA-ES generations plus least-squares (Jacobian) iterations.
    pub iterations: u64,
    /// Time spent in the optimizer \[ms\] (single-threaded; measured by the monotonic clock, so it
    /// equals CPU time unless the machine is oversubscribed).
    pub cpu_ms: f64,
    /// Wall-clock time of the whole request computation, including validation and outputs \[ms\].
    pub wall_ms: f64,
    /// Why the optimizer stopped: `converged`, `max_iterations`, `max_evaluations`, `deadline`
    /// (the time limit), `stall`, `completed`. A budget stop returns the best-so-far.
    pub stop_reason: StopReason,
    /// Least-squares starts run (`auto`: up to 10).
    pub starts_used: u32,
    /// Segments set to exactly zero by the zero-snap step (indices 0..6).
    pub snapped_segments: Vec<usize>,
}

// The ranges of this module's per-field rules (`#[rule]` on the wire types above): the check at
// the door and the document both read them.
/// A sampled value (data channel, boundary value): finite and within the law's magnitude cap
/// (rescale the unit beyond it); the same bound as the evaluator's boundary values.
pub const DATA_VALUE: Range = crate::calc::cam_law::wire::BOUNDARY_VALUE;

/// Samples of a generated abscissa grid [–] (spec §2: 7 unknowns need at least 8).
pub const GRID_COUNT: Range = Range::int(MIN_SAMPLES as i64, MAX_SAMPLES as i64);
/// DTW window \[samples\]; at most N, the number of samples (a cross-field rule).
pub const DTW_WINDOW: Range = Range::int(0, MAX_SAMPLES as i64);
/// Objective evaluations of the optimizer [–].
pub const MAX_EVALUATIONS: Range = Range::int(1, 10_000_000);
/// IPOP-CMA-ES restarts of `auto` with the DTW metric [–].
pub const DTW_RESTARTS: Range = Range::int(0, 9);
/// Zero-snap threshold on normalized coefficients [–].
pub const SNAP_TOL: Range = Range::closed(0.0, 0.05);
/// GA population [–].
pub const POPULATION: Range = Range::int(4, 10_000);
/// GA generation counts (generations, range_every, stall_generations) [–].
pub const GENERATIONS: Range = Range::int(1, 100_000);
/// A GA probability or range fraction [–].
pub const PROBABILITY: Range = Range::closed(0.0, 1.0);
/// Points of the dense output curves [–] (0: none).
pub const CURVE_COUNT: Range = Range::int(0, MAX_CURVE_COUNT as i64);
/// A starting coefficient [–] (normalized internally, so any finite non-negative number).
pub const INITIAL_COEFFICIENT: Range = crate::calc::cam_law::wire::COEFFICIENT;
