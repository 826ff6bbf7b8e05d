//! `compute(&BezierInput, &Budget)`: the end state and residual energy in closed form, the
//! optimum by the direct linear solve, and the optional outputs (spec §3.5–3.10).

use super::error::BezierMotionError;
use super::history::{History, RHO_MAX_HISTORY, history};
use super::input::{BezierInput, Mode};
use super::kinematics::{Kinematics, kinematics, polygon_against_motion, reverses};
use super::law::BezierLaw;
use super::optimize::{LawShape, Objective, objective_terms, residual_rows, solve_terms};
use super::plant::{EndDerivatives, Plant, RHO_MAX_GL, ResponseMatrix, end_state, response_matrix};
use super::shaper::{Comparison, LawRow, Shaper, ShaperSkip, compare};
use crate::numerics::Budget;

/// `E_floor = ½ J_eq (FLOOR_ULPS · ε · s_x)²` (spec §3.6).
pub const FLOOR_ULPS: f64 = 64.0;
/// Warn when `max |γ| / |Phi|` exceeds this (spec §3.7).
pub const GAMMA_WARN: f64 = 10.0;

/// A warning about the request or its answer, in domain terms (`output.rs` words it for the wire
/// with the spec's code).
#[derive(Debug, Clone, PartialEq)]
pub enum BezierWarning {
    /// `robust_stiffness_rel` was given in `simulate` mode and is ignored.
    RobustIgnored,
    /// Only `rank` of `n_constraints` zero-vibration conditions can be met with `p` free ordinates.
    LeastSquaresCompromise {
        /// Numerical rank of the constraints.
        rank: usize,
        /// Constraint rows.
        n_constraints: usize,
        /// Free ordinates.
        p: usize,
    },
    /// `max |γ| / |Phi|` exceeds [`GAMMA_WARN`].
    FragilePolygon {
        /// `max |γ| / |Phi|`.
        gamma_over_phi: f64,
    },
    /// The motor velocity changes sign during the move.
    MotionReversal,
    /// The velocity polygon has an ordinate against the motion; the curve does not reverse.
    VelocityPolygonNegative,
    /// ξ ≥ 1: the joint does not oscillate.
    NotOscillatory {
        /// Damping ratio.
        xi: f64,
    },
    /// A shaper comparison was asked for a drive with ξ ≥ 1 (no damped period): omitted.
    ShaperNotOscillatory {
        /// Damping ratio.
        xi: f64,
    },
    /// A shaper lasts the whole move or longer: its row is empty.
    ShaperTooLong {
        /// Index of the shaper in the request.
        index: usize,
        /// The shaper.
        shaper: Shaper,
        /// Its last impulse time \[s\].
        t_last: f64,
        /// The move time \[s\].
        t: f64,
    },
}

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
        Self::from_state(plant, h.apply(a), a, t)
    }

    /// The residual of the law with acceleration ordinates `a` whose end state is `x`.
    #[must_use]
    pub fn from_state(plant: &Plant, x: [f64; 2], a: &[f64], t: f64) -> Self {
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
    /// The shaper comparison.
    pub shapers: Option<Comparison>,
    /// Warnings (domain terms; `output.rs` words them).
    pub warnings: Vec<BezierWarning>,
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
    admissible(plant)?;
    response_matrix(plant, n, t).ok_or_else(|| too_large(plant, t, pointer))
}

/// Refuses a drive whose natural frequency is 0, not finite or whose ξ is NaN.
fn admissible(plant: &Plant) -> Result<(), BezierMotionError> {
    if !(plant.wn > 0.0 && plant.wn.is_finite()) || plant.xi.is_nan() {
        return Err(BezierMotionError::NonFinite {
            what: "natural frequency of the drive with the scaled stiffness k·f",
        });
    }
    Ok(())
}

