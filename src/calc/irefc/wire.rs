//! Wire types shared by both IREFC endpoints: the `geometry` output object, warnings, materials,
//! profile point sets, and the bounds of the four initial parameters and the materials (checked by
//! [`super::input`]).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::geometry::{CHI_MAX, Z2_MAX, Z2_MIN};
use crate::calc::Range;

/// Millimetres per metre (wire ↔ SI).
pub(crate) const MM: f64 = 1e3;
/// Default number of profile points per wheel (spec).
pub const PROFILE_POINTS_DEFAULT: u32 = 720;
/// Largest number of profile points per wheel (keeps responses below a few MB).
pub const PROFILE_POINTS_MAX: u32 = 100_000;
/// Smallest number of profile points per wheel (a closed polygon needs a few).
pub const PROFILE_POINTS_MIN: u32 = 8;

/// Cage pitch radius r2 \[mm\]: 0 < r2 ≤ 10 000 (spec).
pub const R2_MM: Range = Range::FINITE.gt(0.0).max(10_000.0);
/// Number of rolling elements Z2 [–]: 3 ≤ Z2 ≤ 1000 (Z2 = 2 gives Σsin²α = 0).
pub const Z2: Range = Range::int(Z2_MIN as i64, Z2_MAX as i64);
/// Displacement coefficient χ [–]: 1 < χ ≤ 5.
pub const CHI: Range = Range::FINITE.gt(1.0).max(CHI_MAX);
/// Rolling element radius rb \[mm\]: > 0. Buildability (rb below rb_overlap and rb_undercut, which
/// depend on r2, Z2 and χ) is checked on the geometry (`ELEMENT_OVERLAP`, `UNDERCUT`).
pub const RB_MM: Range = Range::FINITE.gt(0.0);
/// Young's modulus E \[MPa\].
pub const E_MPA: Range = Range::closed(1e3, 1e7);
/// Poisson's ratio ν [–]: 0 ≤ ν < 0.5.
pub const NU: Range = Range::FINITE.min(0.0).lt(0.5);

/// A non-fatal warning: stable code and human message.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, ToSchema)]
#[schema(as = irefc::Warning)]
pub struct Warning {
    /// Stable code, e.g. `NEAR_UNDERCUT`, `RB_BELOW_PAPER_MIN`, `ROLLING_FRICTION_HIGH`.
    #[schema(example = "RB_BELOW_PAPER_MIN")]
    pub code: String,
    /// What it means for this request, with the values involved.
    pub message: String,
}

impl Warning {
    /// A warning from code and message.
    #[must_use]
    pub fn new(code: &str, message: impl Into<String>) -> Self {
        Self {
            code: code.to_owned(),
            message: message.into(),
        }
    }
}

/// Elastic material of a body.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, ToSchema, crate::calc::Rules)]
#[schema(as = irefc::Material)]
#[serde(deny_unknown_fields)]
#[rules(code = "BAD_RANGE")]
pub struct Material {
    /// Young's modulus E \[MPa\].
    #[serde(rename = "E_MPa")]
    #[rule(range = E_MPA)]
    #[schema(example = 210_000.0)]
    pub e_mpa: f64,
    /// Poisson's ratio ν [–], 0 ≤ ν < 0.5.
    #[rule(range = NU)]
    #[schema(example = 0.3)]
    pub nu: f64,
}

impl Default for Material {
    /// Steel, E = 210 000 MPa, ν = 0.3 (the paper gives no values).
    fn default() -> Self {
        Self {
            e_mpa: 210_000.0,
            nu: 0.3,
        }
    }
}

impl Material {
    /// Plane-strain modulus term (1 − ν²)/E [1/Pa].
    #[must_use]
    pub fn compliance(&self) -> f64 {
        self.nu.mul_add(-self.nu, 1.0) / (self.e_mpa * 1e6)
    }
}

