//! Wire types of `POST /v1/spatial-coupling` (spec §2, §5, §9) and the module's bounds.
//!
//! Angles are in degrees, rates in rad/s, lengths in metres. Ground frame Oxyz: Ox along the common
//! normal of the two shafts, O its midpoint, Oxz bisecting the shaft directions; shaft 1 at
//! A1 = (a, 0, 0), shaft 2 at A2 = (−a, 0, 0) (spec §3.1).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::calc::common::{Sign, Warning};
use crate::numerics::SolverReport;

/// A vector `[x, y, z]`.
pub type Vec3 = [f64; 3];
/// A 4×4 homogeneous transform, row by row.
pub type Mat4 = [[f64; 4]; 4];

// ---------------------------------------------------------------------------------------------
// Request
// ---------------------------------------------------------------------------------------------

/// Request of `POST /v1/spatial-coupling`: the coupling (α, a, β), the input speed, the assembly
/// mode, and where to evaluate it: single input angles (`theta1_deg`), a uniform `sweep`, or both.
/// Without either, the default sweep (0°…360°, 721 points) is evaluated.
#[derive(
    Debug, Clone, Default, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = spatial_coupling::SpatialCouplingRequest)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "alpha_deg": 15, "a_m": 1.0, "beta_deg": 15, "omega1_rad_s": 1.0, "branch": 1,
    "theta1_deg": [30],
    "sweep": {"start_deg": 0, "end_deg": 360, "n_points": 721},
    "outputs": {"contact": true, "relative_1": true, "relative_2": true, "summary": true, "check": true}
}))]
pub struct SpatialCouplingRequest {
    /// Half-angle parameter α \[deg\]: the shaft axes make 180° − 2α (misalignment from collinear
    /// 2α). |cos 2α| ≥ 1e-9 (α = ±45°, perpendicular shafts, is a dead-point configuration and
    /// is rejected); |cos 2α| < 0.1 answers with a warning. Default 15.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = ALPHA_DEG)]
    #[schema(nullable = false, example = 15.0)]
    pub alpha_deg: Option<f64>,
    /// Half of the common-normal length `a` \[m\] (A1 = (a, 0, 0), A2 = (−a, 0, 0)). Default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = A_M)]
    #[schema(nullable = false, example = 1.0)]
    pub a_m: Option<f64>,
    /// Orientation β of the support plane P0 \[deg\] (P0 contains Ox; normal (0, −cos β, sin β)).
    /// β = α puts P0 perpendicular to the input shaft (the paper's design). Default: `alpha_deg`.
    /// Requests with a `sweep` need cos(α−β)·cos 2α·cos(α+β) > 0 (contact point finite at every
    /// θ1, spec §7.2); points-only requests answer per point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = BETA_DEG)]
    #[schema(nullable = false, example = 15.0)]
    pub beta_deg: Option<f64>,
    /// Input angular speed ω1 [rad/s] (constant). Default 1: rates are then reduced values
    /// (ω/ω1, v/ω1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = OMEGA1)]
    #[schema(nullable = false, example = 1.0)]
    pub omega1_rad_s: Option<f64>,
    /// Assembly mode σ: 1 (θ2 = 90° at θ1 = 0) or -1 (θ2 = 270° at θ1 = 0). Default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub branch: Option<Sign>,
    /// Input angles θ1 \[deg\] evaluated one by one (any finite value; reduced modulo 360°).
    /// At most 100 000.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(items = THETA1_DEG, max_items = MAX_THETA1_POINTS)]
    #[schema(nullable = false, example = json!([30.0]))]
    pub theta1_deg: Option<Vec<f64>>,
    /// Uniform sweep of θ1 with unwrapped output angles and summaries.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub sweep: Option<SweepIn>,
    /// Points fixed in body 3, in frame-3 coordinates \[m\], whose paths and velocities are
    /// returned at every point (`body3_points` of each point). At most 100.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(items_items = BODY3_COORD_M, max_items = MAX_BODY3_POINTS)]
    #[schema(nullable = false, value_type = Vec<[f64; 3]>)]
    pub body3_points_m: Option<Vec<[f64; 3]>>,
    /// Optional output groups (spec §5); each costs O(1) per point.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub outputs: OutputsIn,
    /// Wall-clock limit for this request \[ms\] (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false, example = 2000)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for SpatialCouplingRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// A uniform sweep θ1 = start + k·(end − start)/(n − 1), k = 0…n − 1 (both ends included).
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = spatial_coupling::SweepIn)]
#[serde(deny_unknown_fields)]
pub struct SweepIn {
    /// First input angle \[deg\]. Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = THETA1_DEG)]
    #[schema(nullable = false, example = 0.0)]
    pub start_deg: Option<f64>,
    /// Last input angle \[deg\] (may be below `start_deg`: a reversed sweep). Default 360.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = THETA1_DEG)]
    #[schema(nullable = false, example = 360.0)]
    pub end_deg: Option<f64>,
    /// Number of points n. Default 721.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = N_POINTS)]
    #[schema(nullable = false, example = 721)]
    pub n_points: Option<u64>,
}

