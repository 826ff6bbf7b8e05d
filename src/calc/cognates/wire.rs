//! Wire types of `POST /v1/cognates` (spec `cognates.md` §3, §5, §9: the JSON example is the
//! contract). Lengths are in the caller's unit (any consistent unit; the paper uses cm) and are
//! returned in the same unit; angles are in degrees.

use crate::calc::Range;
use crate::calc::common::Sign;
use crate::numerics::SolverReport;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// A point `[x, y]` in the caller's length unit.
pub type Point = [f64; 2];

// ---------------------------------------------------------------------------------------------
// Request
// ---------------------------------------------------------------------------------------------

/// Request of `POST /v1/cognates`: a four-bar with a coupler point, either by dimensions
/// (`ground`, `crank`, `coupler`, `rocker`, `coupler_point`) or by one drawn configuration
/// (`joints`), plus an optional snapshot input angle and the optional outputs in `options`.
#[derive(
    Debug, Clone, Default, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cognates::CognatesRequest)]
#[serde(deny_unknown_fields)]
pub struct CognatesRequest {
    /// Ground pivots: `{A, B}` or `{A, length, angle_deg}` (dimension mode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub ground: Option<GroundSpec>,
    /// Crank (input link) length `a` \[length\], > 0 and ≥ 1e-12·L, L the largest length of the
    /// linkage (dimension mode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = LENGTH, code = "NON_POSITIVE_LENGTH")]
    #[schema(nullable = false, example = 1.13)]
    pub crank: Option<f64>,
    /// Coupler length `b` = |E − D| \[length\], > 0 and ≥ 1e-12·L, L the largest length of the
    /// linkage (dimension mode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = LENGTH, code = "NON_POSITIVE_LENGTH")]
    #[schema(nullable = false, example = 1.23)]
    pub coupler: Option<f64>,
    /// Rocker (output link) length `c` \[length\], > 0 and ≥ 1e-12·L, L the largest length of the
    /// linkage (dimension mode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = LENGTH, code = "NON_POSITIVE_LENGTH")]
    #[schema(nullable = false, example = 1.04)]
    pub rocker: Option<f64>,
    /// Coupler point P, exactly one of three forms (dimension mode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub coupler_point: Option<CouplerPoint>,
    /// One drawn configuration (joints mode; excludes the dimension fields, `input_angle_deg` and
    /// `branch`, which are read from the joints).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub joints: Option<JointsSpec>,
    /// Input angle of the snapshot configuration \[deg\] (θ2, or φ with `angle_reference: ground`).
    /// Omit for no snapshot.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false, example = 30.0)]
    pub input_angle_deg: Option<f64>,
    /// Reference of `input_angle_deg`: `global` (from +x) or `ground` (from A→B, paper φ).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub angle_reference: AngleReference,
    /// Assembly branch `t1` of the snapshot (1: E left of the directed line D→B). Default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub branch: Option<Sign>,
    /// Optional outputs and knobs.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub options: CognatesOptions,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false, example = 2000)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for CognatesRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// Ground pivots. `A` defaults to `[0, 0]`; give either `B` or `length` (with `angle_deg`).
#[derive(
    Debug, Clone, Default, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cognates::GroundSpec)]
#[serde(deny_unknown_fields)]
pub struct GroundSpec {
    /// Input pivot A \[length\], default `[0, 0]`.
    #[serde(rename = "A", default, skip_serializing_if = "Option::is_none")]
    #[rule(items = COORDINATE)]
    #[schema(nullable = false, value_type = Option<[f64; 2]>, example = json!([0.0, 0.0]))]
    pub a: Option<[f64; 2]>,
    /// Output pivot B \[length\], ≠ A.
    #[serde(rename = "B", default, skip_serializing_if = "Option::is_none")]
    #[rule(items = COORDINATE)]
    #[schema(nullable = false, value_type = Option<[f64; 2]>, example = json!([3.1, 0.0]))]
    pub b: Option<[f64; 2]>,
    /// Ground length `l` = |B − A| \[length\], > 0 (instead of `B`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = LENGTH, code = "NON_POSITIVE_LENGTH")]
    #[schema(nullable = false)]
    pub length: Option<f64>,
    /// Direction γ of A→B when `length` is used \[deg\], default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub angle_deg: Option<f64>,
}

