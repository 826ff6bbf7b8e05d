//! Wire types of `POST /v1/bezier-motion-law` (spec `bezier_motion.md` §2, §4, §8). SI units,
//! angles in rad (motor side unless said otherwise); paper symbols keep their capitals on the
//! wire (`J_eq_kgm2`, `Phi_rad`, `T_s`).

use serde::{Deserialize, Deserializer, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::common::{TimeLimited, Warning};
use crate::numerics::SolverReport;

/// One inertia `J_i` [kg m²].
pub const INERTIA: Range = Range::closed(0.0, 1e12);
/// Equivalent inertia `J_eq` [kg m²].
pub const J_EQ: Range = Range::FINITE.gt(0.0).max(1e12);
/// Joint stiffness `k` [N m/rad]: at least 1e-6 (a softer joint with the largest inertia and
/// damping drives the damping ratio past what f64 can carry through the end state).
pub const STIFFNESS: Range = Range::FINITE.min(1e-6).max(1e15);
/// Joint damping `c` [N m s/rad].
pub const DAMPING: Range = Range::closed(0.0, 1e15);
/// Reducer ratio `z` (≠ 0 is checked too).
pub const RATIO: Range = Range::closed(-1e3, 1e3);
/// Total motor rotation (`Phi_rad` \[rad\] or `Phi_rev` \[rev\]; ≠ 0 is checked too).
pub const PHI: Range = Range::closed(-1e9, 1e9);
/// Motion time `T` \[s\].
pub const MOTION_TIME: Range = Range::closed(1e-6, 1e4);
/// Order `m` of the vanishing end derivatives.
pub const ORDER_M: Range = Range::int(1, 6);
/// Number `p` of free interior ordinates.
pub const FREE_P: Range = Range::int(1, 20);
/// Largest degree `N = 2m + p − 1` of φ'' (Bernstein conditioning, spec §6).
pub const MAX_ACCEL_DEGREE: usize = 30;
/// An interior ordinate γ_j \[rad\] (also `|γ_j| ≤ 1e3·|Phi|`).
pub const GAMMA: Range = Range::closed(-1e12, 1e12);
/// `|γ_j| / |Phi|` must not exceed this.
pub const GAMMA_OVER_PHI_MAX: f64 = 1e3;
/// Relative stiffness spread δ of the robust extension.
pub const ROBUST_REL: Range = Range::FINITE.gt(0.0).max(0.5);
/// Samples of the time history (each window).
pub const HISTORY_SAMPLES: Range = Range::int(0, 20_000);
/// Free-vibration window after T \[s\].
pub const WINDOW_AFTER: Range = Range::closed(0.0, 1e4);
/// Stiffness factor of the sensitivity sweep.
pub const STIFFNESS_FACTOR: Range = Range::FINITE.gt(0.0).max(100.0);
/// Most stiffness factors per request.
pub const MAX_FACTORS: usize = 201;
/// Most inertias in `inertias_kgm2`.
pub const MAX_INERTIAS: usize = 16;
/// EI shaper's tolerable residual vibration `V` (amplitudes `(1±V)/4`, `(1−V)/2` stay ≥ 0).
pub const EI_TOLERANCE: Range = Range::closed(0.0, 0.5);
/// Most shapers in `shaper_comparison.shapers` (each of the four at most once).
pub const MAX_SHAPERS: usize = 4;

/// Request of `POST /v1/bezier-motion-law`.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::BezierMotionRequest)]
#[serde(deny_unknown_fields)]
pub struct BezierMotionRequest {
    /// `simulate` (evaluate the law `motion.gamma_rad`) or `optimize` (default: the optimal law,
    /// evaluated beside the reference law `motion.gamma_rad`).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub mode: Mode,
    /// The compliant drive.
    pub system: SystemIn,
    /// The move and its Bezier law.
    pub motion: MotionIn,
    /// Optimisation settings (used in `optimize` mode).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub optimize: OptimizeIn,
    /// Optional outputs.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub outputs: OutputsIn,
    /// Wall-clock budget of this request \[ms\] (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false)]
    pub time_limit_ms: Option<u64>,
}

impl TimeLimited for BezierMotionRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// What to compute.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bezier_motion::Mode)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Evaluate the given law.
    Simulate,
    /// Zero (or least) residual vibration by the closed-form solve.
    #[default]
    Optimize,
}

