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
    /// Newton iterations over all steps (those of an abandoned adaptive attempt included).
    pub newton_iterations: usize,
    /// The step control that reached the target.
    pub walked: Stepping,
    /// Where an adaptive attempt stopped (fraction of the path) before the fixed steps were
    /// walked instead; `None` when the requested stepping arrived by itself.
    pub fell_back_at: Option<f64>,
}

/// Continuation parameter distance to 1 treated as arrival (round-off of k additions of 1/k).
const T_SNAP: f64 = 1e-12;
/// Stall window of the predicted continuation steps (see [`NewtonOptions::stall_window`]); the same
/// value as the sweep sub-steps, which it matches in role.
pub const CONTINUATION_STALL_WINDOW: usize = 10;
/// Maximum number of step halvings below the nominal step (spec 4.3 / 4.7 step control): the
/// continuation fails when a step of nominal / 2^8 does not converge.
const MAX_HALVINGS: u32 = 8;

/// The straight parameter path `from + t (to - from)`, `t in [0, 1]`, of a continuation.
struct Path<'a> {
    from: &'a Params,
    dl: Vec<f64>,
    df: [f64; 2],
    dm: f64,
}

impl<'a> Path<'a> {
    fn new(from: &'a Params, to: &Params) -> Self {
        Self {
            from,
            dl: to
                .lambda
                .iter()
                .zip(&from.lambda)
                .map(|(a, b)| a - b)
                .collect(),
            df: [to.force[0] - from.force[0], to.force[1] - from.force[1]],
            dm: to.moment - from.moment,
        }
    }

    fn at(&self, t: f64) -> Params {
        Params {
            lambda: self
                .from
                .lambda
                .iter()
                .zip(&self.dl)
                .map(|(a, d)| t.mul_add(*d, *a))
                .collect(),
            force: [
                t.mul_add(self.df[0], self.from.force[0]),
                t.mul_add(self.df[1], self.from.force[1]),
            ],
            moment: t.mul_add(self.dm, self.from.moment),
        }
    }

    /// Tangent predictor from `sol` at `t` to `t_new` (the current point when it is not finite).
    fn predict(&self, model: &Model, sol: &Solution, t: f64, t_new: f64) -> Vec<f64> {
        let dgdt = model.dg_dt(&sol.v, &sol.eval.forces, &self.dl, self.df, self.dm);
        let tan = tangent(sol, model.n_unknowns(), &dgdt);
        let guess: Vec<f64> = sol
            .v
            .iter()
            .zip(&tan)
            .map(|(a, d)| (t_new - t).mul_add(*d, *a))
            .collect();
        if guess.iter().all(|x| x.is_finite()) {
            guess
        } else {
            sol.v.clone()
        }
    }
}

/// How the continuation from home walks its path (spec 4.3 and the adaptive extension).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stepping {
    /// Step length adapted to the path: grows after easy steps, halves on failure or when the
    /// corrector leaves the predictor's trust region; chord (modified) Newton corrector.
    #[default]
    Adaptive,
    /// The spec's `K` equal steps with full Newton per step (the reference values' path).
    Fixed,
}

/// Continue `start` at `from` to `to` with the chosen stepping; `k` is the spec's step count
/// (the fixed path's steps, the adaptive path's first step `1/k`). An adaptive walk that fails
/// for any reason but the budget is followed by the fixed walk from the same start.
#[expect(
    clippy::too_many_arguments,
    reason = "the continuation's full context; grouping it would only rename it"
)]
pub fn continue_path(
    stepping: Stepping,
    model: &Model,
    start: Solution,
    from: &Params,
    to: &Params,
    k: usize,
    opts: NewtonOptions,
    budget: &Budget,
    counter: &mut Counter,
) -> Result<ContinuationResult, Failed> {
    let leg = Leg::new(model, from, to, k, opts, budget);
    match stepping {
        Stepping::Fixed => continuation(&leg, start, counter),
        Stepping::Adaptive => {
            // The adaptive path is the fast one; where it stalls (a singular Jacobian at home, a
            // near-fold far out) the spec's equal steps are walked from the same start, so an
            // answer never depends on which stepping was asked for when both can arrive.
            match adaptive(&leg, start.clone(), counter) {
                Err(f) if !matches!(f.reason, NewtonFailure::Budget(_)) => {
                    let mut r = continuation(&leg, start, counter)?;
                    r.newton_iterations += f.iterations;
                    r.fell_back_at = Some(f.progress);
                    Ok(r)
                }
                other => other,
            }
        }
    }
}