/// Coupler point P, rigidly attached to the coupler, in exactly one of three forms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cognates::CouplerPoint)]
#[serde(try_from = "CouplerPointRaw", untagged)]
pub enum CouplerPoint {
    /// Paper form: distances to the coupler joints and the side.
    Triangle {
        /// `d` = |P − D| \[length\], ≥ 0; (b, d, e) must close a triangle (within 1e-12·max).
        #[rule(range = NON_NEGATIVE_LENGTH, code = "NON_POSITIVE_LENGTH")]
        #[schema(example = 0.92)]
        d: f64,
        /// `e` = |P − E| \[length\], ≥ 0; (b, d, e) must close a triangle (within 1e-12·max).
        #[rule(range = NON_NEGATIVE_LENGTH, code = "NON_POSITIVE_LENGTH")]
        #[schema(example = 1.56)]
        e: f64,
        /// Coupler side `t2`: 1 when P is left of the directed line D→E. Default 1.
        #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
        side: Sign,
    },
    /// Coupler frame: origin D, x along D→E, y to the left; `k = (u + i·v)/b`.
    Frame {
        /// Coordinate along D→E \[length\].
        #[rule(range = COORDINATE)]
        u: f64,
        /// Coordinate to the left of D→E \[length\].
        #[rule(range = COORDINATE)]
        v: f64,
    },
    /// Polar form from D: `k = (p/b)·e^{i·alpha}`.
    Polar {
        /// Distance |P − D| \[length\], ≥ 0.
        #[rule(range = NON_NEGATIVE_LENGTH, code = "NON_POSITIVE_LENGTH")]
        p: f64,
        /// Angle from D→E, CCW positive \[deg\].
        alpha_deg: f64,
    },
}

/// Flat form of [`CouplerPoint`] used to decode it with a precise message when forms are mixed.
#[derive(Debug, Clone, Copy, Default, Deserialize, crate::calc::Rules)]
#[serde(deny_unknown_fields)]
struct CouplerPointRaw {
    d: Option<f64>,
    e: Option<f64>,
    side: Option<Sign>,
    u: Option<f64>,
    v: Option<f64>,
    p: Option<f64>,
    alpha_deg: Option<f64>,
}

impl TryFrom<CouplerPointRaw> for CouplerPoint {
    type Error = String;
    fn try_from(r: CouplerPointRaw) -> Result<Self, Self::Error> {
        let tri = r.d.is_some() || r.e.is_some() || r.side.is_some();
        let frame = r.u.is_some() || r.v.is_some();
        let polar = r.p.is_some() || r.alpha_deg.is_some();
        let forms = [tri, frame, polar].iter().filter(|x| **x).count();
        if forms != 1 {
            return Err(format!(
                "give exactly one coupler-point form: {{d, e, side}}, {{u, v}} or {{p, alpha_deg}} (got {forms})"
            ));
        }
        let need = |x: Option<f64>, name: &str, form: &str| {
            x.ok_or_else(|| format!("form {form} needs `{name}`"))
        };
        if tri {
            Ok(Self::Triangle {
                d: need(r.d, "d", "{d, e, side}")?,
                e: need(r.e, "e", "{d, e, side}")?,
                side: r.side.unwrap_or(Sign::Plus),
            })
        } else if frame {
            Ok(Self::Frame {
                u: need(r.u, "u", "{u, v}")?,
                v: need(r.v, "v", "{u, v}")?,
            })
        } else {
            Ok(Self::Polar {
                p: need(r.p, "p", "{p, alpha_deg}")?,
                alpha_deg: need(r.alpha_deg, "alpha_deg", "{p, alpha_deg}")?,
            })
        }
    }
}

