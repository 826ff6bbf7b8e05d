//! Wire types of `POST /v1/irefc-stress` (spec `irefc_stress.md`, "JSON example" is the contract).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::common::{Shard, ShardOut};
use crate::calc::irefc::wire::{
    CHI, GeometryOut, Material, PROFILE_POINTS_MAX, PROFILE_POINTS_MIN, R2_MM, RB_MM, Warning, Z2,
};
use crate::numerics::SolverReport;

/// Single design or the paper's "structured array" sweep.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = irefc::stress::StressMode)]
#[serde(rename_all = "snake_case")]
pub enum StressMode {
    /// One design (r2, Z2, χ, rb).
    Single,
    /// Every combination of `sweep.Z2` × `sweep.chi` (× optional rb and r2 lists).
    Sweep,
}

/// Which link carries the output torque.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = irefc::stress::OutputLink)]
#[serde(rename_all = "snake_case")]
pub enum OutputLink {
    /// Cam output, crown fixed (T_cam = T_out).
    #[default]
    Cam,
    /// Crown output, cam rotation locked (T_cam = T_out·(Z2−1)/(Z2+1)).
    Crown,
}

/// How the torque is shared over the elements when an element sits at φ2.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = irefc::stress::LoadSharing)]
#[serde(rename_all = "snake_case")]
pub enum LoadSharing {
    /// The paper: F(φ2) = Fmax·sin α with Fmax from the phase-0 element set (eqs 16–17).
    #[default]
    PaperPhase0,
    /// F(φ2) = T_cam·sin α/(r1·Σsin²α) with Σ over the cage phase that puts an element at φ2.
    PhaseExact,
}

impl LoadSharing {
    /// Wire name.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::PaperPhase0 => "paper_phase0",
            Self::PhaseExact => "phase_exact",
        }
    }
}

/// Optional outputs; expensive ones are off by default and not computed unless requested.
#[derive(Debug, Clone, Copy, Default, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::stress::StressInclude)]
#[serde(deny_unknown_fields)]
pub struct StressInclude {
    /// Per-element force table of the phase-0 element set (default true; single mode only).
    pub elements: Option<bool>,
    /// Force, stress and profile-radius curves over the φ2 grid (default false; single mode only).
    pub curves: Option<bool>,
    /// Profile point sets of both wheels inside `geometry` (default false; single mode only).
    pub profiles: Option<bool>,
    /// Subsurface maximum shear stress and its depth at each maximum (default false).
    pub subsurface: Option<bool>,
}

/// Integer range `from..=to` with step 1.
#[derive(Debug, Clone, Copy, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::stress::IntRange)]
#[serde(deny_unknown_fields)]
#[rules(code = "BAD_RANGE")]
pub struct IntRange {
    /// First value (inclusive).
    #[rule(range = Z2)]
    #[schema(example = 10)]
    pub from: i64,
    /// Last value (inclusive), ≥ `from`.
    #[rule(range = Z2)]
    #[schema(example = 40)]
    pub to: i64,
}

/// Real range `from, from + step, … ≤ to` (values computed as from + i·step).
#[derive(Debug, Clone, Copy, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::stress::StepRange)]
#[serde(deny_unknown_fields)]
#[rules(code = "BAD_RANGE")]
pub struct StepRange {
    /// First value (inclusive).
    #[rule(range = CHI)]
    #[schema(example = 1.25)]
    pub from: f64,
    /// Last value (inclusive within 1e-12), ≥ `from`.
    #[rule(range = CHI)]
    #[schema(example = 1.67)]
    pub to: f64,
    /// Step (> 0).
    #[rule(range = CHI_STEP)]
    #[schema(example = 0.01)]
    pub step: f64,
}

/// The "structured array": ranges of Z2 and χ, optional lists of rb and r2.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::stress::SweepSpec)]
#[serde(deny_unknown_fields)]
#[rules(code = "BAD_RANGE")]
pub struct SweepSpec {
    /// Number of rolling elements Z2, step 1.
    #[serde(rename = "Z2")]
    pub z2: IntRange,
    /// Displacement coefficient χ.
    pub chi: StepRange,
    /// Rolling element radii \[mm\] (at least one); default: the top-level `rb_mm`.
    #[rule(items = RB_MM, min_items = 1)]
    pub rb_mm: Option<Vec<f64>>,
    /// Cage pitch radii \[mm\] (at least one); default: the top-level `r2_mm`.
    #[rule(items = R2_MM, min_items = 1)]
    pub r2_mm: Option<Vec<f64>>,
}