/// One continuation's context: the model, the straight parameter path, its nominal step `1/k`,
/// the request's Newton options, those of the predicted steps, and the budget.
struct Leg<'a> {
    model: &'a Model,
    path: Path<'a>,
    nominal: f64,
    opts: NewtonOptions,
    step_opts: NewtonOptions,
    budget: &'a Budget,
}

impl<'a> Leg<'a> {
    /// The leg from `from` to `to` in `k` nominal steps.
    fn new(
        model: &'a Model,
        from: &'a Params,
        to: &Params,
        k: usize,
        opts: NewtonOptions,
        budget: &'a Budget,
    ) -> Self {
        Self {
            model,
            path: Path::new(from, to),
            nominal: 1.0 / k.max(1) as f64,
            opts,
            // Predicted steps either converge fast or are halved: give up on creeping solves early.
            step_opts: NewtonOptions {
                stall_window: opts.stall_window.or(Some(CONTINUATION_STALL_WINDOW)),
                ..opts
            },
            budget,
        }
    }
}

/// Continue a solution `start` at the leg's start along its straight parameter path to its end
/// in `k` equal steps with tangent predictor; halve a failing step up to 8 times.
fn continuation(
    leg: &Leg<'_>,
    start: Solution,
    counter: &mut Counter,
) -> Result<ContinuationResult, Failed> {
    let &Leg {
        model,
        ref path,
        nominal,
        step_opts,
        budget,
        ..
    } = leg;
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
        let guess = path.predict(model, &sol, t, t_new);
        match solve(model, &path.at(t_new), &guess, step_opts, budget, counter) {
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
        walked: Stepping::Fixed,
        fell_back_at: None,
    })
}

/// Residual (inf-norm) to which the chord corrector converges the intermediate points of the
/// adaptive path (or the request's tolerance when looser). They only carry the path to the next
/// predictor (the branch is set by the trust region, not by this accuracy); the end point is
/// solved by full Newton to the request's tolerance. Chosen from benches/RESULTS.md: 1e-8 made
/// every step of the spec's example take 4 chord iterations (no step growth, 20 steps, slower
/// than the fixed path); 1e-6 takes 9 steps at half the fixed path's cost with the same answers;
/// 1e-5 (keeping the Jacobian after up to 3 iterations) failed on 6 of 100 random targets
/// where the fixed path converged.
const CORRECTOR_TOL: f64 = 1e-6;
/// A point whose chord corrector converged in at most this many iterations keeps the previous
/// Jacobian (its LU) for the next tangent and corrector; else a fresh one is evaluated there.
pub const REUSE_ITER: usize = 2;
/// Chord iterations per corrector before falling back to a fresh Jacobian.
const CHORD_MAX_ITER: usize = 6;
/// A chord iteration must shrink the residual at least by this factor, else fresh Jacobian.
const CHORD_RATE: f64 = 0.5;
/// Steps whose corrector converged in at most this many chord iterations double the next step.
pub const EASY_ITER: usize = 3;
/// Trust region of the predictor: the corrector may move at most this fraction of the predictor
/// step (inf-norm of the unknowns), else the step is halved.
pub const TRUST: f64 = 0.5;
/// Floor of the trust region's predictor length (unknowns are O(1) by their scaling).
pub const TRUST_FLOOR: f64 = 1e-3;
/// Longest adaptive step as a fraction of the path.
pub const MAX_STEP: f64 = 0.25;
/// The adaptive path's intermediate points use half the request's base RK4 steps when that is at
/// least this many (16 steps: position error 4.8e-7 m on the spec's example, below what the
/// corrector's `CORRECTOR_TOL` leaves, and half the cost of an evaluation); the end point is
/// solved on the request's discretisation.
pub const COARSE_MIN_STEPS: usize = 16;