/// One drawn configuration (joints mode).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cognates::JointsSpec)]
#[serde(deny_unknown_fields)]
pub struct JointsSpec {
    /// Input pivot A \[length\].
    #[serde(rename = "A")]
    #[rule(items = COORDINATE)]
    #[schema(value_type = [f64; 2])]
    pub a: [f64; 2],
    /// Output pivot B \[length\].
    #[serde(rename = "B")]
    #[rule(items = COORDINATE)]
    #[schema(value_type = [f64; 2])]
    pub b: [f64; 2],
    /// Crank joint D \[length\].
    #[serde(rename = "D")]
    #[rule(items = COORDINATE)]
    #[schema(value_type = [f64; 2])]
    pub d: [f64; 2],
    /// Rocker joint E \[length\].
    #[serde(rename = "E")]
    #[rule(items = COORDINATE)]
    #[schema(value_type = [f64; 2])]
    pub e: [f64; 2],
    /// Coupler point P \[length\].
    #[serde(rename = "P")]
    #[rule(items = COORDINATE)]
    #[schema(value_type = [f64; 2])]
    pub p: [f64; 2],
}

/// Reference of `input_angle_deg`.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cognates::AngleReference)]
#[serde(rename_all = "snake_case")]
pub enum AngleReference {
    /// θ2, from the +x axis.
    #[default]
    Global,
    /// φ, from the directed ground line A→B (paper convention).
    Ground,
}

/// Sample spacing on limited-range circuits.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cognates::Spacing)]
#[serde(rename_all = "snake_case")]
pub enum Spacing {
    /// Cosine spacing on limited-range circuits, uniform on full-rotation ones (O(N⁻²) chord error).
    #[default]
    Auto,
    /// Uniform in the input angle (O(N⁻¹) near toggles).
    Uniform,
}

/// How curves are traced.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cognates::CurveMode)]
#[serde(rename_all = "snake_case")]
pub enum CurveMode {
    /// Closed circuits, switching branch at toggles (the whole curve).
    #[default]
    Circuits,
    /// Paper style: each mechanism's own input over its range on the branch of the snapshot.
    FixedBranch,
}

/// A verification method (spec §4.9).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cognates::VerifyKind)]
#[serde(rename_all = "snake_case")]
pub enum VerifyKind {
    /// Map every original sample to the cognates; constraint residuals and independent re-solve.
    Sync,
    /// Distance of the cognates' traced points from the original's coupler-curve sextic.
    Implicit,
    /// Symmetric Hausdorff distance between the traced polylines (sampling-limited).
    Hausdorff,
}

/// Optional outputs (off by default, computed only when asked) and accuracy knobs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = cognates::CognatesOptions)]
#[serde(deny_unknown_fields, default)]
pub struct CognatesOptions {
    /// Return sampled coupler curves of all three mechanisms.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub curves: bool,
    /// Samples per closed circuit per mechanism, N. Default 360.
    #[serde(deserialize_with = "points_or_default")]
    #[rule(range = POINTS_PER_CIRCUIT)]
    #[schema(example = 360)]
    pub points_per_circuit: u64,
    /// Sample spacing: `auto` (cosine on limited-range circuits, uniform on full turns) or `uniform`.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    #[schema(inline)]
    pub spacing: Spacing,
    /// Curve tracing mode: `circuits` (whole curve, branch switching at toggles) or `fixed_branch`
    /// (paper style: each input over its range on its snapshot branch).
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    #[schema(inline)]
    pub curve_mode: CurveMode,
    /// Verification methods to run.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub verify: Vec<VerifyKind>,
    /// Also return the three 1:1 geared five-bar equivalents (spec §4.10).
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub geared_fivebars: bool,
    /// Comparison metrics per mechanism (spec §4.11).
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub metrics: bool,
    /// Relative tolerance of the Grashof equality test (change point) and of the special shapes.
    /// Default 1e-9.
    #[serde(deserialize_with = "grashof_rtol_or_default")]
    #[rule(range = GRASHOF_RTOL)]
    #[schema(example = 1e-9)]
    pub grashof_rtol: f64,
}

/// Default of `options.points_per_circuit` (spec §3).
pub const DEFAULT_POINTS_PER_CIRCUIT: u64 = 360;
/// Default of `options.grashof_rtol` (spec §3).
pub const DEFAULT_GRASHOF_RTOL: f64 = 1e-9;

/// `options.points_per_circuit`: `null` reads as the default, exactly as when absent.
fn points_or_default<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    Ok(Option::<u64>::deserialize(d)?.unwrap_or(DEFAULT_POINTS_PER_CIRCUIT))
}