/// Request of `POST /v1/irefc-stress`.
#[derive(Debug, Clone, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::stress::IrefcStressRequest)]
#[serde(deny_unknown_fields)]
#[rules(code = "BAD_RANGE")]
#[schema(example = json!({"mode":"single","r2_mm":20,"Z2":26,"chi":1.4,"rb_mm":2,"lb_mm":4,"torque_Nm":119.366207,
    "output_link":"cam","wheel_material":{"E_MPa":210000,"nu":0.3},"roller_material":{"E_MPa":210000,"nu":0.3},
    "step_deg":1,"refine":true,"load_sharing":"paper_phase0","include":{"elements":true,"curves":false}}))]
pub struct IrefcStressRequest {
    /// "single" (default without `sweep`) or "sweep" (default when `sweep` is present).
    #[schema(nullable = false)]
    pub mode: Option<StressMode>,
    /// Cage generating (pitch) circle radius r2 \[mm\]; required unless `sweep.r2_mm` is given.
    #[rule(range = R2_MM)]
    #[schema(example = 20.0)]
    pub r2_mm: Option<f64>,
    /// Number of rolling elements Z2 [–]; required in mode "single".
    #[serde(rename = "Z2")]
    #[rule(range = Z2)]
    #[schema(example = 26)]
    pub z2: Option<i64>,
    /// Displacement coefficient χ (element-centre circle rc = χ·r2) [–]; required in mode "single".
    #[rule(range = CHI)]
    #[schema(example = 1.4)]
    pub chi: Option<f64>,
    /// Rolling element radius rb \[mm\]; must be below rb_overlap and rb_undercut. Required unless
    /// `sweep.rb_mm` is given.
    #[rule(range = RB_MM)]
    #[schema(example = 2.0)]
    pub rb_mm: Option<f64>,
    /// Output torque T_out [N·m].
    #[serde(rename = "torque_Nm")]
    #[rule(range = TORQUE_NM)]
    #[schema(example = 119.366207)]
    pub torque_nm: f64,
    /// Output link: "cam" (crown fixed, default) or "crown" (cam rotation locked).
    #[schema(nullable = false)]
    pub output_link: Option<OutputLink>,
    /// Contact (roller) length lb \[mm\]; default 2·rb ("equal to the diameter"). 0 < lb ≤ 100·r2.
    #[rule(range = LB_MM)]
    #[schema(example = 4.0)]
    pub lb_mm: Option<f64>,
    /// Cam and crown material; default steel {210000, 0.3}.
    #[schema(nullable = false)]
    pub wheel_material: Option<Material>,
    /// Rolling element material; default steel {210000, 0.3}.
    #[schema(nullable = false)]
    pub roller_material: Option<Material>,
    /// φ2 grid step over [0°, 180°] \[deg\]; 0 < step ≤ 10 and 180/step ≤ 2·10⁶ (a finer step than
    /// 9e-5 is `GRID_TOO_FINE`). Default 1 with refine (see the module docs; the paper used 0.02
    /// without refinement).
    #[rule(range = STEP_DEG_BUILDABLE)]
    #[schema(example = 1.0)]
    pub step_deg: Option<f64>,
    /// Polish each grid maximum with a bounded Brent search to |Δφ2| ≤ 1e-10 rad (default true).
    pub refine: Option<bool>,
    /// "paper_phase0" (default, the paper) or "phase_exact". With "phase_exact" and refine the maximum
    /// search scans at least 8 points per 180/Z2 deg (the load-sharing breakpoints; warning `GRID_REFINED`)
    /// and refines each smooth piece, because σ then has several bumps.
    #[schema(nullable = false)]
    pub load_sharing: Option<LoadSharing>,
    /// Optional outputs.
    #[schema(nullable = false)]
    pub include: Option<StressInclude>,
    /// Keep every n-th grid point in `curves` (the last point is always kept; default 1).
    #[rule(range = CURVES_STRIDE)]
    #[schema(example = 1)]
    pub curves_stride: Option<u32>,
    /// Points per wheel in `geometry.profiles` (default 720).
    #[rule(range = PROFILE_POINTS)]
    #[schema(example = 720)]
    pub profile_points: Option<u32>,
    /// The structured array (mode "sweep").
    #[schema(nullable = false)]
    pub sweep: Option<SweepSpec>,
    /// Compute only block `index` of `count` near-equal contiguous blocks of the combinations
    /// (mode "sweep" only): the answers of shards 0..count, merged as `shard` in the answer
    /// says, equal the unsharded answer.
    #[schema(nullable = false)]
    pub shard: Option<Shard>,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false, example = 2000)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for IrefcStressRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// One element of the phase-0 set (force paper "temporary array").
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::ElementOut)]
pub struct ElementOut {
    /// Element index k (φ2 = 360k/Z2).
    pub k: u32,
    /// Element angle φ2 \[deg\].
    pub phi2_deg: f64,
    /// True contact angle α \[deg\].
    pub alpha_deg: f64,
    /// Cam lever arm h = r1·sin α \[mm\] (eq. 13).
    pub h_mm: f64,
    /// Element force F_k = Fmax·sin α \[N\] (eq. 16).
    #[serde(rename = "F_N")]
    pub f_n: f64,
}