/// The drive: inertia (list or equivalent value), joint stiffness and damping, reducer ratio.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::SystemIn)]
#[serde(deny_unknown_fields)]
#[rules(one_of("inertias_kgm2", "J_eq_kgm2"))]
pub struct SystemIn {
    /// Inertias downstream of the joint, summed to `J_eq` [kg m²] (paper J1, J2, J3): 1..16
    /// items, each ≥ 0, sum > 0. Exactly one of this and `J_eq_kgm2`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(items = INERTIA, min_items = 1, max_items = MAX_INERTIAS)]
    #[schema(nullable = false, example = json!([0.005, 0.005, 2.8]))]
    pub inertias_kgm2: Option<Vec<f64>>,
    /// Equivalent inertia `J_eq` [kg m²]. Exactly one of this and `inertias_kgm2`.
    #[serde(rename = "J_eq_kgm2", default, skip_serializing_if = "Option::is_none")]
    #[rule(range = J_EQ)]
    #[schema(nullable = false, example = 2.81)]
    pub j_eq_kgm2: Option<f64>,
    /// Joint torsional stiffness `k` [N m/rad].
    #[serde(rename = "k_Nm_per_rad")]
    #[rule(range = STIFFNESS)]
    #[schema(example = 8000.0)]
    pub k_nm_per_rad: f64,
    /// Joint viscous damping `c` [N m s/rad].
    #[serde(rename = "c_Nms_per_rad")]
    #[rule(range = DAMPING)]
    #[schema(example = 35.0)]
    pub c_nms_per_rad: f64,
    /// Reducer ratio `z` = α/φ (output/motor), ≠ 0.
    #[rule(range = RATIO)]
    #[schema(example = 0.05)]
    pub z: f64,
}

/// The move: total rotation, time, and the Bezier law's shape and free ordinates.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::MotionIn)]
#[serde(deny_unknown_fields)]
#[rules(one_of("Phi_rad", "Phi_rev"))]
pub struct MotionIn {
    /// Total motor rotation `Phi` \[rad\], ≠ 0. Exactly one of this and `Phi_rev`.
    #[serde(rename = "Phi_rad", default, skip_serializing_if = "Option::is_none")]
    #[rule(range = PHI)]
    #[schema(nullable = false, example = 125.66370614359172)]
    pub phi_rad: Option<f64>,
    /// Total motor rotation \[rev\] (`Phi_rad = 2π·Phi_rev`), ≠ 0. Exactly one of this and
    /// `Phi_rad`.
    #[serde(rename = "Phi_rev", default, skip_serializing_if = "Option::is_none")]
    #[rule(range = PHI)]
    #[schema(nullable = false, example = 20.0)]
    pub phi_rev: Option<f64>,
    /// Motion time `T` \[s\].
    #[serde(rename = "T_s")]
    #[rule(range = MOTION_TIME)]
    #[schema(example = 1.0)]
    pub t_s: f64,
    /// Order `m` of the derivatives forced to zero at both ends (1..6). Default 2.
    #[serde(default = "default_m", deserialize_with = "null_m")]
    #[rule(range = ORDER_M)]
    #[schema(example = 2)]
    pub m: u64,
    /// Number `p` of free interior ordinates (1..20), with `N = 2m + p − 1 ≤ 30`. Default 3.
    #[serde(default = "default_p", deserialize_with = "null_p")]
    #[rule(range = FREE_P)]
    #[schema(example = 3)]
    pub p: u64,
    /// The p interior ordinates γ_j \[rad\]: the law itself in `simulate`, the reference law in
    /// `optimize`; each `|γ_j| ≤ 1e3·|Phi|`. Default: the linear ramp `Phi·j/(p+1)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(items = GAMMA)]
    #[schema(nullable = false)]
    pub gamma_rad: Option<Vec<f64>>,
}

impl Default for MotionIn {
    fn default() -> Self {
        Self {
            phi_rad: None,
            phi_rev: None,
            t_s: 1.0,
            m: default_m(),
            p: default_p(),
            gamma_rad: None,
        }
    }
}