/// Profile point sets of both wheels (spec irefc_geometry "profile point sets").
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::Profiles)]
pub struct Profiles {
    /// Points per wheel.
    pub n_points: u32,
    /// Cam profile [[x, y]] \[mm\] in the cam frame (cam centre at the origin), Z2 − 1 lobes.
    pub cam_mm: Vec<[f64; 2]>,
    /// Crown profile [[x, y]] \[mm\] in the crown frame (crown centre at the origin), Z2 + 1 lobes.
    pub crown_mm: Vec<[f64; 2]>,
}

/// Derived geometry (spec irefc_geometry "Outputs"), shared by both endpoints.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = irefc::GeometryOut)]
pub struct GeometryOut {
    /// Eccentricity of each mesh e = r2/Z2 \[mm\].
    pub e_mm: f64,
    /// Cam centre to crown centre 2e \[mm\].
    pub e_total_mm: f64,
    /// Cam pitch radius r1 = r2(1 − 1/Z2) \[mm\].
    pub r1_mm: f64,
    /// Crown pitch radius r3 = r2(1 + 1/Z2) \[mm\].
    pub r3_mm: f64,
    /// Element-centre circle radius rc = χ·r2 \[mm\].
    pub rc_mm: f64,
    /// Cam lobes Z1 = Z2 − 1.
    #[serde(rename = "Z1")]
    pub z1: u32,
    /// Crown lobes Z3 = Z2 + 1.
    #[serde(rename = "Z3")]
    pub z3: u32,
    /// Cam tip radius r2(χ + 1/Z2) − rb \[mm\] (force paper eq. 8).
    pub cam_tip_mm: f64,
    /// Cam root radius r2(χ − 1/Z2) − rb \[mm\] (eq. 9).
    pub cam_root_mm: f64,
    /// Crown tip radius r2(χ − 1/Z2) + rb \[mm\] (eq. 10).
    pub crown_tip_mm: f64,
    /// Crown root radius r2(χ + 1/Z2) + rb \[mm\] (eq. 11).
    pub crown_root_mm: f64,
    /// Lower bound of force-paper eq. 3, 2·r2/Z2 \[mm\] (below it: warning only).
    pub rb_min_paper_mm: f64,
    /// Element overlap limit χ·r2·sin(π/Z2) \[mm\] (rb must be below).
    pub rb_overlap_mm: f64,
    /// Undercut limit (closed form) \[mm\] (rb must be below).
    pub rb_undercut_mm: f64,
    /// Sharpest convex cam profile radius \[mm\].
    pub min_profile_radius_cam_mm: f64,
    /// Sharpest convex crown profile radius \[mm\]; null when the crown profile is concave everywhere (χ ≥ Z2).
    pub min_profile_radius_crown_mm: Option<f64>,
    /// Carrier → cam ratio with the crown fixed, (Z2 − 1)/2; the cam turns opposite to the carrier.
    pub ratio_cam_output: f64,
    /// Carrier → crown ratio with the cam rotation locked, (Z2 + 1)/2; same direction as the carrier.
    pub ratio_crown_output: f64,
    /// Profile point sets, only when `include.profiles` is true.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub profiles: Option<Profiles>,
}

impl GeometryOut {
    /// Whether every number is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        [
            self.e_mm,
            self.r1_mm,
            self.r3_mm,
            self.rc_mm,
            self.cam_tip_mm,
            self.cam_root_mm,
            self.crown_tip_mm,
            self.crown_root_mm,
            self.rb_min_paper_mm,
            self.rb_overlap_mm,
            self.rb_undercut_mm,
            self.min_profile_radius_cam_mm,
            self.min_profile_radius_crown_mm.unwrap_or(0.0),
        ]
        .iter()
        .all(|v| v.is_finite())
            && self.profiles.as_ref().is_none_or(|p| {
                p.cam_mm
                    .iter()
                    .chain(p.crown_mm.iter())
                    .all(|[x, y]| x.is_finite() && y.is_finite())
            })
    }
}