/// The maximum contact stress of one wheel and the state there (spec step 7).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::WheelMax)]
pub struct WheelMax {
    /// Element angle of the maximum \[deg\]; null when the torque is zero (no argmax).
    pub phi2_deg: Option<f64>,
    /// Hertz peak contact pressure σ_H \[MPa\].
    #[serde(rename = "sigma_MPa")]
    pub sigma_mpa: f64,
    /// Element force there \[N\].
    #[serde(rename = "F_N")]
    pub f_n: f64,
    /// Lever arm of this wheel, r_w·sin α (r1 for the cam, r3 for the crown) \[mm\].
    pub h_mm: Option<f64>,
    /// True contact angle α \[deg\].
    pub alpha_deg: Option<f64>,
    /// Pitch point to element centre distance L \[mm\].
    #[serde(rename = "L_mm")]
    pub l_mm: Option<f64>,
    /// Signed profile radius ρ_w (negative = concave) \[mm\]; null at an inflection or zero torque.
    pub rho_mm: Option<f64>,
    /// Contact half-width b = sqrt(4F/(π·lb·E*·K)) \[mm\].
    pub b_mm: f64,
    /// Subsurface maximum shear stress 0.300·σ \[MPa\] (only with `include.subsurface`).
    #[serde(rename = "tau_max_MPa", skip_serializing_if = "Option::is_none")]
    pub tau_max_mpa: Option<f64>,
    /// Depth of τ_max below the surface, 0.786·b \[mm\] (only with `include.subsurface`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau_depth_mm: Option<f64>,
}

/// Maxima of both wheels.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::MaxOut)]
pub struct MaxOut {
    /// Cam contact (point A).
    pub cam: WheelMax,
    /// Crown contact (point B).
    pub crown: WheelMax,
    /// Wheel with the larger maximum, "cam" or "crown"; null when the torque is zero.
    pub overall: Option<String>,
}

/// Curves over the φ2 grid (`include.curves`), thinned by `curves_stride`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::Curves)]
pub struct Curves {
    /// Element angle φ2 \[deg\].
    pub phi2_deg: Vec<f64>,
    /// Element force F(φ2) \[N\].
    #[serde(rename = "F_N")]
    pub f_n: Vec<f64>,
    /// Cam contact stress \[MPa\].
    #[serde(rename = "sigma_cam_MPa")]
    pub sigma_cam_mpa: Vec<f64>,
    /// Crown contact stress \[MPa\].
    #[serde(rename = "sigma_crown_MPa")]
    pub sigma_crown_mpa: Vec<f64>,
    /// Signed cam profile radius \[mm\] (null at an inflection).
    pub rho_cam_mm: Vec<Option<f64>>,
    /// Signed crown profile radius \[mm\] (null at an inflection).
    pub rho_crown_mm: Vec<Option<f64>>,
}

/// Settings and cost of a single-design computation.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::StressMeta)]
pub struct StressMeta {
    /// Requested grid step \[deg\] (the grid uses 180/n_intervals, n_intervals = round(180/step)).
    pub step_deg: f64,
    /// Whether maxima were refined.
    pub refine: bool,
    /// Load-sharing mode.
    pub load_sharing: LoadSharing,
    /// Grid points scanned, N + 1 (with "phase_exact" + refine at least 4·Z2 + 1, see warning
    /// `GRID_REFINED`; curves always use the requested step).
    pub n_grid: u64,
    /// Stress evaluations (grid + refinement).
    pub evaluations: u64,
    /// Wall-clock compute time \[ms\].
    pub compute_ms: f64,
}