fn yes() -> bool {
    true
}
fn default_m() -> u64 {
    2
}
fn default_p() -> u64 {
    3
}
/// `m`: `null` reads as the default 2, exactly as if absent.
fn null_m<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    Ok(Option::<u64>::deserialize(d)?.unwrap_or_else(default_m))
}
/// `p`: `null` reads as the default 3, exactly as if absent.
fn null_p<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    Ok(Option::<u64>::deserialize(d)?.unwrap_or_else(default_p))
}
/// `shapers`: `null` reads as all four, exactly as if absent.
fn null_shapers<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<ShaperIn>, D::Error> {
    Ok(Option::<Vec<ShaperIn>>::deserialize(d)?.unwrap_or_else(all_shapers))
}
/// `ei_tolerance`: `null` reads as the default 0.05, exactly as if absent.
fn null_ei_tolerance<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or_else(default_ei_tolerance))
}

/// How to choose among the zero-energy laws.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bezier_motion::Objective)]
#[serde(rename_all = "snake_case")]
pub enum ObjectiveIn {
    /// Closest to the reference ordinates (the point a Gauss–Newton/BFGS run from them reaches).
    #[default]
    MinDeviation,
    /// Least `∫₀ᵀ φ''² dt`.
    MinAccelL2,
    /// Least `∫₀ᵀ φ'''² dt`.
    MinJerkL2,
}

/// Optimisation settings.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::OptimizeIn)]
#[serde(deny_unknown_fields)]
pub struct OptimizeIn {
    /// Secondary objective. Default `min_deviation`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub objective: ObjectiveIn,
    /// Robust extension (not in the paper): also zero the residual energy for `k·(1−δ)` and
    /// `k·(1+δ)` (6 constraints: exact when p ≥ 6). Ignored with a warning in `simulate`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = ROBUST_REL)]
    #[schema(nullable = false, example = 0.1)]
    pub robust_stiffness_rel: Option<f64>,
}

/// Optional outputs.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::OutputsIn)]
#[serde(deny_unknown_fields)]
pub struct OutputsIn {
    /// Peak |φ'|, |φ''|, |φ'''|, least velocity and reversal check. Default true.
    #[serde(default = "yes", deserialize_with = "crate::calc::rules::null_true")]
    pub kinematic_peaks: bool,
    /// Sampled response during and after the move.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub time_history: Option<TimeHistoryIn>,
    /// Residual energy of the returned law for scaled stiffness.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub sensitivity: Option<SensitivityIn>,
    /// The returned law beside input shapers (ZV, ZVD, EI) applied to a baseline move on the
    /// same drive and the same total move time T (off by default; only for ξ < 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub shaper_comparison: Option<ShaperComparisonIn>,
}

/// Baseline move of the shaper comparison.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bezier_motion::Baseline)]
#[serde(rename_all = "snake_case")]
pub enum BaselineIn {
    /// Equal thirds: `φ'' = +a0`, 0, `−a0`, `a0 = 4.5·Phi/T0²`.
    #[default]
    Trapezoid,
    /// `φ'' = (2π·Phi/T0²)·sin(2πt/T0)` on [0, T0].
    Cycloidal,
}

/// An input shaper (impulse train designed for the nominal drive: `Td = 2π/ωd`,
/// `K = exp(−ξπ/√(1−ξ²))`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = bezier_motion::Shaper)]
#[serde(rename_all = "snake_case")]
pub enum ShaperIn {
    /// The unshaped baseline: `[1]` at `[0]`.
    None,
    /// Zero vibration: `[1, K]/(1+K)` at `[0, Td/2]`.
    Zv,
    /// Zero vibration and derivative: `[1, 2K, K²]/(1+K)²` at `[0, Td/2, Td]`.
    Zvd,
    /// Extra-insensitive: `[(1+V)/4, (1−V)/2, (1+V)/4]` at `[0, Td/2, Td]`.
    Ei,
}

fn all_shapers() -> Vec<ShaperIn> {
    vec![ShaperIn::None, ShaperIn::Zv, ShaperIn::Zvd, ShaperIn::Ei]
}

fn default_ei_tolerance() -> f64 {
    0.05
}

