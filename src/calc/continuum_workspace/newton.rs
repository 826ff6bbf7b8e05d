//! Newton's method on the full FK residual with backtracking (spec 4.2), the tangent predictor and
//! the home continuation (spec 4.3).

use super::model::{Eval, Model, Params};
use crate::numerics::dense::{self, Lu};
use crate::numerics::{Budget, StopReason};

/// Armijo constant of the backtracking line search (spec 4.2).
const ARMIJO: f64 = 1e-4;
/// Smallest line-search step (spec 4.2: halve down to 1e-4).
const MIN_STEP: f64 = 1e-4;

/// Newton settings.
#[derive(Debug, Clone, Copy)]
pub struct NewtonOptions {
    /// Stop when `||g||_inf < tol`.
    pub tol: f64,
    /// Newton iterations per solve.
    pub max_iter: usize,
    /// Give up when the residual 2-norm has not halved over this many iterations (None: never).
    pub stall_window: Option<usize>,
}

impl NewtonOptions {
    /// Settings without the stall exit.
    #[must_use]
    pub fn new(tol: f64, max_iter: usize) -> Self {
        Self {
            tol,
            max_iter,
            stall_window: None,
        }
    }
}

/// Why a Newton solve failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NewtonFailure {
    /// `max_iter` reached.
    MaxIterations,
    /// No step length down to 1e-4 decreased the residual.
    LineSearch,
    /// The residual did not halve over `stall_window` iterations.
    Stall,
    /// The starting point already gives a non-finite residual.
    NonFinite,
    /// The request's time or evaluation budget ran out.
    Budget(StopReason),
}

/// A converged FK solution with everything needed downstream.
#[derive(Debug, Clone)]
pub struct Solution {
    /// Unknown vector.
    pub v: Vec<f64>,
    /// Residual, Jacobian, tips and forces at `v`.
    pub eval: Eval,
    /// LU of the Jacobian at `v`.
    pub lu: Lu,
    /// RK4 steps used per rod.
    pub steps: Vec<usize>,
    /// Newton iterations taken.
    pub iterations: usize,
}

/// A failed solve: the reason, the last iterate and its residual.
#[derive(Debug, Clone)]
pub struct Failed {
    /// Why.
    pub reason: NewtonFailure,
    /// Last iterate.
    pub v: Vec<f64>,
    /// `||g||_inf` at the last iterate.
    pub residual_inf: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// Fraction of a continuation path completed before the failure (0 outside continuation).
    pub progress: f64,
}

/// Counts rod-system evaluations (one residual, with or without Jacobian).
#[derive(Debug, Default, Clone, Copy)]
pub struct Counter {
    /// Residual evaluations.
    pub evaluations: u64,
}

/// Newton from `v0`. Step counts follow the rule of spec 4.1 at the start point and are raised
/// (never lowered) if the converged point asks for more; the discrete map is fixed within a pass.
pub fn solve(
    model: &Model,
    p: &Params,
    v0: &[f64],
    opts: NewtonOptions,
    budget: &Budget,
    counter: &mut Counter,
) -> Result<Solution, Failed> {
    let n = model.n_unknowns();
    let mut v = v0.to_vec();
    let mut steps = model.steps_for(&v);
    let mut eval = model.evaluate(&v, p, &steps, true);
    counter.evaluations += 1;
    let mut iterations = 0usize;
    let mut history: Vec<f64> = Vec::with_capacity(opts.max_iter + 1);
    if !eval.norm2().is_finite() {
        return Err(Failed {
            reason: NewtonFailure::NonFinite,
            v,
            residual_inf: f64::INFINITY,
            iterations,
            progress: 0.0,
        });
    }
    loop {
        let res = eval.norm_inf();
        if res < opts.tol {
            // Converged for this discretisation: re-check the step rule at the solution.
            let want = model.steps_for(&v);
            if want.iter().zip(&steps).all(|(w, s)| w <= s) {
                let lu = Lu::new(&eval.jac, n);
                return Ok(Solution {
                    v,
                    eval,
                    lu,
                    steps,
                    iterations,
                });
            }
            for (s, w) in steps.iter_mut().zip(want) {
                *s = (*s).max(w);
            }
            eval = model.evaluate(&v, p, &steps, true);
            counter.evaluations += 1;
            continue;
        }
        if iterations >= opts.max_iter {
            return Err(Failed {
                reason: NewtonFailure::MaxIterations,
                v,
                residual_inf: res,
                iterations,
                progress: 0.0,
            });
        }
        if let Some(stop) = budget.check(counter.evaluations) {
            return Err(Failed {
                reason: NewtonFailure::Budget(stop),
                v,
                residual_inf: res,
                iterations,
                progress: 0.0,
            });
        }
        let g0 = eval.norm2();
        history.push(g0);
        if let Some(w) = opts.stall_window
            && history.len() > w
            && g0 > 0.5 * history[history.len() - 1 - w]
        {
            return Err(Failed {
                reason: NewtonFailure::Stall,
                v,
                residual_inf: res,
                iterations,
                progress: 0.0,
            });
        }
        let rhs: Vec<f64> = eval.g.iter().map(|x| -x).collect();
        let (dv, _) = dense::solve(&eval.jac, n, &rhs);
        let mut t = 1.0;
        let mut accepted = None;
        while t >= MIN_STEP {
            let trial: Vec<f64> = v.iter().zip(&dv).map(|(a, d)| t.mul_add(*d, *a)).collect();
            if trial.iter().all(|x| x.is_finite()) {
                // The full step is usually accepted: evaluate it with the Jacobian; shorter trials
                // without (about 40 % cheaper) and add the Jacobian once one is accepted.
                let full = t >= 1.0;
                let e = model.evaluate(&trial, p, &steps, full);
                counter.evaluations += 1;
                if e.norm2() < ARMIJO.mul_add(-t, 1.0) * g0 {
                    let e = if full {
                        e
                    } else {
                        counter.evaluations += 1;
                        model.evaluate(&trial, p, &steps, true)
                    };
                    accepted = Some((trial, e));
                    break;
                }
            }
            t *= 0.5;
        }
        iterations += 1;
        match accepted {
            Some((nv, ne)) => {
                v = nv;
                eval = ne;
            }
            None => {
                return Err(Failed {
                    reason: NewtonFailure::LineSearch,
                    v,
                    residual_inf: res,
                    iterations,
                    progress: 0.0,
                });
            }
        }
    }
}

