//! Conversion of a [`BezierMotionRequest`] into a [`BezierInput`] (spec §2). The per-field rules
//! (ranges, list lengths, exactly one of `inertias_kgm2`/`J_eq_kgm2` and of `Phi_rad`/`Phi_rev`)
//! are `#[rule]`s on the wire types, checked at the door; this file keeps only what JSON Schema
//! cannot state, each rule with its own code ([`CROSS_FIELD_RULES`]).

use super::compute::BezierWarning;
use super::error::{
    DEADLINE_RULE, HISTORY_TOO_LARGE_RULE, NON_FINITE_RESULT_RULE, OBJECTIVE_SINGULAR_RULE,
    RHO_TOO_LARGE_RULE,
};
use super::history::HistorySpec;
use super::optimize::Objective;
use super::plant::Plant;
use super::shaper::ShaperSpec;
use super::wire::{
    self, BezierMotionRequest, FREE_P, GAMMA_OVER_PHI_MAX, MAX_ACCEL_DEGREE, ORDER_M, ObjectiveIn,
};
use crate::calc::rules::door_skipped;
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, Validator};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/bezier-motion-law`, and every code its computation can
    /// answer a schema-valid request with, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid INERTIA_SUM("INERTIA_SUM_ZERO") ["/system/inertias_kgm2"]
        "The inertias in inertias_kgm2 sum to > 0 (each is ≥ 0).";
    invalid RATIO_NONZERO("ZERO_RATIO") ["/system/z"] "The reducer ratio z is ≠ 0.";
    invalid ROTATION_NONZERO("ZERO_ROTATION") ["/motion/Phi_rad", "/motion/Phi_rev"]
        "The total motor rotation (Phi_rad or Phi_rev) is ≠ 0.";
    invalid DEGREE("DEGREE_TOO_HIGH") ["/motion/m", "/motion/p"]
        "N = 2m + p − 1 ≤ 30 (Bernstein conditioning, spec §6).";
    invalid GAMMA_LENGTH ["/motion/gamma_rad", "/motion/p"] "gamma_rad holds exactly p ordinates.";
    invalid GAMMA_SCALE("GAMMA_OUT_OF_SCALE") ["/motion/gamma_rad/*", "/motion/Phi_rad",
        "/motion/Phi_rev"] "Each |gamma_rad[j]| ≤ 1e3·|Phi| (Phi in rad).";
    invalid SHAPER_REPEATED ["/outputs/shaper_comparison/shapers/*"]
        "Each shaper of shaper_comparison.shapers is listed at most once.";
    listed RHO_TOO_LARGE_RULE;
    listed HISTORY_TOO_LARGE_RULE;
    listed OBJECTIVE_SINGULAR_RULE;
    listed NON_FINITE_RESULT_RULE;
    listed DEADLINE_RULE;
    listed crate::calc::common::RESPONSE_TOO_LARGE_RULE;
}

/// What a request computes: the request's `mode`.
pub use super::wire::Mode;

/// A validated request in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierInput {
    /// Simulate or optimise.
    pub mode: Mode,
    /// The drive.
    pub plant: Plant,
    /// Total motor rotation \[rad\].
    pub phi: f64,
    /// Motion time \[s\].
    pub t: f64,
    /// Order of vanishing end derivatives.
    pub m: usize,
    /// Free interior ordinates.
    pub p: usize,
    /// γ \[rad\]: the law (simulate) or the reference law (optimize).
    pub gamma: Vec<f64>,
    /// Secondary objective.
    pub objective: Objective,
    /// Robust extension δ (optimize only).
    pub robust: Option<f64>,
    /// Compute kinematic peaks.
    pub kinematics: bool,
    /// Time history, when samples are asked for.
    pub history: Option<HistorySpec>,
    /// Stiffness factors of the sensitivity sweep.
    pub sensitivity: Option<Vec<f64>>,
    /// The shaper comparison, when asked for.
    pub shapers: Option<ShaperSpec>,
    /// Warnings raised during validation.
    pub warnings: Vec<BezierWarning>,
}

/// `usize` of a validated small integer.
fn small(x: u64) -> usize {
    usize::try_from(x).unwrap_or(usize::MAX)
}

impl TryFrom<BezierMotionRequest> for BezierInput {
    type Error = CalcFailure;

    fn try_from(req: BezierMotionRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let mut warnings = Vec::new();

        // System: exactly one inertia form and every range were checked at the door.
        let sys = &req.system;
        let j_eq = match (&sys.inertias_kgm2, sys.j_eq_kgm2) {
            (Some(list), None) => {
                let sum: f64 = list.iter().sum();
                ensure_rule!(v, sum > 0.0, INERTIA_SUM, "/system/inertias_kgm2";
                    "the inertias must sum to > 0 kg m², got 0");
                sum
            }
            (None, Some(j)) => j,
            _ => return Err(door_skipped("/system/J_eq_kgm2")),
        };
        let (k, c, z) = (sys.k_nm_per_rad, sys.c_nms_per_rad, sys.z);
        ensure_rule!(v, z != 0.0, RATIO_NONZERO, "/system/z"; "z must be ≠ 0, got 0");

        // Motion.
        let mo = &req.motion;
        let (phi, phi_pointer, phi_name) = match (mo.phi_rad, mo.phi_rev) {
            (Some(x), None) => (x, "/motion/Phi_rad", "Phi_rad"),
            (None, Some(x)) => (x * std::f64::consts::TAU, "/motion/Phi_rev", "Phi_rev"),
            _ => return Err(door_skipped("/motion/Phi_rad")),
        };
        let ok_phi = ensure_rule!(v, phi != 0.0, ROTATION_NONZERO, phi_pointer;
            "{phi_name} must be ≠ 0, got 0");
        if !(ORDER_M.contains(mo.m as f64) && FREE_P.contains(mo.p as f64)) {
            return Err(door_skipped("/motion/m"));
        }
        let (m, p) = (small(mo.m), small(mo.p));
        ensure_rule!(v, 2 * m + p - 1 <= MAX_ACCEL_DEGREE, DEGREE, "/motion/p";
            "N = 2m + p − 1 must be ≤ {MAX_ACCEL_DEGREE} (Bernstein conditioning), got {} \
                 (m = {m}, p = {p})",
            2 * m + p - 1);
        let gamma = match &mo.gamma_rad {
            Some(g) if g.len() != p => {
                rule!(v, GAMMA_LENGTH, "/motion/gamma_rad";
                    "must hold p = {p} ordinates, got {}", g.len());
                Vec::new()
            }
            Some(g) => {
                let lim = GAMMA_OVER_PHI_MAX * phi.abs();
                if ok_phi && let Some(i) = g.iter().position(|x| x.abs() > lim) {
                    rule!(v, GAMMA_SCALE, format!("/motion/gamma_rad/{i}");
                        "|gamma_rad[{i}]| [rad] must be ≤ 1e3·|Phi| = {lim}, got {}", g[i]);
                }
                g.clone()
            }
            None => (1..=p)
                .map(|j| phi * j as f64 / (p + 1) as f64)
                .collect::<Vec<_>>(),
        };

        // Optimisation.
        let robust = match req.optimize.robust_stiffness_rel {
            Some(_) if req.mode == wire::Mode::Simulate => {
                warnings.push(BezierWarning::RobustIgnored);
                None
            }
            d => d,
        };
        let objective = match req.optimize.objective {
            ObjectiveIn::MinDeviation => Objective::MinDeviation,
            ObjectiveIn::MinAccelL2 => Objective::MinAccelL2,
            ObjectiveIn::MinJerkL2 => Objective::MinJerkL2,
        };

        // Outputs.
        let history = req
            .outputs
            .time_history
            .filter(|h| h.n_samples > 0 || h.n_after > 0)
            .map(|h| HistorySpec {
                n_samples: small(h.n_samples),
                t_after: h.t_after_s,
                n_after: small(h.n_after),
            });
        let sensitivity = req
            .outputs
            .sensitivity
            .as_ref()
            .map(|s| s.stiffness_factors.clone());
        let shapers = req
            .outputs
            .shaper_comparison
            .as_ref()
            .map(|sc| shaper_spec(sc, &mut v));

        v.finish()?;
        Ok(Self {
            mode: req.mode,
            plant: Plant::new(j_eq, k, c, z),
            phi,
            t: mo.t_s,
            m,
            p,
            gamma,
            objective,
            robust,
            kinematics: req.outputs.kinematic_peaks,
            history,
            sensitivity,
            shapers,
            warnings,
        })
    }
}

/// The shaper comparison's settings; each shaper at most once ([`SHAPER_REPEATED`]).
fn shaper_spec(sc: &wire::ShaperComparisonIn, v: &mut Validator) -> ShaperSpec {
    for (i, s) in sc.shapers.iter().enumerate() {
        if sc.shapers[..i].contains(s) {
            rule!(v, SHAPER_REPEATED, format!("/outputs/shaper_comparison/shapers/{i}");
                "shapers[{i}] repeats an earlier entry; list each shaper once");
        }
    }
    ShaperSpec {
        baseline: sc.baseline,
        shapers: sc.shapers.clone(),
        ei_tolerance: sc.ei_tolerance,
    }
}