/// The shaper comparison: each shaper convolved with the baseline, whose duration is
/// `T0 = T − (last impulse time)`, so every shaped move ends at T like the Bezier law.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::ShaperComparisonIn)]
#[serde(deny_unknown_fields)]
pub struct ShaperComparisonIn {
    /// Baseline move. Default `trapezoid`.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub baseline: BaselineIn,
    /// Shapers to compare, each at most once (1..4 items). Default all four.
    #[serde(default = "all_shapers", deserialize_with = "null_shapers")]
    #[rule(min_items = 1, max_items = MAX_SHAPERS)]
    #[schema(example = json!(["none", "zv", "zvd", "ei"]))]
    pub shapers: Vec<ShaperIn>,
    /// EI's tolerable residual vibration `V` (fraction of the unshaped one). Default 0.05.
    #[serde(
        default = "default_ei_tolerance",
        deserialize_with = "null_ei_tolerance"
    )]
    #[rule(range = EI_TOLERANCE)]
    #[schema(example = 0.05)]
    pub ei_tolerance: f64,
}

impl Default for ShaperComparisonIn {
    fn default() -> Self {
        Self {
            baseline: BaselineIn::default(),
            shapers: all_shapers(),
            ei_tolerance: default_ei_tolerance(),
        }
    }
}

impl Default for OutputsIn {
    fn default() -> Self {
        Self {
            kinematic_peaks: true,
            time_history: None,
            sensitivity: None,
            shaper_comparison: None,
        }
    }
}

/// Time-history sampling. Requires `rho_max ≤ 1.6e6` (sub-step budget).
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::TimeHistoryIn)]
#[serde(deny_unknown_fields)]
pub struct TimeHistoryIn {
    /// Uniform samples on [0, T], both ends included (0 = none).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    #[rule(range = HISTORY_SAMPLES)]
    #[schema(example = 200)]
    pub n_samples: u64,
    /// Length of the free-vibration window after T \[s\].
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    #[rule(range = WINDOW_AFTER)]
    #[schema(example = 0.5)]
    pub t_after_s: f64,
    /// Samples in (T, T + t_after_s].
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    #[rule(range = HISTORY_SAMPLES)]
    #[schema(example = 100)]
    pub n_after: u64,
}

/// Stiffness sensitivity sweep.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = bezier_motion::SensitivityIn)]
#[serde(deny_unknown_fields)]
pub struct SensitivityIn {
    /// Factors f: the returned law is evaluated for stiffness `k·f` (J_eq, c, z fixed); ≤ 201.
    #[rule(items = STIFFNESS_FACTOR, max_items = MAX_FACTORS)]
    #[schema(example = json!([0.8, 0.9, 1.0, 1.1, 1.2]))]
    pub stiffness_factors: Vec<f64>,
}

// ---------------------------------------------------------------------------------------------
// Response
// ---------------------------------------------------------------------------------------------

/// Response of `POST /v1/bezier-motion-law`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bezier_motion::BezierMotionResponse)]
pub struct BezierMotionResponse {
    /// The mode that ran.
    pub mode: Mode,
    /// Derived system quantities.
    pub system: SystemOut,
    /// How the end state was computed.
    pub method: MethodOut,
    /// The returned law (the given one in `simulate`, the optimum in `optimize`).
    pub law: LawOut,
    /// Residual vibration of the returned law.
    pub residual: ResidualOut,
    /// The reference law and its residual (`optimize` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub reference: Option<ReferenceOut>,
    /// The solve (`optimize` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub optimizer: Option<OptimizerOut>,
    /// Residual energy at `k·(1−δ)`, `k`, `k·(1+δ)` (robust extension only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub robust: Option<Vec<SensitivityRow>>,
    /// Kinematic peaks and checks (when `outputs.kinematic_peaks`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub kinematics: Option<KinematicsOut>,
    /// Stiffness sensitivity (when `outputs.sensitivity`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub sensitivity: Option<Vec<SensitivityRow>>,
    /// Sampled response (when `outputs.time_history` asks for samples).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub time_history: Option<HistoryOut>,
    /// The law beside input shapers (when `outputs.shaper_comparison` is given and ξ < 1; for
    /// ξ ≥ 1 omitted with the warning `SHAPER_COMPARISON_NOT_OSCILLATORY`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub shaper_comparison: Option<ShaperComparisonOut>,
    /// Warnings (may be empty).
    pub warnings: Vec<Warning>,
    /// Cost: `iterations` = response matrices built, `evaluations` = those plus history
    /// sub-steps; `stop_reason` is `completed` (closed form, no iteration).
    pub report: SolverReport,
}

