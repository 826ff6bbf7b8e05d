//! `compute(&BezierInput, &Budget)`: the end state and residual energy in closed form, the
//! optimum by the direct linear solve, and the optional outputs (spec §3.5–3.10).

use super::error::BezierMotionError;
use super::history::{History, RHO_MAX_HISTORY, history};
use super::input::{BezierInput, Mode};
use super::kinematics::{Kinematics, kinematics, polygon_against_motion, reverses};
use super::law::BezierLaw;
use super::optimize::{LawShape, Objective, objective_terms, residual_rows, solve};
use super::plant::{Plant, RHO_MAX_GL, ResponseMatrix, response_matrix};
use crate::calc::common::Warning;
use crate::numerics::Budget;

/// `E_floor = ½ J_eq (FLOOR_ULPS · ε · s_x)²` (spec §3.6).
pub const FLOOR_ULPS: f64 = 64.0;
/// Warn when `max |γ| / |Phi|` exceeds this (spec §3.7).
pub const GAMMA_WARN: f64 = 10.0;

/// Residual vibration of one law on one plant (spec §3.6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Residual {
    /// `x(T) = [ψ(T), ψ'(T)]`.
    pub x: [f64; 2],
    /// `E(T)` \[J\].
    pub energy: f64,
    /// `Q = (ωd/z)² (ψ'² + ωn²ψ²)` (ξ < 1).
    pub q: Option<f64>,
    /// Residual amplitude R \[rad\] (ξ < 1).
    pub amplitude: Option<f64>,
    /// Round-off floor of E \[J\].
    pub floor: f64,
}

impl Residual {
    /// The residual of the law with acceleration ordinates `a` on `plant`, given its `H`.
    #[must_use]
    pub fn of(plant: &Plant, h: &ResponseMatrix, a: &[f64], t: f64) -> Self {
        let x = h.apply(a);
        let energy = plant.energy(x);
        let q = plant.omega_d().map(|wd| {
            let s = wd / plant.z;
            let (g, f) = (s * x[1], s * plant.wn * x[0]);
            g * g + f * f
        });
        let amax = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let sx = plant.z.abs() * amax * t.min(1.0 / plant.wn);
        let fl = FLOOR_ULPS * f64::EPSILON * sx;
        Self {
            x,
            energy,
            q,
            amplitude: plant.amplitude(x),
            floor: 0.5 * plant.j_eq * fl * fl,
        }
    }
}

/// The solve's summary (optimize mode).
#[derive(Debug, Clone, PartialEq)]
pub struct OptimizerResult {
    /// Objective used.
    pub objective: Objective,
    /// Constraint rows.
    pub n_constraints: usize,
    /// Numerical rank.
    pub rank: usize,
    /// Lagrange multipliers.
    pub mu: Vec<f64>,
    /// The reference law.
    pub reference_gamma: Vec<f64>,
    /// Its residual.
    pub reference: Residual,
}

/// One stiffness factor's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorResult {
    /// Factor f.
    pub factor: f64,
    /// The scaled plant.
    pub plant: Plant,
    /// Residual of the returned law on it.
    pub residual: Residual,
}

/// Everything the response is built from.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierOutput {
    /// The returned law.
    pub law: BezierLaw,
    /// Its free ordinates.
    pub gamma: Vec<f64>,
    /// Response matrix of the nominal plant.
    pub h: ResponseMatrix,
    /// Residual of the returned law.
    pub residual: Residual,
    /// Optimize mode: the solve.
    pub optimizer: Option<OptimizerResult>,
    /// Robust extension: residual at k(1−δ), k, k(1+δ).
    pub robust: Option<Vec<FactorResult>>,
    /// Kinematic peaks.
    pub kinematics: Option<Kinematics>,
    /// Sensitivity sweep.
    pub sensitivity: Option<Vec<FactorResult>>,
    /// Time history.
    pub history: Option<History>,
    /// Warnings.
    pub warnings: Vec<Warning>,
    /// Response matrices built.
    pub matrices: u64,
}

