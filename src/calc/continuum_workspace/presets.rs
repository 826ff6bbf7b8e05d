//! The spec's presets (spec 6.2). The paper gives no rod lengths, material, layout, clamp angles,
//! platform size or strokes (spec 4.9-2), so every preset geometry here is ASSUMED; responses say so.

use super::model::{Actuator, Design, Rod};

/// Young's modulus of the preset rods (steel) [Pa].
const E_STEEL: f64 = 2.1e11;
/// Preset rod length [m].
const LENGTH: f64 = 0.5;
/// Half-range of the preset strokes around home [m] (the spec's sweep ranges home +/- 0.45 m).
const HALF_STROKE: f64 = 0.45;

/// A named preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preset {
    /// Design 1: parallelogram pair on carriage 1 (a = 0.045 m), third rod on carriage 2 pinned at (+a/2, 0).
    KeopsD1,
    /// Design 2: as design 1, third rod pinned at (-a/2, 0).
    KeopsD2,
    /// Design 3: as design 1, rod 1 pinned at (0, 0) (no stress-free home).
    KeopsD3,
    /// Design 4: as design 1, rod 2 pinned at (0, 0) (no stress-free home).
    KeopsD4,
    /// Optimised design 1, reading A: a = 0.1 m, third rod d = 2 mm.
    KeopsD1OptA,
    /// Symmetric 4-rod design: a parallelogram pair on each carriage.
    Symmetric,
}

impl Preset {
    /// Wire name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::KeopsD1 => "keops_d1",
            Self::KeopsD2 => "keops_d2",
            Self::KeopsD3 => "keops_d3",
            Self::KeopsD4 => "keops_d4",
            Self::KeopsD1OptA => "keops_d1_opt_A",
            Self::Symmetric => "symmetric",
        }
    }

    /// Plain statement of the assumed geometry.
    #[must_use]
    pub fn description(self) -> String {
        let common = "ASSUMED geometry (the paper gives no rod lengths, material, layout, clamp angles, platform size or \
                      strokes): steel rods E = 2.1e11 Pa, L = 0.5 m, both guides through (0,0) along +X, \
                      rods clamped at -60 deg (carriage 1) and -120 deg (carriage 2), platform frame horizontal at \
                      theta_EE = 0, strokes = home +/- 0.45 m";
        let specific = match self {
            Self::KeopsD1 => "design 1: d = 4 mm, a = 0.045 m; rods 1,2 on carriage 1 at offsets (-a/2,0),(+a/2,0) \
                              pinned at (-a/2,0),(+a/2,0); rod 3 on carriage 2 pinned at (+a/2,0); home (-0.25, 0.2725) m"
                .to_string(),
            Self::KeopsD2 => "design 2: as design 1 but rod 3 pinned at (-a/2,0); home (-0.25, 0.2275) m".to_string(),
            Self::KeopsD3 => "design 3: as design 1 but rod 1 pinned at (0,0); no stress-free home (start from the \
                              stable assembly mode with the smallest |theta_EE|)"
                .to_string(),
            Self::KeopsD4 => "design 4: as design 1 but rod 2 pinned at (0,0); no stress-free home (start from the \
                              stable assembly mode with the smallest |theta_EE|)"
                .to_string(),
            Self::KeopsD1OptA => "optimised design 1, reading A of spec 4.9-3: a = 0.1 m, rods 1,2 d = 4 mm, rod 3 \
                                  d = 2 mm; home (-0.25, 0.30) m"
                .to_string(),
            Self::Symmetric => "symmetric 4-rod design: d = 4 mm, a = 0.045 m; rods 1,2 on carriage 1 and rods 3,4 on \
                                carriage 2 at offsets (-a/2,0),(+a/2,0), pinned at (-a/2,0),(+a/2,0); home (-0.25, 0.25) m"
                .to_string(),
        };
        format!("Preset {}: {common}; {specific}.", self.name())
    }

    /// The preset design.
    #[must_use]
    pub fn design(self) -> Design {
        let (a, d3) = match self {
            Self::KeopsD1OptA => (0.1, 0.002),
            _ => (0.045, 0.004),
        };
        let h = a / 2.0;
        let c1 = (-60.0f64).to_radians();
        let c2 = (-120.0f64).to_radians();
        let rod = |actuator: usize, ox: f64, clamp: f64, d: f64, attach_x: f64| {
            let ei = E_STEEL * std::f64::consts::PI * d.powi(4) / 64.0;
            let ea = E_STEEL * std::f64::consts::PI * d * d / 4.0;
            Rod {
                actuator,
                offset: [ox, 0.0],
                clamp,
                length: LENGTH,
                ei,
                ea: Some(ea),
                diameter: Some(d),
                attach: [attach_x, 0.0],
            }
        };
        let (rods, home) = match self {
            Self::Symmetric => (
                vec![
                    rod(0, -h, c1, 0.004, -h),
                    rod(0, h, c1, 0.004, h),
                    rod(1, -h, c2, 0.004, -h),
                    rod(1, h, c2, 0.004, h),
                ],
                Some([-0.25, 0.25]),
            ),
            _ => {
                let (a1, a2, a3) = match self {
                    Self::KeopsD2 => (-h, h, -h),
                    Self::KeopsD3 => (0.0, h, h),
                    Self::KeopsD4 => (-h, 0.0, h),
                    _ => (-h, h, h),
                };
                let home = match self {
                    Self::KeopsD1 => Some([-0.25, 0.25 + h]),
                    Self::KeopsD1OptA => Some([-0.25, 0.25 + h]),
                    Self::KeopsD2 => Some([-0.25, 0.25 - h]),
                    _ => None,
                };
                (
                    vec![
                        rod(0, -h, c1, 0.004, a1),
                        rod(0, h, c1, 0.004, a2),
                        rod(1, 0.0, c2, d3, a3),
                    ],
                    home,
                )
            }
        };
        // Designs 3 and 4 have no home: centre their strokes on design 1's home.
        let centre = home.unwrap_or([-0.25, 0.25 + h]);
        let guide = |c: f64| Actuator {
            origin: [0.0, 0.0],
            dir: [1.0, 0.0],
            stroke: [c - HALF_STROKE, c + HALF_STROKE],
        };
        Design {
            actuators: vec![guide(centre[0]), guide(centre[1])],
            rods,
            home: home.map(|h| h.to_vec()),
            sigma_allow: None,
        }
    }
}