/// `options.grashof_rtol`: `null` reads as the default, exactly as when absent.
fn grashof_rtol_or_default<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(DEFAULT_GRASHOF_RTOL))
}

impl Default for CognatesOptions {
    fn default() -> Self {
        Self {
            curves: false,
            points_per_circuit: DEFAULT_POINTS_PER_CIRCUIT,
            spacing: Spacing::Auto,
            curve_mode: CurveMode::Circuits,
            verify: Vec::new(),
            geared_fivebars: false,
            metrics: false,
            grashof_rtol: DEFAULT_GRASHOF_RTOL,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Response
// ---------------------------------------------------------------------------------------------

/// Response of `POST /v1/cognates`.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::CognatesResponse)]
pub struct CognatesResponse {
    /// Third ground pivot C = A + k·(B − A) \[length\].
    #[serde(rename = "C")]
    #[schema(value_type = [f64; 2])]
    pub c: Point,
    /// Similarity of the ground triangle ABC to the coupler triangle DEP.
    pub similarity: Similarity,
    /// `[original, cognate1, cognate2]`.
    pub mechanisms: Vec<MechanismOut>,
    /// Numerical certificate that the curves coincide (when `options.verify` is not empty).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub verification: Option<Verification>,
    /// The three 1:1 geared five-bar equivalents (when `options.geared_fivebars`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub geared_fivebars: Option<Vec<GearedFiveBar>>,
    /// Warnings about fragile or special geometry.
    pub warnings: Vec<Warning>,
    /// How the calculation stopped and what it cost (closed form: always `completed`;
    /// `iterations` and `evaluations` count the curve points computed), as on every endpoint.
    pub report: SolverReport,
    /// Deprecated: the same cost as `report` (`compute_us` = `report.elapsed_ms` in µs); kept for
    /// one release for clients that read it.
    #[schema(deprecated)]
    pub meta: Meta,
}

/// Ground triangle A-B-C similar to the coupler triangle D-E-P (A↔D, B↔E, C↔P).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::Similarity)]
pub struct Similarity {
    /// |AC|/|AB| = d/b.
    #[serde(rename = "ratio_AC_AB")]
    pub ratio_ac_ab: f64,
    /// |BC|/|AB| = e/b.
    #[serde(rename = "ratio_BC_AB")]
    pub ratio_bc_ab: f64,
    /// Signed angle ∠(AB, AC) = t2·θ3 \[deg\].
    #[serde(rename = "angle_at_A_deg")]
    pub angle_at_a_deg: f64,
    /// Complex coupler ratio k = [Re, Im] (P = D + k·(E − D)).
    #[schema(value_type = [f64; 2])]
    pub k: [f64; 2],
}

/// Which member of the family.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::MechanismId)]
#[serde(rename_all = "snake_case")]
pub enum MechanismId {
    /// The given four-bar.
    Original,
    /// Cognate with pivots A, C.
    Cognate1,
    /// Cognate with pivots C, B.
    Cognate2,
}

/// One four-bar of the family.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::MechanismOut)]
pub struct MechanismOut {
    /// Which member.
    pub id: MechanismId,
    /// Input (crank) pivot \[length\].
    #[schema(value_type = [f64; 2])]
    pub input_pivot: Point,
    /// Output (rocker) pivot \[length\].
    #[schema(value_type = [f64; 2])]
    pub output_pivot: Point,
    /// Direction of the ground line input→output pivot \[deg\].
    pub ground_angle_deg: f64,
    /// Link lengths by physical role.
    pub links: Links,
    /// Coupler-triangle sides in similarity order (paper Eq. 47, Table 1): `s_i·(b, d, e)`.
    pub similar_sides: SimilarSides,
    /// Grashof/Barker classification.
    pub grashof: GrashofOut,
    /// Feasible input range, toggles and circuits.
    pub input_range: InputRangeOut,
    /// Which original link each link turns with (cognates only).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub rotation_map: Option<RotationMap>,
    /// The snapshot configuration (when `input_angle_deg` or `joints` is given).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub snapshot: Option<SnapshotOut>,
    /// Sampled coupler curves (when `options.curves`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub curves: Option<Vec<CurveOut>>,
    /// Comparison metrics (when `options.metrics`).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub metrics: Option<MetricsOut>,
}

/// Link lengths by physical role \[length\].
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::Links)]
pub struct Links {
    /// Ground |O_out − O_in|.
    pub ground: f64,
    /// Crank (input link).
    pub crank: f64,
    /// Coupler |E − D|.
    pub coupler: f64,
    /// Rocker (output link).
    pub rocker: f64,
    /// |P − D| (crank joint to coupler point).
    #[serde(rename = "crank_joint_to_P")]
    pub crank_joint_to_p: f64,
    /// |P − E| (rocker joint to coupler point).
    #[serde(rename = "rocker_joint_to_P")]
    pub rocker_joint_to_p: f64,
    /// Coupler side: 1 when P is left of the directed line D→E (nominal when P is on that line).
    pub coupler_side: i8,
    /// Angle of the coupler triangle at the crank joint, unsigned \[deg\] (θ3 for the original).
    pub coupler_angle_at_crank_joint_deg: f64,
    /// Complex coupler ratio k_i = [Re, Im].
    #[schema(value_type = [f64; 2])]
    pub k: [f64; 2],
}

/// Coupler-triangle sides in similarity order (b_i : d_i : e_i = b : d : e) \[length\].
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::SimilarSides)]
pub struct SimilarSides {
    /// Side similar to the original coupler b.
    pub b: f64,
    /// Side similar to the original d.
    pub d: f64,
    /// Side similar to the original e.
    pub e: f64,
}