/// Derived system quantities (spec §3.1).
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::SystemOut)]
pub struct SystemOut {
    /// Equivalent inertia `J_eq` [kg m²].
    #[serde(rename = "J_eq_kgm2")]
    pub j_eq_kgm2: f64,
    /// Natural frequency `ωn = sqrt(k/J_eq)` [rad/s].
    pub omega_n_rad_s: f64,
    /// Damping ratio `ξ = c / (2 sqrt(k J_eq))`.
    pub xi: f64,
    /// Damped frequency `ωd` [rad/s] (absent for ξ ≥ 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega_d_rad_s: Option<f64>,
    /// Natural frequency `f_n = ωn/2π` \[Hz\].
    pub f_n_hz: f64,
    /// `η = ½ J_eq (z/ωd)²` [kg m² s²] of paper Eq. 29 (absent for ξ ≥ 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eta: Option<f64>,
    /// `ωn T / 2π`.
    pub periods_in_move: f64,
    /// `T·|p_slow|`.
    pub rho_min: f64,
    /// `T·|p_fast|`.
    pub rho_max: f64,
}

/// End-state method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = bezier_motion::EndState)]
#[serde(rename_all = "snake_case")]
pub enum EndState {
    /// Integration by parts, closed form (r ≤ 1).
    ClosedFormIbp,
    /// Composite Gauss–Legendre on the Duhamel integral (r > 1).
    GaussLegendre,
    /// Strongly over-damped drive (ξ ≥ 1.25, r > 1): the two real modes in closed form (the
    /// slow one by Gauss–Legendre when `2N > T·|p_slow|`: `panels`, `nodes` are then its rule).
    ModalClosedForm,
}

/// How the end state was computed (spec §3.5).
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::MethodOut)]
pub struct MethodOut {
    /// The method.
    pub end_state: EndState,
    /// `r = 2N / rho_min` (IBP when ≤ 1).
    pub ibp_ratio: f64,
    /// Gauss–Legendre panels (absent for IBP; on the modal path the slow mode's, when used).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub panels: Option<u64>,
    /// Gauss–Legendre nodes per panel (absent for IBP; on the modal path the slow mode's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nodes: Option<u64>,
}

/// The law's control polygons (spec §3.2).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bezier_motion::LawOut)]
pub struct LawOut {
    /// Free interior ordinates γ \[rad\].
    pub gamma_rad: Vec<f64>,
    /// γ / Phi.
    #[serde(rename = "gamma_over_Phi")]
    pub gamma_over_phi: Vec<f64>,
    /// Displacement ordinates `S_0..S_{n_s}` \[rad\].
    #[serde(rename = "S_rad")]
    pub s_rad: Vec<f64>,
    /// Velocity ordinates `V_i` [rad/s].
    #[serde(rename = "V_rad_s")]
    pub v_rad_s: Vec<f64>,
    /// Acceleration ordinates `A_i` [rad/s²].
    #[serde(rename = "A_rad_s2")]
    pub a_rad_s2: Vec<f64>,
    /// Jerk ordinates `J_i` [rad/s³].
    #[serde(rename = "J_rad_s3")]
    pub j_rad_s3: Vec<f64>,
    /// Degree `n_s = 2m + p + 1` of φ.
    pub degree: u64,
}

/// Residual vibration at the end of the move (spec §3.6).
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::ResidualOut)]
pub struct ResidualOut {
    /// Platform lag ψ(T) \[rad\].
    #[serde(rename = "psi_T_rad")]
    pub psi_t_rad: f64,
    /// ψ'(T) [rad/s] (= β'(T), since φ'(T) = 0).
    #[serde(rename = "dpsi_T_rad_s")]
    pub dpsi_t_rad_s: f64,
    /// Residual vibration energy `E(T) = ½ J_eq (ψ'² + ωn² ψ²)` \[J\] (paper Eq. 24).
    #[serde(rename = "E_T_J")]
    pub e_t_j: f64,
    /// `Q = G² + ωn² F²` of paper Eq. 29 (absent for ξ ≥ 1).
    #[serde(rename = "Q", skip_serializing_if = "Option::is_none")]
    pub q: Option<f64>,
    /// Residual amplitude R of the platform \[rad\] (absent for ξ ≥ 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_amplitude_rad: Option<f64>,
    /// Acceleration envelope `ωn² R` [rad/s²] (absent for ξ ≥ 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_accel_envelope_rad_s2: Option<f64>,
    /// Round-off floor `E_floor = ½ J_eq (64 ε s_x)²` \[J\].
    #[serde(rename = "E_floor_J")]
    pub e_floor_j: f64,
    /// `E(T) ≤ E_floor`: numerically zero.
    pub at_numerical_floor: bool,
}

