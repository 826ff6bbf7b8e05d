//! A small (μ/μ_w, λ)-CMA-ES on nalgebra (Hansen, "The CMA Evolution Strategy: A Tutorial",
//! 2016, default parameters), with IPOP restarts (Auger & Hansen 2005: population doubled per
//! restart).
//!
//! Written here rather than taken from the `cmaes` crate: that crate depends on nalgebra 0.33
//! (we use 0.34), pulls rayon and plotters, and has no box constraints. Bounds `[0, 1]` are
//! handled by mirroring: the search runs in ℝⁿ and every sample is folded into `[0, 1]` by
//! reflection at the bounds before evaluation (period 2), so the distribution adapts undisturbed
//! and the objective sees only feasible genes.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::Rng;

use super::super::objective::{Ctx, CurveModel};
use super::{FreeGenes, RunEnd, eval, normal};
use crate::numerics::StopReason;

/// Stop when the best values of recent generations and the current population span less than
/// this (absolute, plus the same relative to the best value): pycma's `tolfun` scale.
const TOL_FUN: f64 = 1e-12;
/// Stop when every coordinate's standard deviation `σ·sqrt(C_ii)` is below this (gene units).
const TOL_X: f64 = 1e-12;
/// Stop when the covariance condition number exceeds this (numerically degenerate).
const MAX_CONDITION: f64 = 1e14;

/// Fold a real number into `[0, 1]` by reflection at both bounds.
#[must_use]
pub fn fold(v: f64) -> f64 {
    if (0.0..=1.0).contains(&v) {
        return v;
    }
    let t = v.rem_euclid(2.0);
    if t <= 1.0 { t } else { 2.0 - t }
}

/// Default population size `4 + ⌊3 ln n⌋`.
#[must_use]
pub fn default_lambda(n: usize) -> usize {
    let nf = n.max(1) as f64;
    // Small positive value: the cast cannot wrap.
    let extra = (3.0 * nf.ln()).floor() as usize;
    4 + extra
}

/// Settings of one CMA-ES run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CmaParams {
    /// Initial step size in gene units.
    pub sigma0: f64,
    /// Population size λ.
    pub lambda: usize,
    /// Evaluation cap of this run.
    pub max_evaluations: u64,
}