/// Grashof class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::GrashofClassOut)]
#[serde(rename_all = "snake_case")]
pub enum GrashofClassOut {
    /// s + l < p + q.
    Grashof,
    /// s + l > p + q.
    NonGrashof,
    /// s + l = p + q within `grashof_rtol`.
    ChangePoint,
}

/// Four-bar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::LinkageTypeOut)]
#[serde(rename_all = "snake_case")]
pub enum LinkageTypeOut {
    /// Ground shortest (drag link).
    DoubleCrank,
    /// Input shortest.
    CrankRocker,
    /// Coupler shortest (Grashof double rocker).
    DoubleRocker,
    /// Output shortest.
    RockerCrank,
    /// Non-Grashof.
    TripleRocker,
    /// Change point.
    ChangePoint,
}

/// Link role.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::LinkRoleOut)]
#[serde(rename_all = "snake_case")]
pub enum LinkRoleOut {
    /// Ground.
    Ground,
    /// Input link (crank).
    Input,
    /// Coupler.
    Coupler,
    /// Output link (rocker).
    Output,
}

/// Special shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::SpecialOut)]
#[serde(rename_all = "snake_case")]
pub enum SpecialOut {
    /// a = c, b = g.
    Parallelogram,
    /// (a = g, b = c) or (a = b, c = g).
    Deltoid,
    /// All equal.
    Rhombus,
}

/// Grashof/Barker classification (spec §4.2).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::GrashofOut)]
pub struct GrashofOut {
    /// Class.
    pub class: GrashofClassOut,
    /// Type by the shortest link (Grashof) or `triple_rocker` / `change_point`.
    #[serde(rename = "type")]
    pub kind: LinkageTypeOut,
    /// Barker code: GCCC, GCRR, GRCR, GRRC, RRR1..RRR4 (absent for change points).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub barker: Option<String>,
    /// Special shape (absent when none).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub special: Option<SpecialOut>,
    /// Signed margin (s + l) − (p + q) \[length\]; negative = Grashof.
    pub margin: f64,
    /// s + l \[length\].
    pub s_plus_l: f64,
    /// p + q \[length\].
    pub p_plus_q: f64,
    /// Shortest link.
    pub shortest: LinkRoleOut,
    /// Longest link.
    pub longest: LinkRoleOut,
}