/// Why a chord corrector gave up.
enum ChordOutcome {
    /// Converged at the point (with its residual evaluation) in this many iterations.
    Converged(Vec<f64>, usize, Eval),
    /// Left the trust region around the predictor: the step is too long.
    Trust,
    /// Slow, non-finite or stalled: try a fresh Jacobian.
    Slow,
    /// Out of budget.
    Budget(StopReason),
}

/// Chord (modified) Newton from `guess` with the factored Jacobian `lu` of the previous point.
#[expect(
    clippy::too_many_arguments,
    reason = "the corrector's full context; grouping it would only rename it"
)]
fn chord(
    model: &Model,
    p: &Params,
    guess: &[f64],
    lu: &Lu,
    steps: &[usize],
    tol: f64,
    trust: f64,
    budget: &Budget,
    counter: &mut Counter,
) -> ChordOutcome {
    let mut v = guess.to_vec();
    let mut prev = f64::INFINITY;
    for it in 0..=CHORD_MAX_ITER {
        let e = model.evaluate(&v, p, steps, false);
        counter.evaluations += 1;
        let res = e.norm_inf();
        if !res.is_finite() || res > CHORD_RATE * prev {
            return ChordOutcome::Slow;
        }
        if res < tol {
            return ChordOutcome::Converged(v, it, e);
        }
        if it == CHORD_MAX_ITER {
            return ChordOutcome::Slow;
        }
        if let Some(stop) = budget.check(counter.evaluations) {
            return ChordOutcome::Budget(stop);
        }
        prev = res;
        let mut dv: Vec<f64> = e.g.iter().map(|x| -x).collect();
        lu.solve_in_place(&mut dv);
        for (a, d) in v.iter_mut().zip(&dv) {
            *a += d;
        }
        let moved = max_diff(&v, guess);
        if moved > trust || moved.is_nan() {
            return ChordOutcome::Trust;
        }
    }
    ChordOutcome::Slow
}

/// A converged chord point made into a [`Solution`]. Inside the path: one evaluation with the
/// Jacobian (its LU serves the next tangent and chord corrector), or full Newton when the step
/// rule of spec 4.1 asks for more RK4 steps there. At the end of the path (`last`): full Newton to
/// `opts.tol` from the chord point with the step rule taken afresh there, as the fixed path's
/// last solve does (usually one or two quadratic iterations).
#[expect(
    clippy::too_many_arguments,
    reason = "the corrector's full context; grouping it would only rename it"
)]
fn finish(
    model: &Model,
    p: &Params,
    v: Vec<f64>,
    steps: Vec<usize>,
    iterations: usize,
    last: bool,
    opts: NewtonOptions,
    budget: &Budget,
    counter: &mut Counter,
) -> Result<Solution, Failed> {
    let want = model.steps_for(&v);
    if last || want.iter().zip(&steps).any(|(w, s)| w > s) {
        return solve(model, p, &v, opts, budget, counter).map(|mut s| {
            s.iterations += iterations;
            s
        });
    }
    let eval = model.evaluate(&v, p, &steps, true);
    counter.evaluations += 1;
    let lu = Lu::new(&eval.jac, model.n_unknowns());
    Ok(Solution {
        v,
        eval,
        lu,
        steps,
        iterations,
    })
}