/// Output groups (spec §5). The core (θ2, i12, di12/dθ1, ω2, ε2) is always returned.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = spatial_coupling::OutputsIn)]
#[serde(deny_unknown_fields, default)]
pub struct OutputsIn {
    /// Contact point B: position, velocity, speed and the denominator D. Default false.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub contact: bool,
    /// Motion of B and rotation of body 3 relative to shaft 1. Default false.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub relative_1: bool,
    /// Motion of B and rotation of body 3 relative to shaft 2. Default false.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub relative_2: bool,
    /// Unit vectors of frames 1, 2, 3 and the transforms T13, T23. Default false.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub frames: bool,
    /// Sweep summary (spec §3.5). Default true (ignored without a sweep).
    #[serde(deserialize_with = "crate::calc::rules::null_true")]
    pub summary: bool,
    /// Every (kept) sweep point in `series`. Default false: a sweep answers with its summary only.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub series: bool,
    /// Keep every `decimate`-th sweep point in `series` (the last point is always kept; the
    /// summary always uses every point). Default 1.
    #[serde(deserialize_with = "decimate_or_default")]
    #[rule(range = DECIMATE)]
    #[schema(example = 1)]
    pub decimate: u64,
    /// Closure residuals and orthonormality of frame 3 per point (debug). Default false.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub check: bool,
}

/// `outputs.decimate`: `null` reads as the default 1, exactly as when absent.
fn decimate_or_default<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    Ok(Option::<u64>::deserialize(d)?.unwrap_or(1))
}