/// One CMA-ES run from `x0` (free genes) with the given settings. Returns the best point of the
/// run (folded genes) and why it stopped.
// Hansen's default constants read best in their published form.
#[expect(
    clippy::too_many_lines,
    reason = "one CMA-ES run in the order of Hansen's tutorial (sample the generation, rank, recombine, update the evolution paths, covariance and step size, decompose, termination tests); every step updates the same strategy state"
)]
pub fn run<M: CurveModel, R: Rng>(
    ctx: &mut Ctx<'_, M>,
    free: &FreeGenes,
    x0: &[f64],
    p: &CmaParams,
    rng: &mut R,
) -> RunEnd {
    let n = free.len();
    let mut best = RunEnd {
        stop: StopReason::Completed,
        f: f64::INFINITY,
        g: free.expand(x0),
    };
    if n == 0 {
        return best;
    }
    let nf = n as f64;
    let lambda = p.lambda.max(2);
    let mu = lambda / 2;
    let raw: Vec<f64> = (1..=mu)
        .map(|i| ((mu as f64) + 0.5).ln() - (i as f64).ln())
        .collect();
    let wsum: f64 = raw.iter().sum();
    let w: Vec<f64> = raw.iter().map(|v| v / wsum).collect();
    let mueff = 1.0 / w.iter().map(|v| v * v).sum::<f64>();
    let cc = (4.0 + mueff / nf) / (nf + 4.0 + 2.0 * mueff / nf);
    let cs = (mueff + 2.0) / (nf + mueff + 5.0);
    let c1 = 2.0 / ((nf + 1.3) * (nf + 1.3) + mueff);
    let cmu = (1.0 - c1).min(2.0 * (mueff - 2.0 + 1.0 / mueff) / ((nf + 2.0) * (nf + 2.0) + mueff));
    let damps = 1.0 + 2.0 * (((mueff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + cs;
    let chi_n = nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf));
    let hist_len = 10 + (30.0 * nf / lambda as f64).ceil() as usize;

    let mut mean = DVector::from_column_slice(x0);
    let mut sigma = p.sigma0;
    let mut c = DMatrix::<f64>::identity(n, n);
    let mut b = DMatrix::<f64>::identity(n, n);
    let mut d = DVector::<f64>::from_element(n, 1.0);
    let mut pc = DVector::<f64>::zeros(n);
    let mut ps = DVector::<f64>::zeros(n);
    let mut recent_best: Vec<f64> = Vec::new();
    let mut xs: Vec<DVector<f64>> = vec![DVector::zeros(n); lambda];
    let mut fs: Vec<(f64, usize)> = vec![(f64::INFINITY, 0); lambda];
    let mut z = DVector::<f64>::zeros(n);
    let mut folded = vec![0.0; n];
    let mut used = 0u64;
    let mut generation = 0u64;

    loop {
        if let Some(reason) = ctx.check() {
            best.stop = reason;
            return best;
        }
        if used + lambda as u64 > p.max_evaluations {
            best.stop = StopReason::MaxEvaluations;
            return best;
        }
        // Sample and evaluate the whole generation (random numbers drawn first, in order).
        for x in &mut xs {
            for zi in z.iter_mut() {
                *zi = normal(rng);
            }
            let y = &b * d.component_mul(&z);
            *x = &mean + sigma * y;
        }
        for (k, x) in xs.iter().enumerate() {
            for (fo, v) in folded.iter_mut().zip(x.iter()) {
                *fo = fold(*v);
            }
            let g = free.expand(&folded);
            used += 1;
            let Some(f) = eval(ctx, &g) else {
                best.stop = ctx.stop().unwrap_or(StopReason::Deadline);
                return best;
            };
            if f < best.f {
                best.f = f;
                best.g = g;
            }
            fs[k] = (f, k);
        }
        generation += 1;
        ctx.record_iteration();
        fs.sort_by(|a, b| a.0.total_cmp(&b.0));
        if best.f <= 0.0 {
            best.stop = StopReason::Converged;
            return best;
        }

        // Recombination and adaptation.
        let old_mean = mean.clone();
        mean.fill(0.0);
        for (wi, &(_, k)) in w.iter().zip(fs.iter()) {
            mean.axpy(*wi, &xs[k], 1.0);
        }
        let y_w = (&mean - &old_mean) / sigma;
        // C^{-1/2} y_w = B D^{-1} Bᵀ y_w
        let bt_y = b.transpose() * &y_w;
        let inv_sqrt = &b * bt_y.component_div(&d);
        ps = (1.0 - cs) * &ps + (cs * (2.0 - cs) * mueff).sqrt() * inv_sqrt;
        let gen_f = generation as f64;
        let ps_norm = ps.norm();
        let hsig =
            ps_norm / (1.0 - (1.0 - cs).powf(2.0 * gen_f)).sqrt() / chi_n < 1.4 + 2.0 / (nf + 1.0);
        let hs = if hsig { 1.0 } else { 0.0 };
        pc = (1.0 - cc) * &pc + hs * (cc * (2.0 - cc) * mueff).sqrt() * &y_w;
        let mut rank_mu = DMatrix::<f64>::zeros(n, n);
        for (wi, &(_, k)) in w.iter().zip(fs.iter()) {
            let yk = (&xs[k] - &old_mean) / sigma;
            rank_mu.ger(*wi, &yk, &yk, 1.0);
        }
        let delta_h = (1.0 - hs) * cc * (2.0 - cc);
        c = (1.0 - c1 - cmu) * &c + c1 * (&pc * pc.transpose() + delta_h * &c) + cmu * rank_mu;
        sigma *= ((cs / damps) * (ps_norm / chi_n - 1.0)).exp();
        // Symmetrize and decompose.
        c = 0.5 * (&c + c.transpose());
        let eig = SymmetricEigen::new(c.clone());
        let min_ev = eig.eigenvalues.min();
        let max_ev = eig.eigenvalues.max();
        if !(min_ev > 0.0 && max_ev.is_finite() && sigma.is_finite() && sigma > 0.0) {
            best.stop = StopReason::Stall;
            return best;
        }
        b = eig.eigenvectors;
        d = eig.eigenvalues.map(f64::sqrt);

        // Termination tests.
        recent_best.push(fs[0].0);
        if recent_best.len() > hist_len {
            recent_best.remove(0);
        }
        if recent_best.len() >= hist_len {
            let lo = recent_best
                .iter()
                .chain(fs.iter().map(|(f, _)| f))
                .copied()
                .fold(f64::INFINITY, f64::min);
            let hi = recent_best
                .iter()
                .chain(fs.iter().map(|(f, _)| f))
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            if hi - lo <= TOL_FUN * (1.0 + lo.abs()) {
                best.stop = StopReason::Converged;
                return best;
            }
        }
        if (0..n).all(|i| sigma * c[(i, i)].sqrt() < TOL_X) {
            best.stop = StopReason::Converged;
            return best;
        }
        if max_ev / min_ev > MAX_CONDITION {
            best.stop = StopReason::Stall;
            return best;
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::super::testmodel::{coefficient_error, setup};
    use super::*;
    use crate::calc::cam_law_fit::objective::Metric;
    use crate::numerics::Budget;

    #[test]
    fn fold_reflects_into_unit_interval() {
        for (v, e) in [
            (0.3, 0.3),
            (-0.2, 0.2),
            (1.25, 0.75),
            (2.5, 0.5),
            (-1.5, 0.5),
        ] {
            assert!((fold(v) - e).abs() < 1e-15, "{v}");
        }
    }

    #[test]
    fn cmaes_converges_on_toy_model() {
        let truth = [0.1, 0.2, 0.05, 0.15, 0.2, 0.2, 0.1];
        let (m, y) = setup(&truth);
        let free = FreeGenes((0..7).collect());
        let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, Budget::unlimited(), false);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let p = CmaParams {
            sigma0: 0.1,
            lambda: default_lambda(7),
            max_evaluations: 20_000,
        };
        let end = run(&mut ctx, &free, &[1.0 / 7.0; 7], &p, &mut rng);
        let err = coefficient_error(&end.g, &truth);
        assert!(err < 1e-6, "err {err} {end:?}");
    }
}
