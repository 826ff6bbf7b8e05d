//! Objective functions (spec §3.4) and the evaluation context every optimizer runs in.
//!
//! * [`euclidean`]: the paper's EN (Eq. 7), `sqrt(Σ(ŷ_k − y_k)²)`, unweighted, not divided by N.
//! * [`Dtw`]: the paper's DTW as the spec pins it: local cost `|ŷ_i − y_j|` (L1, not squared),
//!   Sakoe–Chiba band `|i − j| ≤ w`, result `D(N, N)` without square root or normalization, two
//!   rolling band rows (O(w) memory, O(N(2w+1)) time, no allocation per call).
//! * [`Ctx`]: the model, the data, the budget and the counters. Every model evaluation goes
//!   through it, so the evaluation count and the best-so-far are exact whatever the optimizer.

use crate::numerics::{Budget, StopReason};

/// Anything that maps 7 non-negative genes (any positive scale; `ĉ = g/Σg`) to a model curve
/// sampled at the data abscissae.
pub trait CurveModel {
    /// Write the model curve of genes `g` into `out` (same length as the data). Returns `false`
    /// for a degenerate candidate (empty pulse, overflow): its objective is `+∞` (spec §3.4).
    fn curve(&self, g: &[f64; 7], out: &mut [f64]) -> bool;
}

/// Which distance the objective uses (spec §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// Euclidean norm of the difference (paper Eq. 7).
    Euclidean,
    /// The paper's banded L1 DTW with Sakoe–Chiba radius `window` (samples).
    Dtw {
        /// Band radius `w`: cells with `|i − j| ≤ w` are allowed.
        window: usize,
    },
}

/// Euclidean norm of `model − data` (paper Eq. 7). `+∞` instead of NaN or overflow.
#[must_use]
pub fn euclidean(model: &[f64], data: &[f64]) -> f64 {
    let ss: f64 = model
        .iter()
        .zip(data)
        .map(|(m, d)| {
            let r = m - d;
            r * r
        })
        .sum();
    finite_or_inf(ss.sqrt())
}

fn finite_or_inf(v: f64) -> f64 {
    if v.is_finite() { v } else { f64::INFINITY }
}

/// Scratch rows of the banded DTW; reuse one per thread to keep evaluations allocation-free.
#[derive(Debug, Clone, Default)]
pub struct Dtw {
    prev: Vec<f64>,
    cur: Vec<f64>,
}

impl Dtw {
    /// Empty scratch (grown on first use).
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// The paper's DTW between `model` (ŷ, rows i) and `data` (y, columns j) with band radius
    /// `window` (spec §3.4). Equal lengths are expected; with unequal lengths the shorter one
    /// bounds the comparison. `window = 0` gives `Σ|ŷ_k − y_k|`. `+∞` instead of NaN.
    pub fn distance(&mut self, model: &[f64], data: &[f64], window: usize) -> f64 {
        let n = model.len().min(data.len());
        if n == 0 {
            return 0.0;
        }
        // A band wider than n − 1 allows every cell already.
        let w = window.min(n - 1);
        let width = 2 * w + 1;
        // Band storage: index k + 1 holds the cell j = i + k − w; indices 0 and width + 1 are
        // permanent +∞ sentinels for the cells just outside the band.
        self.prev.clear();
        self.prev.resize(width + 2, f64::INFINITY);
        self.cur.clear();
        self.cur.resize(width + 2, f64::INFINITY);
        // Row 0: only D(0, 0) = 0 (k = w).
        self.prev[w + 1] = 0.0;
        for i in 1..=n {
            let yi = model[i - 1];
            self.cur.fill(f64::INFINITY);
            // Valid columns 1 ≤ j ≤ n ⇔ w + 1 − i ≤ k ≤ n + w − i.
            let k_lo = (w + 1).saturating_sub(i);
            let k_hi = (2 * w).min(n + w - i);
            for k in k_lo..=k_hi {
                let j = i + k - w;
                let d = (yi - data[j - 1]).abs();
                // D(i−1, j−1) = prev[k+1], D(i−1, j) = prev[k+2], D(i, j−1) = cur[k].
                let m = self.prev[k + 1].min(self.prev[k + 2]).min(self.cur[k]);
                self.cur[k + 1] = d + m;
            }
            std::mem::swap(&mut self.prev, &mut self.cur);
        }
        finite_or_inf(self.prev[w + 1])
    }
}

