//! Bounded nonlinear least squares on the residuals `ŷ_k − y_k` (spec §3.5.2 step 2), using the
//! `levenberg-marquardt` crate (a MINPACK `lmder` port on nalgebra) with the spec's bound-free
//! parametrization: `x ∈ ℝⁿ` over the free genes, `g = x²` (so `g ≥ 0` without bounds),
//! `ĉ = g/Σg` inside the model, plus the spec's scale-pinning residual `w·(Σg − 1)`. The Jacobian is a forward difference with step `1e-8·max(1, |x_i|)`.
//!
//! The budget is checked inside the residual callback: once it is spent the callback returns
//! `None`, the crate stops, and the best point evaluated in the run (including Jacobian probes) is
//! returned.

use std::cell::{Cell, RefCell};

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

use super::super::objective::{Ctx, CurveModel, EvalRefused};
use super::{FreeGenes, RunEnd};
use crate::numerics::StopReason;

/// Relative forward-difference step of the Jacobian (spec §3.5.2: `1e-8·max(1, |x|)`, about
/// √ε, the classic balance of truncation and round-off).
const FD_STEP: f64 = 1e-8;

/// Relative tolerances of the LM iteration (spec §3.5.2: `xtol = ftol = gtol = 1e-12`).
const LM_TOL: f64 = 1e-12;

/// Weight of the scale-pinning residual `w·(Σg − 1)` relative to the data's RMS (spec §3.5.2
/// step 2 pins the scale with weight 10 on raw data). The model only sees `ĉ = g/Σg`, so the pin
/// never biases the fit; it removes the neutral radial direction from the Jacobian, which
/// measurably shortens the runs (Table-3 laws: 45–210 instead of 48–706 evaluations).
const PIN_WEIGHT: f64 = 10.0;

/// Default per-start evaluation cap (spec §3.5.2: ≤ 2000 evaluations per start).
pub const MAX_EVALS_PER_START: u64 = 2000;

struct Problem<'r, 'a, M: CurveModel> {
    ctx: RefCell<&'r mut Ctx<'a, M>>,
    free: &'r FreeGenes,
    x: DVector<f64>,
    /// Residuals at the last evaluated parameter vector (LM asks for the Jacobian at the point
    /// whose residuals it just computed).
    cache: RefCell<Option<(DVector<f64>, DVector<f64>)>>,
    scratch: RefCell<Vec<f64>>,
    best: Cell<(f64, [f64; 7])>,
    local_evals: Cell<u64>,
    cap: u64,
    refused: Cell<Option<StopReason>>,
    /// Stop as converged once the EN is at or below this (an exact fit cannot improve).
    target: f64,
    reached: Cell<bool>,
    /// Early-snap threshold and the genes exempt from it (see [`Options::early_snap`]).
    early_snap: Option<(f64, [bool; 7])>,
    early_hit: Cell<bool>,
    jac_calls: Cell<u64>,
    /// Weight of the scale-pinning residual `pin·(Σg − 1)` (0: none).
    pin: f64,
    /// Residual magnitude substituted for a degenerate candidate (empty pulse): far worse than
    /// any real candidate, so LM rejects the step.
    penalty: f64,
}

impl<M: CurveModel> Problem<'_, '_, M> {
    fn genes(&self, x: &DVector<f64>) -> [f64; 7] {
        let sq: Vec<f64> = x.iter().map(|v| v * v).collect();
        self.free.expand(&sq)
    }

