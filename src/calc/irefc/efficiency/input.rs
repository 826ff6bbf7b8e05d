//! Validation of an [`IrefcEfficiencyRequest`] into SI domain input, collecting every issue.

use std::f64::consts::PI;

use super::wire::{EfficiencyModel, IrefcEfficiencyRequest};
use crate::calc::CalcFailure;
use crate::calc::irefc::error::{AMBIGUOUS_LOAD, IrefcError, Issues};
use crate::calc::irefc::geometry::Geometry;
use crate::calc::irefc::wire::{MM, check_chi, check_r2, check_rb, check_z2, missing};

/// Largest input power [W] (spec).
pub const POWER_MAX_W: f64 = 1e8;
/// Largest input torque [N·m] (same scale as the stress endpoint's torque limit).
pub const INPUT_TORQUE_MAX_NM: f64 = 1e7;
/// Largest input speed [rpm] (spec).
pub const SPEED_MAX_RPM: f64 = 1e6;
/// Largest rolling-friction lever arm [mm] (spec).
pub const ROLLING_FRICTION_MAX_MM: f64 = 10.0;
/// The paper's rolling-friction lever arm μ = 0.001 m [mm].
pub const ROLLING_FRICTION_PAPER_MM: f64 = 1.0;
/// Rolling-friction lever arms above this [mm] get `ROLLING_FRICTION_HIGH` (largest tabulated steel value).
pub const ROLLING_FRICTION_HIGH_MM: f64 = 0.5;
/// The paper's sliding friction coefficient.
pub const SLIDING_FRICTION_PAPER: f64 = 0.1;
/// Largest number of cage phases (spec).
pub const N_PHASE_MAX: u32 = 10_000;

/// Validated efficiency input [SI].
#[derive(Debug, Clone, PartialEq)]
pub struct EfficiencyInput {
    /// Geometry (feasible).
    pub geometry: Geometry,
    /// Input speed ω1 [rad/s].
    pub omega1: f64,
    /// Input torque M_in [N·m].
    pub m_in: f64,
    /// Input power P_in = M_in·ω1 [W].
    pub p_in: f64,
    /// Rolling-friction lever arm μ [m].
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
        let mut is = Issues::new();
        let r2 = check_r2(&mut is, "/r2_mm", req.r2_mm);
        let z2 = check_z2(&mut is, "/Z2", req.z2);
        let chi = check_chi(&mut is, "/chi", req.chi);
        let rb = check_rb(&mut is, "/rb_mm", req.rb_mm);
        match (req.power_w, req.input_torque_nm) {
            (Some(_), Some(_)) => is.push(
                AMBIGUOUS_LOAD,
                "/input_torque_Nm",
                "give either power_W or input_torque_Nm, not both",
            ),
            (None, None) => missing(&mut is, "/power_W", "power_W (or input_torque_Nm)"),
            (Some(p), None) => {
                is.range_open_lo("/power_W", "input power power_W", p, 0.0, POWER_MAX_W);
            }
            (None, Some(m)) => {
                is.range_open_lo(
                    "/input_torque_Nm",
                    "input torque input_torque_Nm",
                    m,
                    0.0,
                    INPUT_TORQUE_MAX_NM,
                );
            }
        }
        is.range_open_lo(
            "/speed_rpm",
            "input speed speed_rpm",
            req.speed_rpm,
            0.0,
            SPEED_MAX_RPM,
        );
        let mu_mm = req.rolling_friction_mm.unwrap_or(ROLLING_FRICTION_PAPER_MM);
        is.range(
            "/rolling_friction_mm",
            "rolling friction lever arm",
            mu_mm,
            0.0,
            ROLLING_FRICTION_MAX_MM,
        );
        let fs = req.sliding_friction.unwrap_or(SLIDING_FRICTION_PAPER);
        is.range(
            "/sliding_friction",
            "sliding friction coefficient",
            fs,
            0.0,
            1.0,
        );
        let n_phase = req.n_phase.unwrap_or(1);
        is.ensure((1..=N_PHASE_MAX).contains(&n_phase), "/n_phase", || {
            format!("n_phase must be in [1, {N_PHASE_MAX}], got {n_phase}")
        });
        let phase_deg = req.phase_deg.unwrap_or(0.0);
        let mut phase_fraction = 0.0;
        if let Some(z) = z2 {
            let pitch = 360.0 / f64::from(z);
            if is.range_open_hi("/phase_deg", "cage phase phase_deg", phase_deg, 0.0, pitch) {
                phase_fraction = (phase_deg / pitch).clamp(0.0, 1.0 - f64::EPSILON);
            }
        }
        is.finish()?;
        let (Some(r2), Some(z2), Some(chi), Some(rb)) = (r2, z2, chi, rb) else {
            return Err(CalcFailure::general(
                crate::calc::ProblemClass::InvalidInput,
                "BAD_RANGE",
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
            model: req.model.unwrap_or_default(),
            phase_fraction,
            n_phase,
            elements: req.include.and_then(|i| i.elements).unwrap_or(true),
        })
    }
}