/// Why a candidate could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvalRefused {
    /// The budget (deadline or evaluation cap) is spent.
    Budget(StopReason),
}

/// The evaluation context: model, data, metric, budget and counters.
///
/// The budget is checked before every model evaluation; once it is spent every further request
/// is refused and [`Ctx::stop`] says why, so optimizers stop at their next check with their
/// best-so-far.
pub struct Ctx<'a, M: CurveModel> {
    model: &'a M,
    data: &'a [f64],
    metric: Metric,
    budget: Budget,
    evaluations: u64,
    /// Optimizer iterations (generations, LM iterations) summed over all phases.
    pub iterations: u64,
    stop: Option<StopReason>,
    curve: Vec<f64>,
    dtw: Dtw,
    /// Best objective after each generation/iteration, when requested.
    pub history: Option<Vec<f64>>,
    best_f: f64,
    best_g: [f64; 7],
}

impl<'a, M: CurveModel> Ctx<'a, M> {
    /// A context over `data` (the `fit_on` channel) with the given metric and budget (the budget
    /// should already carry the request's evaluation cap).
    pub fn new(
        model: &'a M,
        data: &'a [f64],
        metric: Metric,
        budget: Budget,
        keep_history: bool,
    ) -> Self {
        Self {
            model,
            data,
            metric,
            budget,
            evaluations: 0,
            iterations: 0,
            stop: None,
            curve: vec![0.0; data.len()],
            dtw: Dtw::new(),
            history: keep_history.then(Vec::new),
            best_f: f64::INFINITY,
            best_g: [1.0; 7],
        }
    }

    /// The metric of the objective.
    pub fn metric(&self) -> Metric {
        self.metric
    }