/// Feasible input range (spec §4.3).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::InputRangeOut)]
pub struct InputRangeOut {
    /// Intervals of φ relative to the own ground line \[deg\]; an interval through 180° ends above 180.
    #[schema(value_type = Vec<[f64; 2]>)]
    pub intervals_rel_deg: Vec<[f64; 2]>,
    /// The same intervals as absolute input angles \[deg\] (start wrapped to (−180, 180]).
    #[schema(value_type = Vec<[f64; 2]>)]
    pub intervals_abs_deg: Vec<[f64; 2]>,
    /// Whether the input link rotates fully.
    pub full_rotation: bool,
    /// Toggle (dead-centre) input angles, absolute, wrapped to (−180, 180] \[deg\].
    pub toggle_angles_abs_deg: Vec<f64>,
    /// Number of closed circuits of the configuration space.
    pub n_circuits: usize,
}

/// Link of the original that a cognate link turns with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::OriginalLink)]
pub enum OriginalLink {
    /// The original crank.
    #[serde(rename = "original.crank")]
    Crank,
    /// The original coupler.
    #[serde(rename = "original.coupler")]
    Coupler,
    /// The original rocker.
    #[serde(rename = "original.rocker")]
    Rocker,
}

/// A cognate link turns with an original link at a constant angular offset.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::TurnsWith)]
pub struct TurnsWith {
    /// The original link.
    pub turns_with: OriginalLink,
    /// Constant offset: cognate link angle − original link angle \[deg\].
    pub offset_deg: f64,
}

/// Rotation (timing) map of a cognate (spec §4.7).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::RotationMap)]
pub struct RotationMap {
    /// Cognate crank.
    pub crank: TurnsWith,
    /// Cognate coupler.
    pub coupler: TurnsWith,
    /// Cognate rocker.
    pub rocker: TurnsWith,
    /// Whether this cognate driven at the original crank's speed reproduces the original's timing
    /// along the curve (true for cognate 2 only).
    pub same_timing_as_original: bool,
}

/// Status of a snapshot configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::SnapshotStatus)]
#[serde(rename_all = "snake_case")]
pub enum SnapshotStatus {
    /// Assembled.
    Ok,
    /// Assembled at a toggle (h ≤ 1e-9·b): branch labels meet here.
    Toggle,
    /// The input angle is outside the feasible range.
    NotAssemblable,
    /// The crank tip is on the output pivot: the dyad is undetermined by the input.
    Singular,
}

/// Joint positions of one configuration \[length\].
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::JointsOut)]
pub struct JointsOut {
    /// Input pivot.
    #[schema(value_type = [f64; 2])]
    pub input_pivot: Point,
    /// Crank joint D_i.
    #[schema(value_type = [f64; 2])]
    pub crank_joint: Point,
    /// Rocker joint E_i.
    #[schema(value_type = [f64; 2])]
    pub rocker_joint: Point,
    /// Output pivot.
    #[schema(value_type = [f64; 2])]
    pub output_pivot: Point,
    /// Coupler point P (common to all three).
    #[serde(rename = "P")]
    #[schema(value_type = [f64; 2])]
    pub p: [f64; 2],
}

/// The snapshot configuration as seen by one mechanism (spec §4.4, §4.6).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::SnapshotOut)]
pub struct SnapshotOut {
    /// Status of this mechanism's own input at this pose.
    pub status: SnapshotStatus,
    /// This mechanism's own input angle, absolute \[deg\] (absent when undetermined).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub input_angle_deg: Option<f64>,
    /// The same angle relative to its own ground line \[deg\].
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub input_angle_rel_deg: Option<f64>,
    /// This mechanism's assembly branch (absent when undetermined).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub branch: Option<i8>,
    /// Joint positions (absent when not assemblable or undetermined).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub joints: Option<JointsOut>,
    /// Transmission angle folded into [0°, 90°] \[deg\].
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub transmission_angle_deg: Option<f64>,
}

/// One sampled circuit (or fixed-branch sweep) of a coupler curve.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::CurveOut)]
pub struct CurveOut {
    /// Whether the polyline closes on itself (last point connects to the first).
    pub closed: bool,
    /// Coupler point positions \[length\].
    #[schema(value_type = Vec<[f64; 2]>)]
    pub points: Vec<Point>,
    /// Absolute input angle of each point \[deg\].
    pub input_deg: Vec<f64>,
    /// Assembly branch of each point.
    pub branch: Vec<i8>,
    /// Samples dropped because the crank tip sat on the output pivot (deltoid), if any.
    #[serde(skip_serializing_if = "is_zero")]
    pub n_singular_excluded: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Comparison metrics of one mechanism over all its circuits (spec §4.11).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::MetricsOut)]
