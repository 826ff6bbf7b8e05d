//! The wire forms of the geometry shared by both IREFC endpoints (the `geometry` object with its
//! optional profile point sets, and the geometry warnings); each endpoint's own response is built
//! in its `output.rs` ([`super::stress::output`], [`super::efficiency::output`]).

use super::geometry::{Geometry, GeometryWarning, NEAR_UNDERCUT_FRACTION, Wheel};
use super::wire::{GeometryOut, MM, PROFILE_POINTS_MAX, Profiles, Warning};

/// Warnings of a geometry with their messages (spec irefc_geometry "Warnings").
#[must_use]
pub fn geometry_warnings(g: &Geometry) -> Vec<Warning> {
    g.warnings()
        .into_iter()
        .map(|w| {
            let msg = match w {
                GeometryWarning::ChiOutsidePaperRange => {
                    format!("chi = {} is outside the force paper's range [1.25, 1.67] (assemblability)", g.chi)
                }
                GeometryWarning::RbBelowPaperMin => format!(
                    "rb = {} mm <= 2*r2/Z2 = {} mm (lower bound of force-paper eq. 3)",
                    g.rb * MM,
                    g.rb_min_paper * MM
                ),
                GeometryWarning::ContactABeyondPitch => format!(
                    "rb = {} mm >= r2*(chi-1) = {} mm: the cam contact A lies at or before the pitch point near phi2 = 0 (LA <= 0)",
                    g.rb * MM,
                    g.r2 * (g.chi - 1.0) * MM
                ),
                GeometryWarning::NearUndercut => format!(
                    "sharpest convex profile radius {} mm < {} * rb: contact stresses become very large near the undercut limit rb_undercut = {} mm",
                    g.min_profile_radius() * MM,
                    NEAR_UNDERCUT_FRACTION,
                    g.rb_undercut * MM
                ),
            };
            Warning::new(w.code(), msg)
        })
        .collect()
}

impl Profiles {
    /// Generate `n` points per wheel.
    #[must_use]
    pub fn generate(g: &Geometry, n: u32) -> Self {
        let to_mm = |v: Vec<[f64; 2]>| v.into_iter().map(|[x, y]| [x * MM, y * MM]).collect();
        let n_us = usize::try_from(n)
            .unwrap_or(usize::MAX)
            .min(PROFILE_POINTS_MAX as usize);
        Self {
            n_points: n,
            cam_mm: to_mm(g.profile(Wheel::Cam, n_us)),
            crown_mm: to_mm(g.profile(Wheel::Crown, n_us)),
        }
    }
}

impl GeometryOut {
    /// Wire form of `g`; profiles with `profile_points` points per wheel when requested.
    #[must_use]
    pub fn from_geometry(g: &Geometry, profile_points: Option<u32>) -> Self {
        Self {
            e_mm: g.e * MM,
            e_total_mm: g.e_total * MM,
            r1_mm: g.r1 * MM,
            r3_mm: g.r3 * MM,
            rc_mm: g.rc * MM,
            z1: g.z1,
            z3: g.z3,
            cam_tip_mm: g.cam_tip * MM,
            cam_root_mm: g.cam_root * MM,
            crown_tip_mm: g.crown_tip * MM,
            crown_root_mm: g.crown_root * MM,
            rb_min_paper_mm: g.rb_min_paper * MM,
            rb_overlap_mm: g.rb_overlap * MM,
            rb_undercut_mm: g.rb_undercut * MM,
            min_profile_radius_cam_mm: g.min_profile_radius_cam() * MM,
            min_profile_radius_crown_mm: g.min_profile_radius_crown().map(|r| r * MM),
            ratio_cam_output: g.ratio_cam_output(),
            ratio_crown_output: g.ratio_crown_output(),
            profiles: profile_points.map(|n| Profiles::generate(g, n)),
        }
    }
}