impl Default for OutputsIn {
    fn default() -> Self {
        Self {
            contact: false,
            relative_1: false,
            relative_2: false,
            frames: false,
            summary: true,
            series: false,
            decimate: 1,
            check: false,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Response
// ---------------------------------------------------------------------------------------------

/// Answer of `POST /v1/spatial-coupling`.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = spatial_coupling::SpatialCouplingResponse)]
pub struct SpatialCouplingResponse {
    /// Properties of the configuration over a whole revolution (closed form, no sampling).
    pub configuration: Configuration,
    /// One entry per `theta1_deg`, in order: a point, or an error object where the contact point
    /// is at infinity (D = 0 to round-off; only when the support plane fails the validity test).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub points: Option<Vec<PointEntry>>,
    /// Summary of the sweep (spec §3.5; when a sweep ran and `outputs.summary`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub summary: Option<Summary>,
    /// The sweep's points, angles unwrapped along the sweep (first value in [0°, 360°)); when
    /// `outputs.series`, every `outputs.decimate`-th point.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub series: Option<Vec<Point>>,
    /// Ill-conditioned or special configurations (codes `NEAR_PERPENDICULAR_SHAFTS`,
    /// `CONTACT_ILL_CONDITIONED`, `CONTACT_POINT_FAR`, `SUPPORT_PLANE_INVALID`, `LARGE_ANGLE`).
    pub warnings: Vec<Warning>,
    /// How the evaluation stopped and what it cost (points evaluated).
    pub report: SolverReport,
}

/// The configuration's Cardan equivalence and support-plane validity (spec §3.2, §7.2).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Configuration)]
pub struct Configuration {
    /// Bend angle of the equivalent Hooke (Cardan) joint, 2α \[deg\]; its input angle is 90° − θ1.
    pub cardan_bend_angle_deg: f64,
    /// Whether the coupling is homokinetic (|1 − |cos 2α|| < 1e-12; only α = 0 in the valid range
    /// of perpendicular-free shafts, or α → ±90°).
    pub homokinetic: bool,
    /// Range of |i12| over a revolution, [|cos 2α|, 1/|cos 2α|].
    #[schema(value_type = [f64; 2])]
    pub ratio_range_abs: [f64; 2],
    /// Speed fluctuation |i12|max − |i12|min over a revolution = |sin 2α · tan 2α|.
    pub fluctuation: f64,
    /// Mean of i12 over a revolution (−1 for |α| < 45°, +1 for |α| > 45°): one output turn per
    /// input turn.
    pub i12_mean: f64,
    /// Support plane P0: the validity test and the conditioning of the contact point.
    pub support_plane: SupportPlane,
}

/// Support-plane validity (spec §7.2): D(θ1) = D(0)·cos²θ1 + D(90°)·sin²θ1.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::SupportPlane)]
pub struct SupportPlane {
    /// Whether the contact point B is finite at every θ1: cos(α−β)·cos 2α·cos(α+β) > 0.
    pub valid: bool,
    /// D(0) = cos(α−β)·cos 2α.
    pub d_at_0: f64,
    /// D(90°) = cos(α+β).
    pub d_at_90: f64,
    /// min|D| / max|D| over a revolution (0 for an invalid plane; warning below 1e-3).
    pub d_min_over_max: f64,
    /// Input angles in [0°, 360°) where D = 0 (B at infinity), for an invalid plane.
    pub d_roots_theta1_deg: Vec<f64>,
}

/// One entry of `points`: a point, or the error object of a point where B is at infinity.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::PointEntry)]
#[serde(untagged)]
pub enum PointEntry {
    /// The kinematics at this input angle.
    Point(Box<Point>),
    /// No finite contact point at this input angle.
    Error(PointFailure),
}

/// `{"error": {...}}` in place of a point (spec §7.2).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::PointFailure)]
pub struct PointFailure {
    /// What went wrong at this point.
    pub error: PointError,
}

/// The error of one point.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::PointError)]
pub struct PointError {
    /// Stable code: `CONTACT_AT_INFINITY`.
    pub code: String,
    /// Explanation naming the input angle and D.
    pub message: String,
    /// The input angle of this point \[deg\], as requested.
    pub theta1_deg: f64,
}

/// The kinematics at one input angle (spec §5).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Point)]
pub struct Point {
    /// Input angle θ1 \[deg\] (as requested, or the sweep's value).
    pub theta1_deg: f64,
    /// Output angle θ2 \[deg\]: in [0°, 360°) for single points, unwrapped along a sweep.
    pub theta2_deg: f64,
    /// Transmission ratio i12 = dθ2/dθ1 = ω2/ω1 (negative for |α| < 45°: the output turns in −z2).
    pub i12: f64,
    /// di12/dθ1 [1/rad].
    pub di12_dtheta1: f64,
    /// Output angular speed ω2 = i12·ω1 [rad/s].
    pub omega2_rad_s: f64,
    /// Output angular acceleration ε2 = (di12/dθ1)·ω1² [rad/s²] (ω1 constant).
    pub epsilon2_rad_s2: f64,
    /// Contact point B (`outputs.contact`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub contact: Option<Contact>,
    /// Motion relative to shaft 1 (`outputs.relative_1`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub relative_1: Option<Relative1>,
    /// Motion relative to shaft 2 (`outputs.relative_2`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub relative_2: Option<Relative2>,
    /// Frames (`outputs.frames`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub frames: Option<Frames>,
    /// Paths of the requested body-3 points (when `body3_points_m` is not empty).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub body3_points: Option<Vec<Body3Point>>,
    /// Closure residuals (`outputs.check`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub check: Option<Check>,
}

/// Contact point B, the centre of the sphere of body 3 on the support plane (spec §3.3).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Contact)]
#[expect(
    non_snake_case,
    reason = "the spec's wire names rB_m, vB_m_s, vB_mag, D"
)]
pub struct Contact {
    /// Position r_B in the ground frame \[m\].
    #[schema(value_type = [f64; 3])]
    pub rB_m: Vec3,
    /// Velocity v_B in the ground frame [m/s].
    #[schema(value_type = [f64; 3])]
    pub vB_m_s: Vec3,
    /// Speed |v_B| [m/s].
    pub vB_mag: f64,
    /// Denominator D(θ1) = cos(α−β)·cos 2α·cos²θ1 + cos(α+β)·sin²θ1 of r_B = −a·N/D.
    pub D: f64,
}

/// Motion relative to shaft 1 (frame 1; y1B ≡ 0), spec §3.4.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Relative1)]
#[expect(non_snake_case, reason = "the spec's wire names x1B_m, …")]
pub struct Relative1 {
    /// x of B in frame 1 \[m\].
    pub x1B_m: f64,
    /// z of B in frame 1 \[m\] (0 for β = α).
    pub z1B_m: f64,
    /// dx1B/dt [m/s].
    pub vx1B_m_s: f64,
    /// dz1B/dt [m/s].
    pub vz1B_m_s: f64,
    /// Rotation θ31 of body 3 relative to shaft 1 about i3 ≡ j1 \[deg\] ([0°, 360°) for single
    /// points, unwrapped along a sweep).
    pub theta31_deg: f64,
    /// ω31 = dθ31/dt [rad/s].
    pub omega31_rad_s: f64,
}

/// Motion relative to shaft 2 (frame 2; y2B ≡ 0), spec §3.4.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Relative2)]
#[expect(non_snake_case, reason = "the spec's wire names x2B_m, …")]
pub struct Relative2 {
    /// x of B in frame 2 \[m\].
    pub x2B_m: f64,
    /// z of B in frame 2 \[m\].
    pub z2B_m: f64,
    /// dx2B/dt [m/s].
    pub vx2B_m_s: f64,
    /// dz2B/dt [m/s].
    pub vz2B_m_s: f64,
    /// Rotation θ32 of body 3 relative to shaft 2 about j3 ≡ j2 \[deg\] ([0°, 360°) for single
    /// points, unwrapped along a sweep).
    pub theta32_deg: f64,
    /// ω32 = dθ32/dt = −σ·ω1·sin2α·sin θ1/√(sin²θ1 + cos²2α·cos²θ1) [rad/s] (flips with σ
    /// because j2 does; the vector ω32·j2 is the same in both assembly modes).
    pub omega32_rad_s: f64,
}

/// Unit vectors in ground coordinates and the body-3 transforms (spec §3.1, §3.4).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Frames)]
#[expect(non_snake_case, reason = "the spec's wire names T13, T23")]
pub struct Frames {
    /// i1.
    #[schema(value_type = [f64; 3])]
    pub i1: Vec3,
    /// j1 (normal of plane P1).
    #[schema(value_type = [f64; 3])]
    pub j1: Vec3,
    /// k1 (shaft-1 axis).
    #[schema(value_type = [f64; 3])]
    pub k1: Vec3,
    /// i2.
    #[schema(value_type = [f64; 3])]
    pub i2: Vec3,
    /// j2 (normal of plane P2).
    #[schema(value_type = [f64; 3])]
    pub j2: Vec3,
    /// k2 (shaft-2 axis).
    #[schema(value_type = [f64; 3])]
    pub k2: Vec3,
    /// i3 = j1.
    #[schema(value_type = [f64; 3])]
    pub i3: Vec3,
    /// j3 = j2.
    #[schema(value_type = [f64; 3])]
    pub j3: Vec3,
    /// k3 = i3 × j3.
    #[schema(value_type = [f64; 3])]
    pub k3: Vec3,
    /// Pose of body 3 in frame 1 (translation in m), rows.
    #[schema(value_type = Vec<[f64; 4]>)]
    pub T13: Mat4,
    /// Pose of body 3 in frame 2 (translation in m), rows.
    #[schema(value_type = Vec<[f64; 4]>)]
    pub T23: Mat4,
}

/// A point M of body 3 at one input angle.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Body3Point)]
pub struct Body3Point {
    /// Position in the ground frame \[m\].
    #[schema(value_type = [f64; 3])]
    pub r0_m: Vec3,
    /// Position in frame 1 \[m\].
    #[schema(value_type = [f64; 3])]
    pub r1_m: Vec3,
    /// Position in frame 2 \[m\].
    #[schema(value_type = [f64; 3])]
    pub r2_m: Vec3,
    /// Absolute velocity, ground frame [m/s].
    #[schema(value_type = [f64; 3])]
    pub v0_m_s: Vec3,
    /// Velocity relative to shaft 1, frame-1 coordinates [m/s].
    #[schema(value_type = [f64; 3])]
    pub v1_m_s: Vec3,
    /// Velocity relative to shaft 2, frame-2 coordinates [m/s].
    #[schema(value_type = [f64; 3])]
    pub v2_m_s: Vec3,
}

/// Closure residuals of the returned configuration (spec §5 `check`).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Check)]
pub struct Check {
    /// Largest of `closure` and `orthonormality`.
    pub max_residual: f64,
    /// |(rB − A1)·j1|, |(rB − A2)·j2|, |n0·rB| (each over max(a, |rB|)) and |n1·n2|.
    #[schema(value_type = [f64; 4])]
    pub closure: [f64; 4],
    /// Largest |[i3 j3 k3]ᵀ[i3 j3 k3] − I| entry.
    pub orthonormality: f64,
}

/// Summary of a sweep (spec §3.5): extremes over the swept points.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::Summary)]
#[expect(
    non_snake_case,
    reason = "the spec's wire names rB_radius_range_m, vB_range_m_s, D_min_over_max"
)]
pub struct Summary {
    /// Points evaluated.
    pub n_points: u64,
    /// Whether the coupling is homokinetic (|1 − |cos 2α|| < 1e-12).
    pub homokinetic: bool,
    /// Smallest i12.
    pub i12_min: f64,
    /// Largest i12.
    pub i12_max: f64,
    /// [min, max] of |i12|.
    #[schema(value_type = [f64; 2])]
    pub ratio_range_abs: [f64; 2],
    /// |i12|max − |i12|min.
    pub fluctuation: f64,
    /// (max − min)/2 of the unwrapped θ31 \[deg\] (2|α| over a revolution for |α| < 45°).
    pub theta31_amplitude_deg: f64,
    /// (max − min)/2 of the unwrapped θ32 \[deg\].
    pub theta32_amplitude_deg: f64,
    /// [min, max] of |rB| \[m\].
    #[schema(value_type = [f64; 2])]
    pub rB_radius_range_m: [f64; 2],
    /// [min, max] of |vB| [m/s].
    #[schema(value_type = [f64; 2])]
    pub vB_range_m_s: [f64; 2],
    /// Bounding box of the path of B in frame 2 (x2B, z2B) \[m\].
    pub lemniscate_box_m: LemniscateBox,
    /// max |ω31| [rad/s].
    pub omega31_max_abs: f64,
    /// max |ω32| [rad/s].
    pub omega32_max_abs: f64,
    /// min|D| / max|D| over the swept points.
    pub D_min_over_max: f64,
}

