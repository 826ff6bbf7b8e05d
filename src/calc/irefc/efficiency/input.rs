//! Validation of an [`IrefcEfficiencyRequest`] into SI domain input, collecting every issue.

use std::f64::consts::PI;

use super::wire::{
    self, INPUT_TORQUE_NM, IrefcEfficiencyRequest, N_PHASE, POWER_W, ROLLING_FRICTION_MM,
    SLIDING_FRICTION, SPEED_RPM, phase_deg_range,
};
use crate::calc::irefc::error::{AMBIGUOUS_LOAD, BAD_RANGE, IrefcError};
use crate::calc::irefc::geometry::Geometry;
use crate::calc::irefc::input as design;
use crate::calc::irefc::wire::MM;
use crate::calc::{CalcFailure, ProblemClass};

/// The paper's rolling-friction lever arm μ = 0.001 m \[mm\].
pub const ROLLING_FRICTION_PAPER_MM: f64 = 1.0;
/// Rolling-friction lever arms above this \[mm\] get `ROLLING_FRICTION_HIGH` (largest tabulated steel value).
pub const ROLLING_FRICTION_HIGH_MM: f64 = 0.5;
/// The paper's sliding friction coefficient.
pub const SLIDING_FRICTION_PAPER: f64 = 0.1;

/// Loss model of the element slip speeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EfficiencyModel {
    /// The paper's equations exactly as printed (signed slip speed); reproduces its Table 1.
    PaperTable,
    /// The paper's equations with |Vs| in the sliding loss (what the paper's text says).
    PaperAbs,
    /// Not in the paper: rigid-body relative speeds in the carrier frame (pure rolling at the
    /// crown, slip at the cam).
    RigidBody,
}

impl From<wire::EfficiencyModel> for EfficiencyModel {
    fn from(m: wire::EfficiencyModel) -> Self {
        match m {
            wire::EfficiencyModel::PaperTable => Self::PaperTable,
            wire::EfficiencyModel::PaperAbs => Self::PaperAbs,
            wire::EfficiencyModel::RigidBody => Self::RigidBody,
        }
    }
}

/// Validated efficiency input \[SI\].
#[derive(Debug, Clone, PartialEq)]
pub struct EfficiencyInput {
    /// Geometry (feasible).
    pub geometry: Geometry,
    /// Input speed ω1 [rad/s].
    pub omega1: f64,
    /// Input torque M_in [N·m].
    pub m_in: f64,
    /// Input power P_in = M_in·ω1 \[W\].
    pub p_in: f64,
    /// Rolling-friction lever arm μ \[m\].
    pub mu: f64,
    /// Sliding friction coefficient f_s.
    pub fs: f64,
    /// Loss model.
    pub model: EfficiencyModel,
    /// Cage phase fraction p ∈ [0, 1) (phase angle p·360/Z2).
    pub phase_fraction: f64,
    /// Cage phases to average over.
    pub n_phase: u32,
    /// Output the element table.
    pub elements: bool,
}

impl EfficiencyInput {
    /// Validate a request: ranges (`BAD_RANGE`, `MISSING_FIELD`, `AMBIGUOUS_LOAD`, all at once), then
    /// buildability (`UNDERCUT`, `ELEMENT_OVERLAP`).
    pub fn try_from_request(req: &IrefcEfficiencyRequest) -> Result<Self, CalcFailure> {
        let mut v = design::validator();
        let _ = crate::calc::common::time_limit(&mut v, req.time_limit_ms);
        let r2 = design::r2(&mut v, "/r2_mm", req.r2_mm);
        let z2 = design::z2(&mut v, "/Z2", req.z2);
        let chi = design::chi(&mut v, "/chi", req.chi);
        let rb = design::rb(&mut v, "/rb_mm", req.rb_mm);
        match (req.power_w, req.input_torque_nm) {
            (Some(_), Some(_)) => v.push_code(
                AMBIGUOUS_LOAD,
                "/input_torque_Nm",
                "give either power_W or input_torque_Nm, not both",
            ),
            (None, None) => design::missing(&mut v, "/power_W", "power_W (or input_torque_Nm)"),
            (Some(p), None) => {
                v.range("/power_W", "input power power_W", p, POWER_W);
            }
            (None, Some(m)) => {
                v.range(
                    "/input_torque_Nm",
                    "input torque input_torque_Nm",
                    m,
                    INPUT_TORQUE_NM,
                );
            }
        }
        let mu_mm = req.rolling_friction_mm.unwrap_or(ROLLING_FRICTION_PAPER_MM);
        let fs = req.sliding_friction.unwrap_or(SLIDING_FRICTION_PAPER);
        let n_phase = req.n_phase.unwrap_or(1);
        for (pointer, name, x, range) in [
            (
                "/speed_rpm",
                "input speed speed_rpm",
                req.speed_rpm,
                SPEED_RPM,
            ),
            (
                "/rolling_friction_mm",
                "rolling friction lever arm",
                mu_mm,
                ROLLING_FRICTION_MM,
            ),
            (
                "/sliding_friction",
                "sliding friction coefficient",
                fs,
                SLIDING_FRICTION,
            ),
            ("/n_phase", "n_phase", f64::from(n_phase), N_PHASE),
        ] {
            v.range(pointer, name, x, range);
        }
        let phase_deg = req.phase_deg.unwrap_or(0.0);
        let mut phase_fraction = 0.0;
        if let Some(z) = z2 {
            let range = phase_deg_range(z);
            if v.range("/phase_deg", "cage phase phase_deg", phase_deg, range) {
                phase_fraction = (phase_deg / range.hi).clamp(0.0, 1.0 - f64::EPSILON);
            }
        }
        v.finish()?;
        let (Some(r2), Some(z2), Some(chi), Some(rb)) = (r2, z2, chi, rb) else {
            // Unreachable: each None recorded a problem and `finish` returned it.
            return Err(CalcFailure::general(
                ProblemClass::InvalidInput,
                BAD_RANGE,
                "incomplete design",
            ));
        };
        let geometry = Geometry::new_unchecked(r2 / MM, z2, chi, rb / MM);
        let bad = geometry.infeasibilities();
        if !bad.is_empty() {
            return Err(IrefcError::Infeasible(bad).into());
        }
        // ω1 exactly from rpm (2π/60): the paper's Table 1 used the exact value, not 157.1.
        let omega1 = 2.0 * PI * req.speed_rpm / 60.0;
        let (m_in, p_in) = match (req.power_w, req.input_torque_nm) {
            (Some(p), _) => (p / omega1, p),
            (None, Some(m)) => (m, m * omega1),
            (None, None) => (0.0, 0.0),
        };
        Ok(Self {
            geometry,
            omega1,
            m_in,
            p_in,
            mu: mu_mm / MM,
            fs,
            model: req.model.unwrap_or_default().into(),
            phase_fraction,
            n_phase,
            elements: req.include.and_then(|i| i.elements).unwrap_or(true),
        })
    }
}