/// Largest absolute component difference of two vectors.
fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Adaptive continuation of `start` at the leg's start to its end: tangent predictor, first step `1/k`,
/// doubled after easy steps (corrector converged in at most [`EASY_ITER`] chord iterations) up
/// to [`MAX_STEP`], halved on a failed corrector or when the corrector moves more than [`TRUST`]
/// of the predictor step; chord Newton with the last evaluated Jacobian's LU (kept across steps
/// while the chord converges in at most [`REUSE_ITER`] iterations), falling back to full Newton
/// with fresh Jacobians; the end point is solved by full Newton to `opts.tol`. Fails when the
/// step falls below `1/(k 2^8)` (the fixed path's smallest step). Chord iterations count as
/// Newton iterations in the result.
fn adaptive(
    leg: &Leg<'_>,
    start: Solution,
    counter: &mut Counter,
) -> Result<ContinuationResult, Failed> {
    let &Leg {
        model,
        ref path,
        nominal,
        opts,
        step_opts,
        budget,
    } = leg;
    let h_min = nominal / f64::from(1u32 << MAX_HALVINGS);
    let mid_tol = opts.tol.max(CORRECTOR_TOL);
    // The intermediate points only carry the path to the next predictor: a coarser discretisation
    // (half the RK4 steps) serves them; the end point is solved on the request's.
    let coarse = (model.base_steps / 2 >= COARSE_MIN_STEPS)
        .then(|| model.with_base_steps(model.base_steps / 2));
    let mut t = 0.0;
    let mut sol = start;
    let mut accepted = 0usize;
    let mut iters = 0usize;
    let mut h = nominal.min(MAX_STEP);
    let mut sol_coarse = false;
    while t < 1.0 {
        let t_new = if t + h >= 1.0 - T_SNAP { 1.0 } else { t + h };
        let last = t_new >= 1.0;
        let on_coarse = coarse.is_some() && !last;
        let model = coarse.as_ref().filter(|_| on_coarse).unwrap_or(model);
        let p = path.at(t_new);
        let guess = path.predict(model, &sol, t, t_new);
        let trust = TRUST * max_diff(&guess, &sol.v).max(TRUST_FLOOR);
        let mut steps = model.steps_for(&guess);
        if sol_coarse == on_coarse {
            // Never fewer steps than the last point on the same discretisation.
            for (s, o) in steps.iter_mut().zip(&sol.steps) {
                *s = (*s).max(*o);
            }
        }
        let outcome = if sol.lu.is_singular() {
            ChordOutcome::Slow
        } else {
            chord(
                model, &p, &guess, &sol.lu, &steps, mid_tol, trust, budget, counter,
            )
        };
        let (next, easy) = match outcome {
            ChordOutcome::Converged(v, it, e) => {
                let keep = !last
                    && it <= REUSE_ITER
                    && model.steps_for(&v).iter().zip(&steps).all(|(w, s)| w <= s);
                let next = if keep {
                    // The Jacobian still converges the chord fast: keep its LU for the next
                    // tangent and corrector.
                    Ok(Solution {
                        v,
                        eval: e,
                        lu: sol.lu.clone(),
                        steps,
                        iterations: it,
                    })
                } else {
                    finish(model, &p, v, steps, it, last, step_opts, budget, counter)
                };
                (next, it <= EASY_ITER)
            }
            ChordOutcome::Trust => (
                Err(Failed {
                    reason: NewtonFailure::Stall,
                    v: guess,
                    residual_inf: f64::INFINITY,
                    iterations: 0,
                    progress: t,
                }),
                false,
            ),
            ChordOutcome::Budget(stop) => {
                return Err(Failed {
                    reason: NewtonFailure::Budget(stop),
                    v: sol.v,
                    residual_inf: sol.eval.norm_inf(),
                    iterations: iters,
                    progress: t,
                });
            }
            ChordOutcome::Slow => {
                // Fresh Jacobians from the predictor; the result must stay in the trust region.
                let r = solve(model, &p, &guess, step_opts, budget, counter).and_then(|s| {
                    if max_diff(&s.v, &guess) <= trust {
                        Ok(s)
                    } else {
                        Err(Failed {
                            reason: NewtonFailure::Stall,
                            residual_inf: s.eval.norm_inf(),
                            iterations: s.iterations,
                            v: s.v,
                            progress: t,
                        })
                    }
                });
                (r, false)
            }
        };
        match next {
            Ok(s) => {
                iters += s.iterations;
                sol = s;
                sol_coarse = on_coarse;
                t = t_new;
                accepted += 1;
                if easy {
                    h = (2.0 * h).min(MAX_STEP);
                }
            }
            Err(f) => {
                if matches!(f.reason, NewtonFailure::Budget(_)) || h * 0.5 < h_min * (1.0 - 1e-9) {
                    return Err(Failed { progress: t, ..f });
                }
                h *= 0.5;
            }
        }
    }
    Ok(ContinuationResult {
        solution: sol,
        steps: accepted,
        newton_iterations: iters,
        walked: Stepping::Adaptive,
        fell_back_at: None,
    })
}