/// Tangent `dv/ds = -J^-1 dg/ds` for the parameter direction `dg_ds` (LU, or minimum norm when
/// `J` is singular, e.g. straight over-constrained rods).
#[must_use]
pub fn tangent(sol: &Solution, n: usize, dg_ds: &[f64]) -> Vec<f64> {
    let rhs: Vec<f64> = dg_ds.iter().map(|x| -x).collect();
    if sol.lu.is_singular() {
        dense::min_norm_solve(&sol.eval.jac, n, &rhs)
    } else {
        let mut x = rhs;
        sol.lu.solve_in_place(&mut x);
        x
    }
}

/// Result of a continuation run.
#[derive(Debug, Clone)]
pub struct ContinuationResult {
    /// Final solution at the target parameters.
    pub solution: Solution,
    /// Accepted continuation steps.
    pub steps: usize,
    /// Newton iterations over all steps.
    pub newton_iterations: usize,
}

/// Continuation parameter distance to 1 treated as arrival (round-off of k additions of 1/k).
const T_SNAP: f64 = 1e-12;
/// Stall window of the predicted continuation steps (see [`NewtonOptions::stall_window`]); the same
/// value as the sweep sub-steps, which it matches in role.
pub const CONTINUATION_STALL_WINDOW: usize = 10;
/// Maximum number of step halvings below the nominal step (spec 4.3 / 4.7 step control): the
/// continuation fails when a step of nominal / 2^8 does not converge.
const MAX_HALVINGS: u32 = 8;

#[expect(
    clippy::too_many_arguments,
    reason = "the continuation's full context; grouping it would only rename it"
)]
/// Continue a solution `start` at `from` along the straight parameter path to `to` in `k` equal
/// steps with tangent predictor; halve a failing step up to 8 times.
pub fn continuation(
    model: &Model,
    start: Solution,
    from: &Params,
    to: &Params,
    k: usize,
    opts: NewtonOptions,
    budget: &Budget,
    counter: &mut Counter,
) -> Result<ContinuationResult, Failed> {
    let n = model.n_unknowns();
    let dl: Vec<f64> = to
        .lambda
        .iter()
        .zip(&from.lambda)
        .map(|(a, b)| a - b)
        .collect();
    let df = [to.force[0] - from.force[0], to.force[1] - from.force[1]];
    let dm = to.moment - from.moment;
    let at = |t: f64| Params {
        lambda: from
            .lambda
            .iter()
            .zip(&dl)
            .map(|(a, d)| t.mul_add(*d, *a))
            .collect(),
        force: [
            t.mul_add(df[0], from.force[0]),
            t.mul_add(df[1], from.force[1]),
        ],
        moment: t.mul_add(dm, from.moment),
    };
    let nominal = 1.0 / k.max(1) as f64;
    // Predicted steps either converge fast or are halved: give up on creeping solves early.
    let step_opts = NewtonOptions {
        stall_window: opts.stall_window.or(Some(CONTINUATION_STALL_WINDOW)),
        ..opts
    };
    let mut t = 0.0;
    let mut sol = start;
    let mut accepted = 0usize;
    let mut iters = 0usize;
    let mut halvings = 0u32;
    let mut h = nominal;
    while t < 1.0 {
        let h_try = h.min(1.0 - t);
        // Snap to the end when within round-off of it (k equal steps must land exactly on t = 1).
        let t_new = if t + h_try >= 1.0 - T_SNAP {
            1.0
        } else {
            t + h_try
        };
        let dgdt = model.dg_dt(&sol.v, &sol.eval.forces, &dl, df, dm);
        let tan = tangent(&sol, n, &dgdt);
        let guess: Vec<f64> = sol
            .v
            .iter()
            .zip(&tan)
            .map(|(a, d)| (t_new - t).mul_add(*d, *a))
            .collect();
        let guess = if guess.iter().all(|x| x.is_finite()) {
            guess
        } else {
            sol.v.clone()
        };
        match solve(model, &at(t_new), &guess, step_opts, budget, counter) {
            Ok(s) => {
                iters += s.iterations;
                sol = s;
                t = t_new;
                accepted += 1;
                // Grow back one level per success (resetting to the nominal step at once made
                // the approach to a fold re-fail every halving level after each success).
                halvings = halvings.saturating_sub(1);
                h = nominal / f64::from(1u32 << halvings);
            }
            Err(f) => {
                if matches!(f.reason, NewtonFailure::Budget(_)) || halvings >= MAX_HALVINGS {
                    return Err(Failed { progress: t, ..f });
                }
                halvings += 1;
                h = nominal / f64::from(1u32 << halvings);
            }
        }
    }
    Ok(ContinuationResult {
        solution: sol,
        steps: accepted,
        newton_iterations: iters,
    })
}