pub struct MetricsOut {
    /// ground + crank + coupler + rocker \[length\].
    pub link_length_sum: f64,
    /// Ground pivot distance \[length\].
    pub ground_span: f64,
    /// Longest side of the coupler triangle \[length\].
    pub coupler_max_side: f64,
    /// Bounding box of the pivots and all moving joints over all circuits.
    pub footprint: Footprint,
    /// Smallest transmission angle over the motion \[deg\] (0 at toggles).
    pub transmission_angle_min_deg: f64,
    /// Largest transmission angle over the motion \[deg\].
    pub transmission_angle_max_deg: f64,
    /// Whether the input rotates fully.
    pub full_rotation: bool,
    /// Whether the timing along the curve equals the original's (original and cognate 2).
    pub timing_equals_original: bool,
    /// Samples the metrics were taken over.
    pub n_samples: usize,
}

/// Axis-aligned bounding box \[length\].
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::Footprint)]
pub struct Footprint {
    /// Lower-left corner.
    #[schema(value_type = [f64; 2])]
    pub min: Point,
    /// Upper-right corner.
    #[schema(value_type = [f64; 2])]
    pub max: Point,
    /// Width \[length\].
    pub width: f64,
    /// Height \[length\].
    pub height: f64,
    /// Area \[length²\].
    pub area: f64,
}

/// Numerical certificate (spec §4.9); every distance in the caller's length unit.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::Verification)]
pub struct Verification {
    /// Pose-map check (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub sync: Option<SyncCheck>,
    /// Sextic check (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub implicit: Option<ImplicitCheck>,
    /// Hausdorff distances (when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub hausdorff: Option<HausdorffCheck>,
}

/// `sync`: every original sample mapped to the cognates (spec §4.9).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::SyncCheck)]
pub struct SyncCheck {
    /// Largest |P_i − P| of the independent re-solve of each cognate at its own input and branch.
    pub max_dev: f64,
    /// The same over samples where every cognate is away from its toggles (h_i/b_i ≥ 1e-6).
    pub max_dev_regular: f64,
    /// Largest residual of the cognates' length and coupler-point constraints.
    pub max_constraint_residual: f64,
    /// Original samples checked.
    pub n_samples: usize,
    /// Samples where some cognate is near a toggle (h_i/b_i < 1e-6).
    pub n_near_toggle: usize,
    /// Samples whose re-solve was skipped because a cognate's crank tip sat on its output pivot
    /// (locked input, spec §7).
    pub n_skipped_locked: usize,
    /// Whether residual ≤ 1e-12·L and regular deviation ≤ 1e-9·L (L = largest original length).
    pub passed: bool,
}

/// `implicit`: the cognates' own traced points on the original's coupler-curve sextic.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::ImplicitCheck)]
pub struct ImplicitCheck {
    /// Largest distance estimate |F|/|∇F|.
    pub max_dist: f64,
    /// Points checked.
    pub n_points: usize,
    /// Points skipped as (near) double points of the curve (|∇F| < 1e-6·median).
    pub n_skipped_double_points: usize,
    /// Whether max_dist ≤ 1e-10·L.
    pub passed: bool,
}

/// `hausdorff`: symmetric Hausdorff distance between the traced polylines (vertex to segment).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::HausdorffCheck)]
pub struct HausdorffCheck {
    /// Original vs cognate 1 (absent when a curve has no points).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub cognate1: Option<f64>,
    /// Original vs cognate 2 (absent when a curve has no points).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub cognate2: Option<f64>,
    /// The larger of the two.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub max: Option<f64>,
    /// Points per traced curve the distances were measured on (sampling-limited: O(N⁻²)).
    pub n_points: usize,
}

