//! Wire types of `POST /v1/cam-law/evaluate` (spec §8b, outputs of §4).
//!
//! Units are not converted (spec §2): the abscissa `x` is time or cam angle (unit "x"), the
//! displacement has unit U; velocity U/x, acceleration U/x², jerk U/x³. The optional `units`
//! labels are echoed back.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::catalogue::{NamedLaw, PeakFactors};
use super::law::{Jump, Knot, Quantity};
use crate::calc::Range;

/// Largest number of abscissae per evaluate request (spec §8b).
pub const MAX_POINTS: usize = 200_000;

/// Request of `POST /v1/cam-law/evaluate`: exactly one of `coefficients` or `law`.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law::EvaluateRequest)]
#[serde(deny_unknown_fields)]
#[rules(one_of("coefficients", "law"))]
#[schema(example = json!({
    "coefficients": [0.0645, 0.129, 0.1935, 0.0968, 0.2581, 0.2258, 0.0323],
    "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0, "v_a": 0.2, "v_b": 0.5, "a_a": 1.4, "a_b": 1.2},
    "abscissa": {"values": [0.0, 0.25, 0.5, 0.75, 1.0]},
    "quantities": ["s", "v", "a", "j"],
    "normalize": false
}))]
pub struct EvaluateRequest {
    /// Duration coefficients `ĉ0..ĉ6` of the general 7-segment law (paper c1..c7): 7 numbers
    /// ≥ 0 summing to 1 within 1e-3 (renormalized; set `normalize` to accept any positive sum).
    /// Both pulses (c0..c2 and c4..c6) must be non-empty. Exclusive with `law`.
    #[serde(default)]
    #[rule(items = COEFFICIENT, min_items = 7, max_items = 7)]
    #[schema(example = json!([0.0645, 0.129, 0.1935, 0.0968, 0.2581, 0.2258, 0.0323]))]
    pub coefficients: Option<Vec<f64>>,
    /// A classic law of spec Appendix A by name. Exclusive with `coefficients`. Laws outside
    /// the 7-segment class (constant_velocity, cubic, polynomial_*, double_harmonic) require zero
    /// end rates.
    #[serde(default)]
    #[schema(nullable = false)]
    pub law: Option<NamedLaw>,
    /// Boundary conditions of the motion segment (paper constraint vector λ).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub constraints: ConstraintsIn,
    /// Where to evaluate the curves; omit it to get only the law's description and peaks.
    #[serde(default)]
    #[schema(nullable = false)]
    pub abscissa: Option<AbscissaIn>,
    /// Quantities returned in `curves` (default all four: s, v, a, j). Duplicates are ignored.
    #[serde(default)]
    pub quantities: Option<Vec<Quantity>>,
    /// Accept coefficients whose sum is any positive number (renormalized, warning
    /// `coefficients_renormalized`). Default false: the sum must be 1 within 1e-3.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub normalize: bool,
    /// Free-text unit labels, echoed back (spec §2).
    #[serde(default)]
    #[schema(nullable = false)]
    pub units: Option<Units>,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false, example = 2000)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for EvaluateRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// Boundary conditions (spec §2). Every field is optional.
#[derive(Debug, Clone, Copy, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law::ConstraintsIn)]
#[serde(deny_unknown_fields)]
pub struct ConstraintsIn {
    /// Segment start `t_a` \[x\]. Default: first abscissa (0 without an abscissa).
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 0.0)]
    pub t_a: Option<f64>,
    /// Segment end `t_b` \[x\], `> t_a`. Default: last abscissa (1 without an abscissa).
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 1.0)]
    pub t_b: Option<f64>,
    /// Displacement at the start `s_a` \[U\]. Default 0.
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 0.0)]
    pub s_a: Option<f64>,
    /// Displacement at the end `s_b` \[U\]. Default 1 (unit rise).
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 1.0)]
    pub s_b: Option<f64>,
    /// Velocity at the start `v_a` [U/x]. Default 0.
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 0.2)]
    pub v_a: Option<f64>,
    /// Velocity at the end `v_b` [U/x]. Default 0.
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 0.5)]
    pub v_b: Option<f64>,
    /// Acceleration at the start `a_a` [U/x²]. Default 0.
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 1.4)]
    pub a_a: Option<f64>,
    /// Acceleration at the end `a_b` [U/x²]. Default 0.
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 1.2)]
    pub a_b: Option<f64>,
}

/// Sample abscissae: exactly one of `values` or `grid`.
#[derive(Debug, Clone, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law::AbscissaIn)]
#[serde(deny_unknown_fields)]
#[rules(one_of_object("values", "grid"))]
pub struct AbscissaIn {
    /// Explicit abscissae \[x\], strictly increasing, 1..200 000 values, all inside
    /// `[t_a − 1e-9·Δt, t_b + 1e-9·Δt]` (values within that tolerance are clamped).
    #[serde(default)]
    #[rule(items = BOUNDARY_VALUE, min_items = 1, max_items = MAX_POINTS)]
    #[schema(example = json!([0.0, 0.25, 0.5, 0.75, 1.0]))]
    pub values: Option<Vec<f64>>,
    /// Uniform grid `x_k = start + k·(end − start)/(count − 1)`, `k = 0..count−1`.
    #[serde(default)]
    #[schema(nullable = false)]
    pub grid: Option<GridIn>,
}

/// A uniform grid including both ends.
#[derive(Debug, Clone, Copy, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cam_law::GridIn)]
#[serde(deny_unknown_fields)]
pub struct GridIn {
    /// First abscissa \[x\].
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 0.0)]
    pub start: f64,
    /// Last abscissa \[x\], `> start`.
    #[rule(range = BOUNDARY_VALUE)]
    #[schema(example = 1.0)]
    pub end: f64,
    /// Number of points, 2..200 000.
    #[rule(range = GRID_COUNT)]
    #[schema(example = 300)]
    pub count: u64,
}