    fn eval_at(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
        if let Some((cx, cr)) = self.cache.borrow().as_ref()
            && cx == x
        {
            return Some(cr.clone());
        }
        if self.refused.get().is_some() || self.reached.get() || self.early_hit.get() {
            return None;
        }
        if self.local_evals.get() >= self.cap {
            self.refused.set(Some(StopReason::MaxEvaluations));
            return None;
        }
        let g = self.genes(x);
        let mut scratch = self.scratch.borrow_mut();
        let got = self.ctx.borrow_mut().residuals(&g, &mut scratch);
        self.local_evals.set(self.local_evals.get() + 1);
        let r = match got {
            Err(EvalRefused::Budget(reason)) => {
                self.refused.set(Some(reason));
                return None;
            }
            Ok(None) => {
                DVector::from_element(scratch.len() + usize::from(self.pin > 0.0), self.penalty)
            }
            Ok(Some(en)) => {
                if en < self.best.get().0 {
                    self.best.set((en, g));
                }
                if en <= self.target {
                    self.reached.set(true);
                    return None;
                }
                if self.pin > 0.0 {
                    let sum: f64 = g.iter().sum();
                    DVector::from_iterator(
                        scratch.len() + 1,
                        scratch
                            .iter()
                            .copied()
                            .chain(std::iter::once(self.pin * (sum - 1.0))),
                    )
                } else {
                    DVector::from_column_slice(&scratch)
                }
            }
        };
        *self.cache.borrow_mut() = Some((x.clone(), r.clone()));
        Some(r)
    }
}

impl<M: CurveModel> LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, '_, M> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.eval_at(&self.x)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let r0 = self.eval_at(&self.x)?;
        // Early snap: after the first accepted step, stop as soon as a non-exempt free gene's
        // normalized value falls below the threshold (the caller zeroes it and continues on
        // fewer genes: an active-set strategy that avoids the slow approach of x² → 0).
        self.jac_calls.set(self.jac_calls.get() + 1);
        if let Some((thr, exempt)) = self.early_snap
            && self.jac_calls.get() > 1
        {
            let g = self.genes(&self.x);
            let sum: f64 = g.iter().sum();
            if sum > 0.0 && self.free.0.iter().any(|&k| !exempt[k] && g[k] < thr * sum) {
                self.early_hit.set(true);
                return None;
            }
        }
        let n = self.x.len();
        let mut jac = DMatrix::zeros(r0.len(), n);
        let mut xp = self.x.clone();
        for i in 0..n {
            let xi = self.x[i];
            xp[i] = FD_STEP.mul_add(xi.abs().max(1.0), xi);
            // The step actually taken after rounding.
            let h = xp[i] - xi;
            let rp = self.eval_at(&xp)?;
            let mut col = jac.column_mut(i);
            for (c, (a, b)) in col.iter_mut().zip(rp.iter().zip(r0.iter())) {
                *c = (a - b) / h;
            }
            xp[i] = xi;
        }
        // The Jacobian is requested once per LM iteration.
        self.ctx.borrow_mut().record_iteration();
        // Keep the cache on the base point: LM evaluates the trial step next.
        *self.cache.borrow_mut() = Some((self.x.clone(), r0));
        Some(jac)
    }
}

/// Options of one least-squares run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Evaluation cap of the run (Jacobian probes included).
    pub cap: u64,
    /// Stop as converged once EN ≤ `target` (0: run to LM's own tolerances).
    pub target: f64,
    /// `(threshold, exempt)`: end the run early, with [`End::early_snap`] set, once a free gene
    /// that is not exempt has a normalized value below `threshold`.
    pub early_snap: Option<(f64, [bool; 7])>,
}

/// How a least-squares run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct End {
    /// Best point evaluated (EN) and the stop reason.
    pub run: RunEnd,
    /// The run ended because a gene fell below the early-snap threshold.
    pub early_snap: bool,
}

/// One least-squares run from genes `start` over the `free` genes, at most `cap` evaluations.
/// Returns the best point evaluated (EN of the residuals), and why the run ended: `Converged`
/// (LM's tolerance test or an exact fit), `MaxEvaluations` (the per-start cap), `Stall` (LM
/// cannot improve further in f64), or the global budget's reason.
pub fn run<M: CurveModel>(
    ctx: &mut Ctx<'_, M>,
    start: &[f64; 7],
    free: &FreeGenes,
    cap: u64,
) -> RunEnd {
    run_with(
        ctx,
        start,
        free,
        &Options {
            cap,
            target: 0.0,
            early_snap: None,
        },
    )
    .run
}