/// The nominal `H`, or the typed error of spec §2 when the GL path would exceed its limit.
///
/// A stiffness factor can underflow `k·f` to 0 at the bottom of the `k` range (`ωn = 0`, ξ
/// infinite or 0/0): that drive has no response matrix and is refused as non-finite.
fn matrix_for(
    plant: &Plant,
    n: usize,
    t: f64,
    pointer: String,
) -> Result<ResponseMatrix, BezierMotionError> {
    if !(plant.wn > 0.0 && plant.wn.is_finite()) || plant.xi.is_nan() {
        return Err(BezierMotionError::NonFinite {
            what: "natural frequency of the drive with the scaled stiffness k·f",
        });
    }
    response_matrix(plant, n, t).ok_or_else(|| BezierMotionError::RhoTooLarge {
        rho_max: t * plant.pole_magnitudes().1,
        limit: RHO_MAX_GL,
        xi: plant.xi,
        pointer,
    })
}

/// Control points, optimizer report and robust results of [`optimize`].
type Optimized = (Vec<f64>, Option<OptimizerResult>, Option<Vec<FactorResult>>);

/// The zero-vibration law of `Mode::Optimize`: the constrained least-squares
/// solve for `input.objective` (with the robust variant's two extra stiffness factors), the
/// reference law's residual, and the robust residuals at the three factors. Returns the
/// optimal control points, the optimizer's report and the robust results.
fn optimize(
    input: &BezierInput,
    plant: Plant,
    (h, shape, n): (&ResponseMatrix, &LawShape, usize),
    matrices: &mut u64,
    warnings: &mut Vec<Warning>,
) -> Result<Optimized, BezierMotionError> {
    let mut rows = vec![residual_rows(&plant, h, shape)];
    let mut robust_plants = Vec::new();
    if let Some(d) = input.robust {
        for f in [1.0 - d, 1.0 + d] {
            let pf = plant.with_stiffness_factor(f);
            let hf = matrix_for(&pf, n, input.t, "/optimize/robust_stiffness_rel".into())?;
            *matrices += 1;
            rows.push(residual_rows(&pf, &hf, shape));
            robust_plants.push((f, pf, hf));
        }
    }
    let (hq, f) = objective_terms(input.objective, shape, &input.gamma);
    let sol = solve(&hq, &f, &rows).map_err(|_| BezierMotionError::ObjectiveSingular {
        objective: match input.objective {
            Objective::MinDeviation => "min_deviation",
            Objective::MinAccelL2 => "min_accel_l2",
            Objective::MinJerkL2 => "min_jerk_l2",
        },
    })?;
    let ref_law = BezierLaw::new(input.m, input.phi, &input.gamma, input.t);
    let reference = Residual::of(&plant, h, &ref_law.a, input.t);
    let law = BezierLaw::new(input.m, input.phi, &sol.gamma, input.t);
    let robust = input.robust.map(|_| {
        let mut out: Vec<FactorResult> = robust_plants
            .iter()
            .map(|(f, pf, hf)| FactorResult {
                factor: *f,
                plant: *pf,
                residual: Residual::of(pf, hf, &law.a, input.t),
            })
            .collect();
        out.insert(
            1,
            FactorResult {
                factor: 1.0,
                plant,
                residual: Residual::of(&plant, h, &law.a, input.t),
            },
        );
        out
    });
    if sol.rank < sol.n_constraints {
        warnings.push(Warning::new(
            "LEAST_SQUARES_COMPROMISE",
            format!(
                "only {} of {} zero-vibration conditions can be met (p = {}): the law \
                 is the least-squares compromise, not exactly vibration-free",
                sol.rank, sol.n_constraints, input.p
            ),
        ));
    }
    Ok((
        sol.gamma.clone(),
        Some(OptimizerResult {
            objective: input.objective,
            n_constraints: sol.n_constraints,
            rank: sol.rank,
            mu: sol.mu,
            reference_gamma: input.gamma.clone(),
            reference,
        }),
        robust,
    ))
}