/// Free-text unit labels (not interpreted).
#[derive(
    Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cam_law::Units)]
#[serde(deny_unknown_fields)]
pub struct Units {
    /// Unit of the abscissa, e.g. "s" or "deg" (at most 32 characters).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(max_length = MAX_UNIT_LABEL)]
    #[schema(example = "s")]
    pub x: Option<String>,
    /// Unit of the displacement, e.g. "rad" or "mm" (at most 32 characters).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(max_length = MAX_UNIT_LABEL)]
    #[schema(example = "rad")]
    pub s: Option<String>,
}

/// Longest accepted unit label, in characters (the `max_length` of [`Units`]).
pub const MAX_UNIT_LABEL: usize = 32;

/// Warning codes (spec §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cam_law::Warning)]
#[serde(rename_all = "snake_case")]
pub enum Warning {
    /// The coefficients did not sum to 1 and were renormalized.
    CoefficientsRenormalized,
    /// Δs = 0 with zero end rates: the law is flat and does not depend on the coefficients.
    NonIdentifiable,
    /// A pulse peak has the sign opposite to the usual one for this rise/fall (end rates
    /// dominate): `sign(A1) ≠ sign(Δs)` or `sign(A2) = sign(Δs)`.
    PeakSignUnusual,
    /// (fit only) a channel was derived by numerical differentiation.
    DerivedChannelNoiseGain,
    /// (fit only) a segment is shorter than the sample spacing next to a jump.
    SegmentBelowResolution,
    /// (fit only) the optimizer stopped on its budget.
    BudgetExhausted,
}

/// Peaks of the evaluated law, in physical units.
///
/// For the general 7-segment law (and named laws of the class) every field but `peak_factors`
/// is present (`peak_factors` is added for named laws evaluated with zero end rates). For named
/// laws outside the class, `a1`/`a2` are absent and the peaks are the Appendix-A factors scaled:
/// `v_max_abs = Cv·|Δs|/Δt`, `a_max_abs = Ca·|Δs|/Δt²` (absent: infinite, constant velocity),
/// `jerk_max_abs_finite = Cj·|Δs|/Δt³` (absent: infinite).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law::PeaksOut)]
pub struct PeaksOut {
    /// Peak of the first acceleration pulse `A1` [U/x²] (7-segment class only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a1: Option<f64>,
    /// Peak of the second acceleration pulse `A2` [U/x²] (7-segment class only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a2: Option<f64>,
    /// Largest |a| [U/x²]; absent when infinite (constant velocity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a_max_abs: Option<f64>,
    /// Largest |v| [U/x].
    pub v_max_abs: f64,
    /// First abscissa where |v| is largest \[x\].
    pub x_at_v_max: f64,
    /// Largest finite |jerk| [U/x³] (impulses at jumps excluded); absent when the Appendix-A
    /// table gives Cj = ∞ for a named law outside the class.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jerk_max_abs_finite: Option<f64>,
    /// Dimensionless Appendix-A factors Cv, Ca, Cj of a named law (only with zero end rates).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub peak_factors: Option<PeakFactors>,
}

/// Sampled curves at exactly the requested abscissae (same order and length).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law::Curves)]
pub struct Curves {
    /// Abscissae as given \[x\].
    pub x: Vec<f64>,
    /// Displacement \[U\] (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub s: Option<Vec<f64>>,
    /// Velocity [U/x] (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v: Option<Vec<f64>>,
    /// Acceleration [U/x²] (when requested; right-continuous at inner jumps, left-continuous at `t_b`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<Vec<f64>>,
    /// Jerk [U/x³] (when requested; impulses at acceleration jumps are not represented).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub j: Option<Vec<f64>>,
}

/// Response of `POST /v1/cam-law/evaluate` (spec §8b; law description as in §4).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law::EvaluateResponse)]
pub struct EvaluateResponse {
    /// The named law evaluated, when the request gave `law`.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub law: Option<NamedLaw>,
    /// Normalized coefficients `ĉ0..ĉ6` (Σ = 1); absent for named laws outside the class.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coefficients: Option<Vec<f64>>,
    /// Segment durations `c_k = ĉ_k·Δt` \[x\]; absent for named laws outside the class.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub durations: Option<Vec<f64>>,
    /// The 8 knots `t_0..t_7` with s, v and one-sided accelerations; absent for named laws
    /// outside the class.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub knots: Option<Vec<Knot>>,
    /// Exact peaks in physical units (see [`PeaksOut`]).
    pub peaks: PeaksOut,
    /// Acceleration jumps (jerk impulses), in abscissa order; may be empty.
    pub acceleration_jumps: Vec<Jump>,
    /// Curves at the requested abscissae; absent when the request has no `abscissa`.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub curves: Option<Curves>,
    /// Warning codes (may be empty).
    pub warnings: Vec<Warning>,
    /// The request's unit labels, echoed.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub units: Option<Units>,
}

/// A boundary value (`t_a`, `t_b`, `s_a`, `s_b`, end rates): finite and at most
/// [`MAX_MAGNITUDE`](super::law::MAX_MAGNITUDE) in magnitude (spec §6 item 9).
pub const BOUNDARY_VALUE: Range = Range::FINITE
    .min(-super::law::MAX_MAGNITUDE)
    .max(super::law::MAX_MAGNITUDE);
/// A duration coefficient `ĉ_i`: finite and non-negative.
pub const COEFFICIENT: Range = Range::FINITE.min(0.0);
/// Points of a uniform abscissa grid.
pub const GRID_COUNT: Range = Range::int(2, MAX_POINTS as i64);
