//! Validation of a [`BezierMotionRequest`] into a [`BezierInput`] (spec §2), collecting every
//! offending field with its JSON pointer.

use super::compute::BezierWarning;
use super::history::HistorySpec;
use super::optimize::Objective;
use super::plant::Plant;
use super::shaper::{Baseline, Shaper, ShaperSpec};
use super::wire::{
    self, BezierMotionRequest, DAMPING, FREE_P, GAMMA, GAMMA_OVER_PHI_MAX, HISTORY_SAMPLES,
    INERTIA, J_EQ, MAX_ACCEL_DEGREE, MAX_FACTORS, MAX_INERTIAS, MOTION_TIME, ORDER_M, ObjectiveIn,
    PHI, RATIO, ROBUST_REL, STIFFNESS, STIFFNESS_FACTOR, WINDOW_AFTER,
};
use super::wire::{BaselineIn, EI_TOLERANCE, MAX_SHAPERS, ShaperIn};
use crate::calc::common::time_limit;
use crate::calc::{CalcFailure, Validator};

/// What a request computes (the request's `mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Evaluate the given law.
    Simulate,
    /// The zero (or least) residual-vibration law by the closed-form solve.
    Optimize,
}

impl From<wire::Mode> for Mode {
    fn from(m: wire::Mode) -> Self {
        match m {
            wire::Mode::Simulate => Self::Simulate,
            wire::Mode::Optimize => Self::Optimize,
        }
    }
}

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

    #[expect(
        clippy::too_many_lines,
        reason = "one flat list of field checks in request order, each a line or two; splitting \
                  it would scatter the pointers"
    )]
    fn try_from(req: BezierMotionRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let _ = time_limit(&mut v, req.time_limit_ms);
        let mut warnings = Vec::new();

        // System.
        let sys = &req.system;
        let j_eq = match (&sys.inertias_kgm2, sys.j_eq_kgm2) {
            (Some(_), Some(_)) | (None, None) => {
                v.push(
                    "/system/J_eq_kgm2",
                    "give exactly one of `inertias_kgm2` and `J_eq_kgm2`",
                );
                None
            }
            (Some(list), None) => {
                let n = list.len();
                if !(1..=MAX_INERTIAS).contains(&n) {
                    v.push(
                        "/system/inertias_kgm2",
                        format!("must hold 1..={MAX_INERTIAS} inertias, got {n}"),
                    );
                    None
                } else if v.all_in("/system/inertias_kgm2", "inertias_kgm2", list, INERTIA) {
                    let sum: f64 = list.iter().sum();
                    v.ensure(sum > 0.0, "/system/inertias_kgm2", || {
                        "the inertias must sum to > 0, got 0".to_owned()
                    })
                    .then_some(sum)
                } else {
                    None
                }
            }
            (None, Some(j)) => v
                .range("/system/J_eq_kgm2", "J_eq_kgm2", j, J_EQ)
                .then_some(j),
        };
        let k = sys.k_nm_per_rad;
        let ok_k = v.range("/system/k_Nm_per_rad", "k_Nm_per_rad", k, STIFFNESS);
        let c = sys.c_nms_per_rad;
        let ok_c = v.range("/system/c_Nms_per_rad", "c_Nms_per_rad", c, DAMPING);
        let z = sys.z;
        let ok_z = v.range("/system/z", "z", z, RATIO)
            && v.ensure(z != 0.0, "/system/z", || "z must be ≠ 0, got 0".to_owned());

        // Motion.
        let mo = &req.motion;
        let phi = match (mo.phi_rad, mo.phi_rev) {
            (Some(_), Some(_)) | (None, None) => {
                v.push(
                    "/motion/Phi_rad",
                    "give exactly one of `Phi_rad` and `Phi_rev`",
                );
                None
            }
            (Some(x), None) => nonzero(&mut v, "/motion/Phi_rad", "Phi_rad", x),
            (None, Some(x)) => {
                nonzero(&mut v, "/motion/Phi_rev", "Phi_rev", x).map(|r| r * std::f64::consts::TAU)
            }
        };
        let ok_t = v.range("/motion/T_s", "T_s", mo.t_s, MOTION_TIME);
        let ok_m = v.uint("/motion/m", "m", mo.m, ORDER_M);
        let ok_p = v.uint("/motion/p", "p", mo.p, FREE_P);
        let (m, p) = (small(mo.m), small(mo.p));
        let ok_n =
            ok_m && ok_p && v.ensure(2 * m + p - 1 <= MAX_ACCEL_DEGREE, "/motion/p", || {
                format!(
                    "N = 2m + p − 1 must be ≤ {MAX_ACCEL_DEGREE} (Bernstein conditioning), got {} \
                     (m = {m}, p = {p})",
                    2 * m + p - 1
                )
            });
        let gamma = match (&mo.gamma_rad, phi) {
            (Some(g), _) if ok_p && g.len() != p => {
                v.push(
                    "/motion/gamma_rad",
                    format!("must hold p = {p} ordinates, got {}", g.len()),
                );
                None
            }
            (Some(g), Some(phi)) if ok_p => {
                if v.all_in("/motion/gamma_rad", "gamma_rad", g, GAMMA) {
                    let lim = GAMMA_OVER_PHI_MAX * phi.abs();
                    if let Some(i) = g.iter().position(|x| x.abs() > lim) {
                        v.push(
                            format!("/motion/gamma_rad/{i}"),
                            format!("|gamma_rad[{i}]| must be ≤ 1e3·|Phi| = {lim}, got {}", g[i]),
                        );
                        None
                    } else {
                        Some(g.clone())
                    }
                } else {
                    None
                }
            }
            (None, Some(phi)) if ok_p => Some(
                (1..=p)
                    .map(|j| phi * j as f64 / (p + 1) as f64)
                    .collect::<Vec<_>>(),
            ),
            _ => None,
        };

        // Optimisation.
        let robust = match req.optimize.robust_stiffness_rel {
            Some(d)
                if v.range(
                    "/optimize/robust_stiffness_rel",
                    "robust_stiffness_rel",
                    d,
                    ROBUST_REL,
                ) =>
            {
                if req.mode == wire::Mode::Simulate {
                    warnings.push(BezierWarning::RobustIgnored);
                    None
                } else {
                    Some(d)
                }
            }
            _ => None,
        };
        let objective = match req.optimize.objective {
            ObjectiveIn::MinDeviation => Objective::MinDeviation,
            ObjectiveIn::MinAccelL2 => Objective::MinAccelL2,
            ObjectiveIn::MinJerkL2 => Objective::MinJerkL2,
        };

        // Outputs.
        let history = req.outputs.time_history.and_then(|h| {
            let a = v.uint(
                "/outputs/time_history/n_samples",
                "n_samples",
                h.n_samples,
                HISTORY_SAMPLES,
            );
            let b = v.range(
                "/outputs/time_history/t_after_s",
                "t_after_s",
                h.t_after_s,
                WINDOW_AFTER,
            );
            let c = v.uint(
                "/outputs/time_history/n_after",
                "n_after",
                h.n_after,
                HISTORY_SAMPLES,
            );
            (a && b && c && (h.n_samples > 0 || h.n_after > 0)).then_some(HistorySpec {
                n_samples: small(h.n_samples),
                t_after: h.t_after_s,
                n_after: small(h.n_after),
            })
        });
        let sensitivity = req.outputs.sensitivity.as_ref().and_then(|s| {
            let f = &s.stiffness_factors;
            if f.len() > MAX_FACTORS {
                v.push(
                    "/outputs/sensitivity/stiffness_factors",
                    format!("must hold at most {MAX_FACTORS} factors, got {}", f.len()),
                );
                return None;
            }
            v.all_in(
                "/outputs/sensitivity/stiffness_factors",
                "stiffness_factors",
                f,
                STIFFNESS_FACTOR,
            )
            .then(|| f.clone())
        });

        let shapers = req.outputs.shaper_comparison.as_ref().and_then(|sc| {
            let pointer = "/outputs/shaper_comparison/shapers";
            let n = sc.shapers.len();
            let mut ok = v.ensure((1..=MAX_SHAPERS).contains(&n), pointer, || {
                format!("must hold 1..={MAX_SHAPERS} shapers, got {n}")
            });
            for (i, s) in sc.shapers.iter().enumerate() {
                if sc.shapers[..i].contains(s) {
                    v.push(
                        format!("{pointer}/{i}"),
                        format!("shapers[{i}] repeats an earlier entry; list each shaper once"),
                    );
                    ok = false;
                }
            }
            let ok_v = v.range(
                "/outputs/shaper_comparison/ei_tolerance",
                "ei_tolerance",
                sc.ei_tolerance,
                EI_TOLERANCE,
            );
            (ok && ok_v).then(|| ShaperSpec {
                baseline: match sc.baseline {
                    BaselineIn::Trapezoid => Baseline::Trapezoid,
                    BaselineIn::Cycloidal => Baseline::Cycloidal,
                },
                shapers: sc
                    .shapers
                    .iter()
                    .map(|s| match s {
                        ShaperIn::None => Shaper::None,
                        ShaperIn::Zv => Shaper::Zv,
                        ShaperIn::Zvd => Shaper::Zvd,
                        ShaperIn::Ei => Shaper::Ei,
                    })
                    .collect(),
                ei_tolerance: sc.ei_tolerance,
            })
        });

        v.finish()?;
        match (j_eq, phi, gamma) {
            (Some(j_eq), Some(phi), Some(gamma)) if ok_k && ok_c && ok_z && ok_t && ok_n => {
                Ok(Self {
                    mode: req.mode.into(),
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
            // Every path to here pushed an issue, so `finish` has already failed.
            _ => Err(CalcFailure::general(
                crate::calc::ProblemClass::InvalidInput,
                crate::calc::INVALID_INPUT,
                "invalid request",
            )),
        }
    }
}

fn nonzero(v: &mut Validator, pointer: &str, name: &str, x: f64) -> Option<f64> {
    (v.range(pointer, name, x, PHI)
        && v.ensure(x != 0.0, pointer, || format!("{name} must be ≠ 0, got 0")))
    .then_some(x)
}