/// A 1:1 geared five-bar that traces the same curve (spec §4.10).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::GearedFiveBar)]
pub struct GearedFiveBar {
    /// Pivot names, e.g. `["A", "C"]`.
    pub pivot_names: [String; 2],
    /// Ground pivots \[length\].
    #[schema(value_type = Vec<[f64; 2]>)]
    pub pivots: [Point; 2],
    /// Which family links the two cranks are.
    pub from: [String; 2],
    /// Crank 1 length \[length\].
    pub crank1: f64,
    /// Crank 2 length \[length\].
    pub crank2: f64,
    /// Phase ψ = crank-2 angle − crank-1 angle, constant under the 1:1 same-direction gearing \[deg\].
    pub phase_deg: f64,
    /// Dyad link from crank-1 tip to P \[length\].
    pub dyad1: f64,
    /// Dyad link from crank-2 tip to P \[length\].
    pub dyad2: f64,
    /// The five-bar in the snapshot configuration (when the snapshot assembles).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub snapshot: Option<FiveBarSnapshot>,
}

/// A geared five-bar in the snapshot configuration.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::FiveBarSnapshot)]
pub struct FiveBarSnapshot {
    /// Crank 1 angle \[deg\].
    pub crank1_angle_deg: f64,
    /// Crank 2 angle \[deg\].
    pub crank2_angle_deg: f64,
    /// Crank 1 tip \[length\].
    #[schema(value_type = [f64; 2])]
    pub crank1_tip: Point,
    /// Crank 2 tip \[length\].
    #[schema(value_type = [f64; 2])]
    pub crank2_tip: Point,
    /// Coupler point \[length\].
    #[serde(rename = "P")]
    #[schema(value_type = [f64; 2])]
    pub p: [f64; 2],
    /// Largest deviation of |P − tip_i| from the dyad lengths \[length\].
    pub dyad_residual: f64,
}

/// A warning code (spec §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = cognates::WarningCode)]
#[serde(rename_all = "snake_case")]
pub enum WarningCode {
    /// Grashof equality within tolerance: folded configurations, ambiguous branches.
    ChangePoint,
    /// A mechanism is a parallelogram.
    Parallelogram,
    /// A mechanism is a deltoid (kite).
    Deltoid,
    /// Part of the curve is traced while the mechanism's input link stands still.
    InputLockedSegment,
    /// P lies on the line DE: the ground pivots are collinear.
    CollinearCouplerTriangle,
    /// |k| or |1−k| < 1e-3: a cognate is tiny or huge.
    NearDegenerateCognate,
    /// The snapshot is at a toggle: its branch label is ambiguous.
    SnapshotAtToggle,
    /// The lengths span more than 6 orders of magnitude.
    ExtremeAspectRatio,
    /// `fixed_branch` curves without an assembled snapshot used default branches.
    FixedBranchDefaultBranches,
}

/// A warning about fragile or special geometry.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::Warning)]
pub struct Warning {
    /// Stable code.
    pub code: WarningCode,
    /// Human explanation naming the mechanism and values.
    pub message: String,
    /// The mechanism concerned, if one.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub mechanism: Option<MechanismId>,
    /// Related input angles (absolute) \[deg\], e.g. the folded positions of a change point.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub angles_deg: Option<Vec<f64>>,
}

/// Cost of the request (deprecated: read `report`).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = cognates::Meta, deprecated)]
pub struct Meta {
    /// Curve points returned (all mechanisms).
    pub points_total: usize,
    /// Compute time \[µs\].
    pub compute_us: u64,
}

/// Largest magnitude accepted for any coordinate or length: keeps `|B − A|` and every product of
/// two lengths finite (1e100² = 1e200 < f64::MAX), far beyond any physical unit choice.
pub const MAX_MAGNITUDE: f64 = 1e100;
/// A link length \[length\]: positive and at most [`MAX_MAGNITUDE`].
pub const LENGTH: Range = Range::FINITE.gt(0.0).max(MAX_MAGNITUDE);
/// A distance that may be zero \[length\].
pub const NON_NEGATIVE_LENGTH: Range = Range::FINITE.min(0.0).max(MAX_MAGNITUDE);
/// A coordinate or signed length \[length\].
pub const COORDINATE: Range = Range::FINITE.min(-MAX_MAGNITUDE).max(MAX_MAGNITUDE);
/// Samples per circuit N (spec §3).
pub const POINTS_PER_CIRCUIT: Range = Range::int(16, 100_000);
/// Relative tolerance of the Grashof classification (spec §3).
pub const GRASHOF_RTOL: Range = Range::closed(0.0, 1e-3);