    /// The data the model is compared with.
    pub fn data(&self) -> &'a [f64] {
        self.data
    }

    /// Model evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Why the budget stopped the run, if it did.
    pub fn stop(&self) -> Option<StopReason> {
        self.stop
    }

    /// Check the budget now (also done before every evaluation). `Some` once spent.
    pub fn check(&mut self) -> Option<StopReason> {
        if self.stop.is_none() {
            self.stop = self.budget.check(self.evaluations);
        }
        self.stop
    }

    /// Best objective value and genes seen so far under the metric (`+∞` before any).
    pub fn best(&self) -> (f64, [f64; 7]) {
        (self.best_f, self.best_g)
    }

    /// Record the best-so-far in the history (called once per generation/iteration).
    /// Streaming clients see the best objective so far and the share of the budget spent.
    pub fn record_iteration(&mut self) {
        self.iterations += 1;
        let best = self.best_f;
        self.budget
            .progress(self.budget.spent_fraction(self.evaluations), Some(best));
        if let Some(h) = self.history.as_mut() {
            h.push(best);
        }
    }

    /// Offer a point evaluated elsewhere (e.g. by the least-squares phase) as best-so-far.
    pub fn offer(&mut self, f: f64, g: &[f64; 7]) {
        if f < self.best_f {
            self.best_f = f;
            self.best_g = *g;
        }
    }

    /// Evaluate the model once (counted). `Ok(false)` for a degenerate candidate.
    fn eval_curve(&mut self, g: &[f64; 7]) -> Result<bool, EvalRefused> {
        if let Some(r) = self.check() {
            return Err(EvalRefused::Budget(r));
        }
        self.evaluations += 1;
        let ok = self.model.curve(g, &mut self.curve) && self.curve.iter().all(|v| v.is_finite());
        Ok(ok)
    }

    /// The objective under the context's metric (one counted evaluation; updates best-so-far).
    ///
    /// # Errors
    /// [`EvalRefused::Budget`] once the budget is spent.
    pub fn value(&mut self, g: &[f64; 7]) -> Result<f64, EvalRefused> {
        let ok = self.eval_curve(g)?;
        Ok(self.score(ok, g))
    }

    /// The objective at `g` even when the budget is spent (counted; updates best-so-far). Used
    /// once per fit for the initial solution, so that every answer has a finite best-so-far.
    pub fn value_forced(&mut self, g: &[f64; 7]) -> f64 {
        self.evaluations += 1;
        let ok = self.model.curve(g, &mut self.curve) && self.curve.iter().all(|v| v.is_finite());
        self.score(ok, g)
    }

    /// The objective of the curve just evaluated at `g` (infinite when `ok` is false: a
    /// degenerate or non-finite curve); updates best-so-far.
    fn score(&mut self, ok: bool, g: &[f64; 7]) -> f64 {
        let f = if ok {
            match self.metric {
                Metric::Euclidean => euclidean(&self.curve, self.data),
                Metric::Dtw { window } => self.dtw.distance(&self.curve, self.data, window),
            }
        } else {
            f64::INFINITY
        };
        self.offer(f, g);
        f
    }

    /// Residuals `ŷ_k − y_k` into `out` and their Euclidean norm (one counted evaluation). When
    /// the metric is EN this also updates best-so-far. `Ok(None)` for a degenerate candidate.
    ///
    /// # Errors
    /// [`EvalRefused::Budget`] once the budget is spent.
    pub fn residuals(&mut self, g: &[f64; 7], out: &mut [f64]) -> Result<Option<f64>, EvalRefused> {
        if !self.eval_curve(g)? {
            return Ok(None);
        }
        let mut ss = 0.0;
        for ((o, m), d) in out.iter_mut().zip(&self.curve).zip(self.data) {
            let r = m - d;
            *o = r;
            ss += r * r;
        }
        let en = finite_or_inf(ss.sqrt());
        if !en.is_finite() {
            return Ok(None);
        }
        if self.metric == Metric::Euclidean {
            self.offer(en, g);
        }
        Ok(Some(en))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dtw_regression_case_spec_5_2() {
        let x = [0.0, 1.0, 2.0, 1.0, 0.0, 0.0];
        let y = [0.0, 0.0, 1.0, 2.0, 1.0, 0.0];
        assert!((euclidean(&x, &y) - 2.0).abs() < 1e-15);
        let mut d = Dtw::new();
        assert!((d.distance(&x, &y, 0) - 4.0).abs() < 1e-15);
        for w in [1, 2, 5, 100] {
            assert!(d.distance(&x, &y, w).abs() < 1e-15, "w = {w}");
        }
    }

    /// Full O(N²) DP for cross-checking the banded rows.
    fn dtw_full(a: &[f64], b: &[f64], w: usize) -> f64 {
        let n = a.len();
        let mut dm = vec![vec![f64::INFINITY; n + 1]; n + 1];
        dm[0][0] = 0.0;
        for i in 1..=n {
            for j in 1..=n {
                if i.abs_diff(j) <= w {
                    let m = dm[i - 1][j - 1].min(dm[i - 1][j]).min(dm[i][j - 1]);
                    dm[i][j] = (a[i - 1] - b[j - 1]).abs() + m;
                }
            }
        }
        dm[n][n]
    }

    #[test]
    fn banded_rows_match_full_matrix() {
        let a: Vec<f64> = (0..37).map(|k| (f64::from(k) * 0.37).sin()).collect();
        let b: Vec<f64> = (0..37)
            .map(|k| f64::from(k).mul_add(0.41, 0.3).cos())
            .collect();
        let mut d = Dtw::new();
        for w in [0, 1, 2, 3, 7, 36, 50] {
            let full = dtw_full(&a, &b, w);
            let band = d.distance(&a, &b, w);
            assert!(
                (full - band).abs() <= 1e-12 * full.max(1.0),
                "w={w}: {full} vs {band}"
            );
        }
    }
}