/// Run the calculation (spec §3).
///
/// # Errors
/// [`BezierMotionError`] for a too-fast pole on the Gauss–Legendre or history path, a singular
/// L2 objective, an overflow at the extremes of the ranges, or an exhausted budget.
pub fn compute(input: &BezierInput, budget: &Budget) -> Result<BezierOutput, BezierMotionError> {
    let plant = input.plant;
    let shape = LawShape {
        m: input.m,
        p: input.p,
        phi: input.phi,
        t: input.t,
    };
    let n = shape.accel_degree();
    let rho_max = input.t * plant.pole_magnitudes().1;
    if input.history.is_some_and(|h| h.n_samples > 1) && rho_max > RHO_MAX_HISTORY {
        return Err(BezierMotionError::HistoryTooLarge {
            rho_max,
            limit: RHO_MAX_HISTORY,
        });
    }
    let h = matrix_for(&plant, n, input.t, "/system/c_Nms_per_rad".to_owned())?;
    let mut matrices = 1_u64;
    let mut warnings = input.warnings.clone();
    let (gamma, optimizer, robust) = match input.mode {
        Mode::Simulate => (input.gamma.clone(), None, None),
        Mode::Optimize => optimize(input, plant, (&h, &shape, n), &mut matrices, &mut warnings)?,
    };
    let law = BezierLaw::new(input.m, input.phi, &gamma, input.t);
    // Recompute the end state from the law itself (never trust the affine model's residual).
    let residual = Residual::of(&plant, &h, &law.a, input.t);
    if !residual.energy.is_finite() || law.a.iter().any(|a| !a.is_finite()) {
        return Err(BezierMotionError::NonFinite {
            what: "residual energy",
        });
    }
    let kin = input.kinematics.then(|| kinematics(&law));
    law_warnings(input, &plant, &law, (&gamma, kin.as_ref()), &mut warnings);
    let sensitivity = match &input.sensitivity {
        None => None,
        Some(factors) => Some(sensitivity(
            &plant,
            (n, input.t),
            &law,
            factors,
            budget,
            &mut matrices,
        )?),
    };
    let history = match &input.history {
        None => None,
        Some(spec) => Some(history(&plant, &law, residual.x, spec, budget).ok_or(
            BezierMotionError::Deadline {
                stage: "time history",
            },
        )?),
    };
    Ok(BezierOutput {
        law,
        gamma,
        h,
        residual,
        optimizer,
        robust,
        kinematics: kin,
        sensitivity,
        history,
        warnings,
        matrices,
    })
}

/// The residual of `law` with the joint stiffness scaled by each of `factors` (the sensitivity
/// sweep), counting the matrices built in `matrices` and checking the budget before each one.
fn sensitivity(
    plant: &Plant,
    (n, t): (usize, f64),
    law: &BezierLaw,
    factors: &[f64],
    budget: &Budget,
    matrices: &mut u64,
) -> Result<Vec<FactorResult>, BezierMotionError> {
    let mut out = Vec::with_capacity(factors.len());
    for (i, &f) in factors.iter().enumerate() {
        if budget.check(*matrices).is_some() {
            return Err(BezierMotionError::Deadline {
                stage: "sensitivity sweep",
            });
        }
        let pf = plant.with_stiffness_factor(f);
        let hf = matrix_for(
            &pf,
            n,
            t,
            format!("/outputs/sensitivity/stiffness_factors/{i}"),
        )?;
        *matrices += 1;
        out.push(FactorResult {
            factor: f,
            plant: pf,
            residual: Residual::of(&pf, &hf, &law.a, t),
        });
        budget.progress((i + 1) as f64 / factors.len() as f64, None);
    }
    Ok(out)
}

/// The law's warnings (spec §3.7, §2): fragile polygon, reversal, negative velocity ordinate,
/// non-oscillating system.
fn law_warnings(
    input: &BezierInput,
    plant: &Plant,
    law: &BezierLaw,
    (gamma, kin): (&[f64], Option<&Kinematics>),
    warnings: &mut Vec<Warning>,
) {
    let gmax = gamma.iter().fold(0.0_f64, |m, g| m.max(g.abs())) / input.phi.abs();
    if gmax > GAMMA_WARN {
        warnings.push(Warning::new(
            "FRAGILE_POLYGON",
            format!(
                "max |γ|/|Phi| = {gmax:.4e} > {GAMMA_WARN}: a strongly oscillating control polygon \
                 (numerically fragile even though the curve is smooth)"
            ),
        ));
    }
    if polygon_against_motion(law) {
        // The peaks' own check when they were computed (the same samples and refinements).
        if kin.map_or_else(|| reverses(law), |k| k.motion_reversal) {
            warnings.push(Warning::new(
                "MOTION_REVERSAL",
                "the motor velocity changes sign during the move (the law reverses)",
            ));
        } else {
            warnings.push(Warning::new(
                "VELOCITY_POLYGON_NEGATIVE",
                "the velocity control polygon has an ordinate against the direction of motion; \
                 the curve itself does not reverse",
            ));
        }
    }
    if plant.xi >= 1.0 {
        warnings.push(Warning::new(
            "NOT_OSCILLATORY",
            format!(
                "ξ = {:.6} ≥ 1: the joint does not oscillate; ωd, η, Q and amplitude outputs are \
                 omitted",
                plant.xi
            ),
        ));
    }
}