/// An axis-aligned box in the (x2, z2) plane of frame 2 \[m\].
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = spatial_coupling::LemniscateBox)]
pub struct LemniscateBox {
    /// [min, max] of x2B \[m\].
    #[schema(value_type = [f64; 2])]
    pub x: [f64; 2],
    /// [min, max] of z2B \[m\].
    #[schema(value_type = [f64; 2])]
    pub z: [f64; 2],
}

// ---------------------------------------------------------------------------------------------
// Bounds
// ---------------------------------------------------------------------------------------------

/// α \[deg\]: open interval (−90°, 90°); |cos 2α| ≥ [`MIN_ABS_COS_2ALPHA`] is a separate rule.
pub const ALPHA_DEG: Range = Range::FINITE.gt(-90.0).lt(90.0);
/// β \[deg\]: (−90°, 90°] (spec §2); the plane-validity test is a separate rule.
pub const BETA_DEG: Range = Range::FINITE.gt(-90.0).max(90.0);
/// Largest half common-normal length \[m\]: with |ω1| ≤ [`MAX_OMEGA1`] every returned length,
/// speed and acceleration stays far inside f64 even at the conditioning limits of §7.
pub const MAX_LENGTH_M: f64 = 1e6;
/// a \[m\]: positive, at most [`MAX_LENGTH_M`].
pub const A_M: Range = Range::FINITE.gt(0.0).max(MAX_LENGTH_M);
/// Largest |ω1| [rad/s] (1e6 rad/s ≈ 1e7 rpm, far beyond any machine).
pub const MAX_OMEGA1: f64 = 1e6;
/// ω1 [rad/s].
pub const OMEGA1: Range = Range::closed(-MAX_OMEGA1, MAX_OMEGA1);
/// θ1 \[deg\]: any finite angle (reduced modulo 360°).
pub const THETA1_DEG: Range = Range::FINITE;
/// Sweep points n (spec §2: 2 … 10⁶).
pub const N_POINTS: Range = Range::int(2, 1_000_000);
/// `decimate`: 1 … 10⁶.
pub const DECIMATE: Range = Range::int(1, 1_000_000);
/// Body-3 point coordinates \[m\].
pub const BODY3_COORD_M: Range = Range::closed(-MAX_LENGTH_M, MAX_LENGTH_M);
/// |cos 2α| below this is rejected (spec §2, §7.1: perpendicular shafts, dead points).
pub const MIN_ABS_COS_2ALPHA: f64 = 1e-9;
/// Most `theta1_deg` values per request.
pub const MAX_THETA1_POINTS: usize = 100_000;
/// Most body-3 points per request (spec §2).
pub const MAX_BODY3_POINTS: usize = 100;