/// Response of mode "single".
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::StressSingleResponse)]
pub struct StressSingleResponse {
    /// Always "single".
    pub mode: StressMode,
    /// Derived geometry.
    pub geometry: GeometryOut,
    /// Cam torque T_cam [N·m].
    #[serde(rename = "T_cam_Nm")]
    pub t_cam_nm: f64,
    /// Crown torque T_crown = T_cam·r3/r1 [N·m].
    #[serde(rename = "T_crown_Nm")]
    pub t_crown_nm: f64,
    /// Lossless carrier (input) torque T_cam·2/(Z2−1) [N·m].
    #[serde(rename = "T_in_Nm")]
    pub t_in_nm: f64,
    /// Contact modulus E* = 1/((1−ν_w²)/E_w + (1−ν_r²)/E_r) \[MPa\].
    #[serde(rename = "E_star_MPa")]
    pub e_star_mpa: f64,
    /// Contact length used \[mm\].
    pub lb_mm: f64,
    /// Force an element would carry at α = 90°, T_cam/(r1·Σsin²α) \[N\] (eq. 17).
    #[serde(rename = "Fmax_N")]
    pub fmax_n: f64,
    /// Σh² = r1²·Σsin²α over the phase-0 set \[mm²\].
    pub sum_h2_mm2: f64,
    /// Phase-0 element table (`include.elements`, default on).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<Vec<ElementOut>>,
    /// Maximum contact stresses.
    pub max: MaxOut,
    /// Curves (`include.curves`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub curves: Option<Curves>,
    /// Warnings (geometry and request).
    pub warnings: Vec<Warning>,
    /// Settings and cost.
    pub meta: StressMeta,
}

/// Why a sweep combination has no result.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::Reason)]
pub struct Reason {
    /// `UNDERCUT`, `ELEMENT_OVERLAP`, `NON_FINITE`, or `NOT_EVALUATED` (budget ran out first).
    pub code: String,
    /// Values and the broken limit.
    pub message: String,
}

/// One combination of the sweep (spec "Sweep" record).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::SweepRecord)]
pub struct SweepRecord {
    /// Number of rolling elements.
    #[serde(rename = "Z2")]
    pub z2: u32,
    /// Displacement coefficient.
    pub chi: f64,
    /// Rolling element radius \[mm\].
    pub rb_mm: f64,
    /// Cage pitch radius \[mm\].
    pub r2_mm: f64,
    /// Whether the design is feasible and was computed.
    pub valid: bool,
    /// Why not, when `valid` is false.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub reason: Option<Reason>,
    /// Fmax \[N\].
    #[serde(rename = "Fmax_N", skip_serializing_if = "Option::is_none")]
    pub fmax_n: Option<f64>,
    /// Cam maximum contact stress \[MPa\].
    #[serde(rename = "sigma_cam_max_MPa", skip_serializing_if = "Option::is_none")]
    pub sigma_cam_max_mpa: Option<f64>,
    /// φ2 of the cam maximum \[deg\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phi2_cam_deg: Option<f64>,
    /// Crown maximum contact stress \[MPa\].
    #[serde(
        rename = "sigma_crown_max_MPa",
        skip_serializing_if = "Option::is_none"
    )]
    pub sigma_crown_max_mpa: Option<f64>,
    /// φ2 of the crown maximum \[deg\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phi2_crown_deg: Option<f64>,
    /// Larger of both maxima \[MPa\].
    #[serde(rename = "sigma_max_MPa", skip_serializing_if = "Option::is_none")]
    pub sigma_max_mpa: Option<f64>,
    /// "cam" or "crown".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub governing: Option<String>,
    /// Element force at the governing maximum \[N\].
    #[serde(rename = "F_at_max_N", skip_serializing_if = "Option::is_none")]
    pub f_at_max_n: Option<f64>,
    /// Signed profile radius at the governing maximum \[mm\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rho_at_max_mm: Option<f64>,
    /// Sharpest convex profile radius of either wheel \[mm\] (negative past the undercut limit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_profile_radius_mm: Option<f64>,
    /// Geometry warning codes of this combination (omitted when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// Settings and cost of a sweep.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::SweepMeta)]