/// [`run`] with all options.
pub fn run_with<M: CurveModel>(
    ctx: &mut Ctx<'_, M>,
    start: &[f64; 7],
    free: &FreeGenes,
    opts: &Options,
) -> End {
    let cap = opts.cap;
    let data_scale = ctx.data().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let n_data = ctx.data().len();
    let ctx_rms = (ctx.data().iter().map(|v| v * v).sum::<f64>() / n_data.max(1) as f64).sqrt();
    let x0 = DVector::from_iterator(free.len(), free.0.iter().map(|&k| start[k].max(0.0).sqrt()));
    let problem = Problem {
        ctx: RefCell::new(ctx),
        free,
        x: x0,
        cache: RefCell::new(None),
        scratch: RefCell::new(vec![0.0; n_data]),
        best: Cell::new((f64::INFINITY, *start)),
        local_evals: Cell::new(0),
        cap,
        refused: Cell::new(None),
        target: opts.target,
        reached: Cell::new(false),
        early_snap: opts.early_snap,
        early_hit: Cell::new(false),
        jac_calls: Cell::new(0),
        pin: PIN_WEIGHT * ctx_rms,
        penalty: 1e3 * (data_scale + 1.0),
    };
    if free.is_empty() {
        return End {
            run: RunEnd {
                stop: StopReason::Converged,
                f: f64::INFINITY,
                g: *start,
            },
            early_snap: false,
        };
    }
    let lm = LevenbergMarquardt::new()
        .with_ftol(LM_TOL)
        .with_xtol(LM_TOL)
        .with_gtol(LM_TOL)
        // Our own evaluation cap (Jacobian probes included) ends the run; LM's patience only
        // counts residual calls.
        .with_patience(usize::try_from(cap).unwrap_or(usize::MAX).max(1));
    let (problem, report) = lm.minimize(problem);
    let (f, g) = problem.best.get();
    let early = problem.early_hit.get();
    let stop = match (problem.refused.get(), report.termination) {
        (Some(reason), _) => reason,
        _ if problem.reached.get() || early => StopReason::Converged,
        (None, t) if t.was_successful() => StopReason::Converged,
        (None, TerminationReason::LostPatience) => StopReason::MaxEvaluations,
        (None, _) => StopReason::Stall,
    };
    End {
        run: RunEnd { stop, f, g },
        early_snap: early && problem.refused.get().is_none(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::testmodel::{coefficient_error, setup};
    use super::*;
    use crate::calc::cam_law_fit::objective::Metric;
    use crate::numerics::Budget;

    #[test]
    fn recovers_toy_model_and_respects_caps() {
        let truth = [0.1, 0.2, 0.05, 0.15, 0.2, 0.2, 0.1];
        let (m, y) = setup(&truth);
        let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, Budget::unlimited(), false);
        let free = FreeGenes((0..7).collect());
        let end = run(&mut ctx, &[1.0; 7], &free, 2000);
        let err = coefficient_error(&end.g, &truth);
        assert!(err < 1e-9, "err {err}, {end:?}");
        assert!(ctx.evaluations() <= 2000);

        let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, Budget::unlimited(), false);
        let end = run(&mut ctx, &[1.0; 7], &free, 5);
        assert_eq!(end.stop, StopReason::MaxEvaluations);
        assert_eq!(ctx.evaluations(), 5);

        let b = Budget::unlimited().with_max_evaluations(3);
        let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, b, false);
        let end = run(&mut ctx, &[1.0; 7], &free, 2000);
        assert_eq!(end.stop, StopReason::MaxEvaluations);
        assert_eq!(ctx.evaluations(), 3);
        assert!(end.f.is_finite());
    }
}
