//! Validation of an [`IrefcEfficiencyRequest`] into SI domain input, collecting every issue.

use std::f64::consts::PI;

use super::wire::{IrefcEfficiencyRequest, phase_deg_range};
use crate::calc::CalcFailure;
use crate::calc::irefc::error::{self, IrefcError};
use crate::calc::irefc::geometry::Geometry;
use crate::calc::irefc::input as design;
use crate::calc::irefc::wire::MM;
use crate::calc::rules::{ensure_rule, rule};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/irefc-efficiency`, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid AMBIGUOUS_LOAD(error::AMBIGUOUS_LOAD) ["/power_W", "/input_torque_Nm"]
        "At most one of `power_W` and `input_torque_Nm` is given.";
    invalid LOAD_MISSING(error::MISSING_FIELD) ["/power_W", "/input_torque_Nm"]
        "One of `power_W` and `input_torque_Nm` is given.";
    invalid PHASE_BELOW_PITCH(error::BAD_RANGE) ["/phase_deg", "/Z2"]
        "phase_deg < 360/Z2 (one element pitch).";
    listed design::UNDERCUT;
    listed design::ELEMENT_OVERLAP;
    listed design::NON_FINITE;
    listed design::DEADLINE;
    listed crate::calc::common::RESPONSE_TOO_LARGE_RULE;
}

/// The paper's rolling-friction lever arm μ = 0.001 m \[mm\].
pub const ROLLING_FRICTION_PAPER_MM: f64 = 1.0;
/// Rolling-friction lever arms above this \[mm\] get `ROLLING_FRICTION_HIGH` (largest tabulated steel value).
pub const ROLLING_FRICTION_HIGH_MM: f64 = 0.5;
/// The paper's sliding friction coefficient.
pub const SLIDING_FRICTION_PAPER: f64 = 0.1;

/// The efficiency model: the request's `model`.
pub use super::wire::EfficiencyModel;

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
    /// The rules between fields of a request whose ranges passed the door (`MISSING_FIELD`,
    /// `AMBIGUOUS_LOAD`, the phase against Z2, all at once), then buildability (`UNDERCUT`,
    /// `ELEMENT_OVERLAP`).
    ///
    /// # Errors
    /// Each broken rule between fields ([`CROSS_FIELD_RULES`]).
    pub fn try_from_request(req: &IrefcEfficiencyRequest) -> Result<Self, CalcFailure> {
        // Every range is checked at the door (`BAD_RANGE`).
        let mut v = design::validator();
        match (req.power_w, req.input_torque_nm) {
            (Some(_), Some(_)) => rule!(v, AMBIGUOUS_LOAD, "/input_torque_Nm";
                "give either power_W or input_torque_Nm, not both"),
            (None, None) => design::missing(
                &mut v,
                &LOAD_MISSING,
                "/power_W",
                "power_W (or input_torque_Nm)",
            ),
            _ => {}
        }
        let mu_mm = req.rolling_friction_mm.unwrap_or(ROLLING_FRICTION_PAPER_MM);
        let fs = req.sliding_friction.unwrap_or(SLIDING_FRICTION_PAPER);
        let n_phase = req.n_phase.unwrap_or(1);
        let z2 = design::z2(req.z2);
        let phase_deg = req.phase_deg.unwrap_or(0.0);
        let mut phase_fraction = 0.0;
        if let Some(z) = z2 {
            let range = phase_deg_range(z);
            if ensure_rule!(v, range.contains(phase_deg), PHASE_BELOW_PITCH, "/phase_deg";
                "cage phase phase_deg [deg] must be {range}, got {phase_deg}")
            {
                phase_fraction = (phase_deg / range.hi).clamp(0.0, 1.0 - f64::EPSILON);
            }
        }
        v.finish()?;
        let (r2, chi, rb) = (req.r2_mm, req.chi, req.rb_mm);
        let Some(z2) = z2 else {
            return Err(crate::calc::rules::door_skipped("/Z2"));
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
            model: req.model.unwrap_or_default(),
            phase_fraction,
            n_phase,
            elements: req.include.and_then(|i| i.elements).unwrap_or(true),
        })
    }
}

impl TryFrom<IrefcEfficiencyRequest> for EfficiencyInput {
    type Error = CalcFailure;

    /// [`EfficiencyInput::try_from_request`].
    fn try_from(req: IrefcEfficiencyRequest) -> Result<Self, CalcFailure> {
        Self::try_from_request(&req)
    }
}