pub struct SweepMeta {
    /// Requested grid step \[deg\].
    pub step_deg: f64,
    /// Whether maxima were refined.
    pub refine: bool,
    /// Load-sharing mode.
    pub load_sharing: LoadSharing,
    /// Grid points per combination as requested (with "phase_exact" + refine each combination scans at
    /// least 4·Z2 + 1 points).
    pub n_grid: u64,
    /// Combinations in this answer (the whole sweep, or the shard's block).
    pub n_combinations: u64,
    /// Worker threads used.
    pub threads: u32,
    /// Wall-clock compute time \[ms\].
    pub compute_ms: f64,
    /// How the sweep stopped (`completed`, or `deadline`/`max_evaluations` with unevaluated records);
    /// iterations = evaluations = combinations evaluated.
    pub solver: SolverReport,
}

/// Response of mode "sweep".
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::StressSweepResponse)]
pub struct StressSweepResponse {
    /// Always "sweep".
    pub mode: StressMode,
    /// One record per combination, ordered by Z2, then χ, then rb, then r2 (with `shard`: the
    /// combinations `shard.start..shard.end` of that order).
    pub records: Vec<SweepRecord>,
    /// Index of the valid record with the largest sigma_max (null if none is valid); the first
    /// such record on ties. With `shard` a global index (counted from the start of the whole
    /// sweep); merged: the shards' `worst` with the largest `sigma_max_MPa`, the lowest index
    /// on ties.
    pub worst: Option<usize>,
    /// Index of the valid record with the smallest sigma_max (null if none is valid); the first
    /// such record on ties. With `shard` a global index; merged: the shards' `best` with the
    /// smallest `sigma_max_MPa`, the lowest index on ties.
    pub best: Option<usize>,
    /// Which block of the sweep this answer holds (only when the request gave `shard`).
    /// Merged: records concatenated in shard order; `n_valid`, `n_invalid`, `n_not_evaluated`
    /// and `meta.n_combinations` added; `best`/`worst` as stated there.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub shard: Option<Box<ShardOut>>,
    /// Valid records.
    pub n_valid: u64,
    /// Invalid records (infeasible, non-finite or not evaluated).
    pub n_invalid: u64,
    /// Records not evaluated because the budget ran out (included in n_invalid).
    pub n_not_evaluated: u64,
    /// Request-level warnings.
    pub warnings: Vec<Warning>,
    /// Settings and cost.
    pub meta: SweepMeta,
}

/// Response of `POST /v1/irefc-stress`: one of the two shapes, by `mode`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::stress::IrefcStressResponse)]
#[serde(untagged)]
pub enum IrefcStressResponse {
    /// Mode "single".
    Single(Box<StressSingleResponse>),
    /// Mode "sweep".
    Sweep(StressSweepResponse),
}

/// Output torque T_out [N·m]: 0 ≤ T ≤ 1e7 (spec).
pub const TORQUE_NM: Range = Range::closed(0.0, 1e7);
/// lb may be at most this multiple of r2 (spec).
pub const LB_MAX_OVER_R2: f64 = 100.0;
/// Contact length lb \[mm\]: > 0; the upper end [`LB_MAX_OVER_R2`]·r2 depends on r2 (a cross-field
/// rule, stated in the field's doc).
pub const LB_MM: Range = Range::FINITE.gt(0.0);
/// Largest number of φ2 grid intervals 180/step (spec: 180/step ≤ 2·10⁶).
pub const GRID_INTERVALS_MAX: f64 = 2e6;
/// Grid steps a φ2 grid can be built from \[deg\]: 0 < step ≤ 10 (spec; `BAD_RANGE` outside).
pub const STEP_DEG_BUILDABLE: Range = Range::FINITE.gt(0.0).max(10.0);
/// The φ2 grid steps within the size limit \[deg\]: 180/step ≤ 2·10⁶ (step ≥ 9e-5) and step ≤ 10.
/// The per-field rule is [`STEP_DEG_BUILDABLE`] (`BAD_RANGE`); a positive step below this range's
/// lower end is `GRID_TOO_FINE` (a size limit, a rule of the operation). (Division is correctly rounded and monotone, so `step ≥ 180/2e6` is exactly
/// `180/step ≤ 2e6`.)
pub const STEP_DEG: Range = STEP_DEG_BUILDABLE.min(180.0 / GRID_INTERVALS_MAX);
/// Sweep χ step [–]: > 0.
pub const CHI_STEP: Range = Range::FINITE.gt(0.0);
/// Stride of the curve points [–]: ≥ 1.
pub const CURVES_STRIDE: Range = Range::INTEGER.min(1.0);
/// Profile points per wheel [–].
pub const PROFILE_POINTS: Range = Range::int(PROFILE_POINTS_MIN as i64, PROFILE_POINTS_MAX as i64);