/// The reference law (`optimize` mode).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bezier_motion::ReferenceOut)]
pub struct ReferenceOut {
    /// Reference ordinates γ_ref \[rad\].
    pub gamma_rad: Vec<f64>,
    /// Its residual vibration.
    pub residual: ResidualOut,
}

/// The closed-form solve (spec §3.7).
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::OptimizerOut)]
pub struct OptimizerOut {
    /// Secondary objective used.
    pub objective: ObjectiveIn,
    /// Constraint rows (2, or 6 with the robust extension).
    pub n_constraints: u64,
    /// Numerical rank of the constraints.
    pub rank: u64,
    /// `p − rank`: dimension of the set of optimal laws before the secondary objective.
    pub free_dimensions: u64,
    /// Every constraint is met (rank = n_constraints); false: least-squares compromise.
    pub exact_zero: bool,
    /// `E / E_ref` (absent when E_ref = 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_ratio_to_reference: Option<f64>,
    /// `10 log10(E_ref / max(E, E_floor))` \[dB\] (absent when E_ref = 0).
    #[serde(rename = "reduction_dB", skip_serializing_if = "Option::is_none")]
    pub reduction_db: Option<f64>,
    /// `max |γ_j| / |Phi|` of the optimum (> 10: fragile polygon, warned).
    #[serde(rename = "max_abs_gamma_over_Phi")]
    pub max_abs_gamma_over_phi: f64,
}

/// Kinematic peaks (spec §3.9).
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::KinematicsOut)]
pub struct KinematicsOut {
    /// Peak |φ'| [rad/s].
    pub peak_velocity_rad_s: f64,
    /// Its time \[s\].
    pub t_peak_velocity_s: f64,
    /// Peak |φ''| [rad/s²].
    pub peak_accel_rad_s2: f64,
    /// Its time \[s\].
    pub t_peak_accel_s: f64,
    /// Peak |φ'''| [rad/s³].
    pub peak_jerk_rad_s3: f64,
    /// Its time \[s\].
    pub t_peak_jerk_s: f64,
    /// Least velocity in the direction of Phi, `min sign(Phi)·φ'` [rad/s] (0 at the ends).
    pub min_velocity_rad_s: f64,
    /// Its time \[s\].
    pub t_min_velocity_s: f64,
    /// The motor reverses (`min_velocity < −1e-9·peak`).
    pub motion_reversal: bool,
    /// Convex-hull bound `max |V_i|` [rad/s] (≥ peak velocity).
    pub hull_velocity_rad_s: f64,
    /// Convex-hull bound `max |A_i|` [rad/s²].
    pub hull_accel_rad_s2: f64,
    /// Convex-hull bound `max |J_i|` [rad/s³].
    pub hull_jerk_rad_s3: f64,
}

/// Residual of the returned law for one stiffness factor.
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::SensitivityRow)]
pub struct SensitivityRow {
    /// Factor f on k.
    pub stiffness_factor: f64,
    /// ωn of that system [rad/s].
    pub omega_n_rad_s: f64,
    /// ξ of that system.
    pub xi: f64,
    /// Residual energy E(T) \[J\].
    #[serde(rename = "E_T_J")]
    pub e_t_j: f64,
    /// Residual amplitude \[rad\] (absent for ξ ≥ 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_amplitude_rad: Option<f64>,
}