fn too_large(plant: &Plant, t: f64, pointer: String) -> BezierMotionError {
    BezierMotionError::RhoTooLarge {
        rho_max: t * plant.pole_magnitudes().1,
        limit: RHO_MAX_GL,
        xi: plant.xi,
        pointer,
    }
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
    warnings: &mut Vec<BezierWarning>,
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
    let terms = objective_terms(input.objective, shape, &input.gamma);
    let sol = solve_terms(&terms, &rows).map_err(|_| BezierMotionError::ObjectiveSingular {
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
        warnings.push(BezierWarning::LeastSquaresCompromise {
            rank: sol.rank,
            n_constraints: sol.n_constraints,
            p: input.p,
        });
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
            input.t,
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
    let shapers = match &input.shapers {
        None => None,
        Some(_) => shaper_comparison(
            input,
            &law,
            (&residual, kin.as_ref(), sensitivity.as_deref()),
            &mut warnings,
        )?,
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
        shapers,
        warnings,
        matrices,
    })
}

/// The shaper comparison of `input.shapers` beside `law` (its residual, peaks and sweep reused);
/// `None` with a warning for ξ ≥ 1.
fn shaper_comparison(
    input: &BezierInput,
    law: &BezierLaw,
    (residual, kin, sweep): (&Residual, Option<&Kinematics>, Option<&[FactorResult]>),
    warnings: &mut Vec<BezierWarning>,
) -> Result<Option<Comparison>, BezierMotionError> {
    let Some(spec) = &input.shapers else {
        return Ok(None);
    };
    let plant = &input.plant;
    let (td, rows, skips) = match compare(
        plant,
        spec,
        (input.phi, input.t),
        input.sensitivity.as_deref(),
    ) {
        Ok(r) => r,
        Err(ShaperSkip::NotOscillatory { xi }) => {
            warnings.push(BezierWarning::ShaperNotOscillatory { xi });
            return Ok(None);
        }
        Err(ShaperSkip::TooLong { .. }) => return Ok(None),
    };
    for s in skips {
        if let ShaperSkip::TooLong { shaper, t_last, t } = s {
            let index = spec.shapers.iter().position(|x| *x == shaper).unwrap_or(0);
            warnings.push(BezierWarning::ShaperTooLong {
                index,
                shaper,
                t_last,
                t,
            });
        }
    }
    let finite = rows.iter().flatten().all(|r| {
        r.energy.is_finite()
            && r.sensitivity
                .as_ref()
                .is_none_or(|s| s.iter().all(|(_, e)| e.is_finite()))
    });
    if !finite {
        return Err(BezierMotionError::NonFinite {
            what: "residual energy of a shaped move",
        });
    }
    let own;
    let k = match kin {
        Some(k) => k,
        None => {
            own = kinematics(law);
            &own
        }
    };
    Ok(Some(Comparison {
        spec: spec.clone(),
        td,
        rows,
        law: LawRow {
            energy: residual.energy,
            peak_accel: k.peak_accel.0,
            peak_vel: k.peak_velocity.0,
            sensitivity: sweep.map(|s| s.iter().map(|f| (f.factor, f.residual.energy)).collect()),
        },
    }))
}

/// The residual of `law` with the joint stiffness scaled by each of `factors` (the sensitivity
/// sweep), counting the matrices built in `matrices` and checking the budget before each one.
fn sensitivity(
    plant: &Plant,
    t: f64,
    law: &BezierLaw,
    factors: &[f64],
    budget: &Budget,
    matrices: &mut u64,
) -> Result<Vec<FactorResult>, BezierMotionError> {
    let mut out = Vec::with_capacity(factors.len());
    // The law's end derivatives are computed once; each factor then costs O(N) on the IBP path.
    let ends = EndDerivatives::new(&law.a);
    for (i, &f) in factors.iter().enumerate() {
        if budget.check(*matrices).is_some() {
            return Err(BezierMotionError::Deadline {
                stage: "sensitivity sweep",
            });
        }
        let pf = plant.with_stiffness_factor(f);
        admissible(&pf)?;
        let x = end_state(&pf, &ends, t).ok_or_else(|| {
            too_large(
                &pf,
                t,
                format!("/outputs/sensitivity/stiffness_factors/{i}"),
            )
        })?;
        *matrices += 1;
        out.push(FactorResult {
            factor: f,
            plant: pf,
            residual: Residual::from_state(&pf, x, &law.a, t),
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
    warnings: &mut Vec<BezierWarning>,
) {
    let gmax = gamma.iter().fold(0.0_f64, |m, g| m.max(g.abs())) / input.phi.abs();
    if gmax > GAMMA_WARN {
        warnings.push(BezierWarning::FragilePolygon {
            gamma_over_phi: gmax,
        });
    }
    if polygon_against_motion(law) {
        // The peaks' own check when they were computed (the same samples and refinements).
        if kin.map_or_else(|| reverses(law), |k| k.motion_reversal) {
            warnings.push(BezierWarning::MotionReversal);
        } else {
            warnings.push(BezierWarning::VelocityPolygonNegative);
        }
    }
    if plant.xi >= 1.0 {
        warnings.push(BezierWarning::NotOscillatory { xi: plant.xi });
    }
}