/// Sampled response: every vector has one entry per sample (samples on [0, T], then (T, T+t_after]).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bezier_motion::HistoryOut)]
pub struct HistoryOut {
    /// Time \[s\].
    pub t_s: Vec<f64>,
    /// Motor angle φ \[rad\].
    pub phi_rad: Vec<f64>,
    /// Motor speed φ' [rad/s].
    pub dphi_rad_s: Vec<f64>,
    /// Motor acceleration φ'' [rad/s²].
    pub ddphi_rad_s2: Vec<f64>,
    /// Rigid-joint output α = zφ \[rad\] (the paper's Figs. 5–6 plot this).
    pub alpha_rad: Vec<f64>,
    /// Platform angle β \[rad\].
    pub beta_rad: Vec<f64>,
    /// Platform speed β' [rad/s].
    pub dbeta_rad_s: Vec<f64>,
    /// Platform acceleration β'' [rad/s²].
    pub ddbeta_rad_s2: Vec<f64>,
    /// Platform lag ψ = β − zφ \[rad\].
    pub psi_rad: Vec<f64>,
    /// Joint torque on the platform τ_j = J_eq β'' [N m].
    #[serde(rename = "joint_torque_Nm")]
    pub joint_torque_nm: Vec<f64>,
    /// Sampled peak |τ_j| during the move [N m].
    #[serde(rename = "peak_joint_torque_move_Nm")]
    pub peak_joint_torque_move_nm: f64,
    /// Sampled peak |β''| during the move [rad/s²].
    pub peak_ddbeta_move_rad_s2: f64,
    /// Sampled peak |β''| after T [rad/s²] (0 without after-samples).
    pub peak_ddbeta_after_rad_s2: f64,
    /// Sub-steps per sample interval during the move.
    pub substeps_per_sample: u64,
    /// Gauss–Legendre nodes per sub-step.
    pub nodes_per_substep: u64,
}

/// The shaper comparison (`outputs.shaper_comparison`).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bezier_motion::ShaperComparisonOut)]
pub struct ShaperComparisonOut {
    /// Baseline move.
    pub baseline: BaselineIn,
    /// EI's tolerance `V`.
    pub ei_tolerance: f64,
    /// Damped period `Td = 2π/ωd` the shapers are designed for \[s\].
    pub damped_period_s: f64,
    /// One row per requested shaper, in request order; `null` where the shaper lasts the whole
    /// move or longer (`T0 ≤ 0`, warning `SHAPER_TOO_LONG`).
    pub rows: Vec<Option<ShaperRowOut>>,
    /// The returned Bezier law on the same drive.
    pub bezier: BezierRowOut,
}

/// One shaped move.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bezier_motion::ShaperRow)]
pub struct ShaperRowOut {
    /// The shaper.
    pub shaper: ShaperIn,
    /// Baseline duration `T0 = T − (last impulse time)` \[s\].
    pub baseline_time_s: f64,
    /// Residual vibration energy at T, `½ J_eq (ψ'(T)² + ωn² ψ(T)²)` \[J\] (spec §3.3).
    #[serde(rename = "E_T_J")]
    pub e_t_j: f64,
    /// Peak motor acceleration `max |u|` [rad/s²].
    pub peak_accel_rad_s2: f64,
    /// Peak motor speed `max |∫u|` [rad/s].
    pub peak_vel_rad_s: f64,
    /// The shaper's impulses.
    pub impulses: Vec<ImpulseOut>,
    /// Residual energy on the drive with stiffness `k·f`, the shaper designed for the nominal k
    /// (when `outputs.sensitivity` is given).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub sensitivity: Option<Vec<FactorEnergyOut>>,
}

/// The Bezier law's row of the shaper comparison.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = bezier_motion::BezierRow)]
pub struct BezierRowOut {
    /// Residual vibration energy at T \[J\] (as `residual.E_T_J`).
    #[serde(rename = "E_T_J")]
    pub e_t_j: f64,
    /// Peak motor acceleration `max |φ''|` [rad/s²].
    pub peak_accel_rad_s2: f64,
    /// Peak motor speed `max |φ'|` [rad/s].
    pub peak_vel_rad_s: f64,
    /// Residual energy for stiffness `k·f` (when `outputs.sensitivity` is given).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub sensitivity: Option<Vec<FactorEnergyOut>>,
}

/// One impulse of a shaper.
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::Impulse)]
pub struct ImpulseOut {
    /// Time \[s\].
    pub t_s: f64,
    /// Amplitude (a shaper's amplitudes sum to 1).
    pub amplitude: f64,
}

/// Residual energy for one stiffness factor.
#[derive(Debug, Clone, Copy, Serialize, ToSchema)]
#[schema(as = bezier_motion::FactorEnergy)]
pub struct FactorEnergyOut {
    /// Factor f on k.
    pub factor: f64,
    /// Residual energy E(T) \[J\].
    #[serde(rename = "E_T_J")]
    pub e_t_j: f64,
}
