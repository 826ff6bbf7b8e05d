//! Differential evolution, scipy-style `DE/best/1/bin` (spec §3.5.2, last paragraph): population
//! `15·n` (n free genes) initialised by Latin hypercube sampling with the initial solution as
//! member 0, mutation factor dithered uniformly in [0.5, 1) once per generation, crossover
//! probability 0.7 with one forced gene, out-of-bounds trial genes redrawn uniformly in [0, 1],
//! immediate (asynchronous) replacement with the best kept in slot 0, and scipy's convergence
//! test `std(f) ≤ 0.01·|mean(f)|`.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::objective::{Ctx, CurveModel};
use super::{FreeGenes, RunEnd, eval};
use crate::numerics::StopReason;

/// Population size per free gene (scipy default `popsize = 15`).
const POPSIZE_PER_GENE: usize = 15;
/// Crossover probability (scipy default `recombination = 0.7`).
const CR: f64 = 0.7;
/// Dither interval of the mutation factor (scipy default `mutation = (0.5, 1)`).
const F_LO: f64 = 0.5;
const F_HI: f64 = 1.0;
/// Relative convergence tolerance on the population's spread (scipy default `tol = 0.01`).
const TOL: f64 = 0.01;
/// Generation limit (scipy default `maxiter = 1000`); the evaluation budget usually ends first.
pub const MAX_GENERATIONS: u64 = 1000;

/// Run DE over the free genes from `initial` (member 0).
pub fn run<M: CurveModel>(
    ctx: &mut Ctx<'_, M>,
    initial: &[f64; 7],
    free: &FreeGenes,
    seed: u64,
) -> RunEnd {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = free.len();
    let finish = |ctx: &Ctx<'_, M>, stop: StopReason| {
        let (f, g) = ctx.best();
        RunEnd { stop, f, g }
    };
    if n == 0 {
        return finish(ctx, StopReason::Completed);
    }
    let size = (POPSIZE_PER_GENE * n).max(5);
    // Latin hypercube: one sample per stratum and gene, strata shuffled per gene.
    let seg = 1.0 / size as f64;
    let mut samples = vec![vec![0.0; n]; size];
    for (i, row) in samples.iter_mut().enumerate() {
        for v in row.iter_mut() {
            let lo = i as f64 * seg;
            *v = seg.mul_add(rng.random::<f64>(), lo);
        }
    }
    let mut pop = vec![vec![0.0; n]; size];
    for j in 0..n {
        let mut order: Vec<usize> = (0..size).collect();
        for i in (1..size).rev() {
            let k = rng.random_range(0..=i);
            order.swap(i, k);
        }
        for (i, &o) in order.iter().enumerate() {
            pop[i][j] = samples[o][j];
        }
    }
    pop[0] = free
        .project(initial)
        .iter()
        .map(|v| v.clamp(0.0, 1.0))
        .collect();

    let mut fit = vec![f64::INFINITY; size];
    for (f, x) in fit.iter_mut().zip(&pop) {
        match eval(ctx, &free.expand(x)) {
            Some(v) => *f = v,
            None => return finish(ctx, ctx.stop().unwrap_or(StopReason::Deadline)),
        }
    }
    // Promote the lowest energy to slot 0.
    let bi = fit
        .iter()
        .enumerate()
        .fold(0, |b, (i, f)| if *f < fit[b] { i } else { b });
    pop.swap(0, bi);
    fit.swap(0, bi);

    let mut trial = vec![0.0; n];
    let mut idx: Vec<usize> = Vec::with_capacity(size);
    for _generation in 0..MAX_GENERATIONS {
        if let Some(reason) = ctx.check() {
            return finish(ctx, reason);
        }
        let scale = rng.random_range(F_LO..F_HI);
        for cand in 0..size {
            // Two distinct members other than the candidate (partial Fisher–Yates).
            idx.clear();
            idx.extend((0..size).filter(|&i| i != cand));
            for t in 0..2 {
                let k = rng.random_range(t..idx.len());
                idx.swap(t, k);
            }
            let (r0, r1) = (idx[0], idx[1]);
            trial.copy_from_slice(&pop[cand]);
            let fill = rng.random_range(0..n);
            for j in 0..n {
                let cross = rng.random::<f64>() < CR;
                if cross || j == fill {
                    trial[j] = scale.mul_add(pop[r0][j] - pop[r1][j], pop[0][j]);
                }
            }
            for v in &mut trial {
                if !(0.0..=1.0).contains(v) {
                    *v = rng.random::<f64>();
                }
            }
            let Some(f) = eval(ctx, &free.expand(&trial)) else {
                ctx.record_iteration();
                return finish(ctx, ctx.stop().unwrap_or(StopReason::Deadline));
            };
            if f <= fit[cand] {
                pop[cand].copy_from_slice(&trial);
                fit[cand] = f;
                if f <= fit[0] {
                    pop[0].copy_from_slice(&trial);
                    fit[0] = f;
                }
            }
        }
        ctx.record_iteration();
        if fit[0] <= 0.0 {
            return finish(ctx, StopReason::Converged);
        }
        if fit.iter().all(|f| f.is_finite()) {
            let nf = size as f64;
            let mean = fit.iter().sum::<f64>() / nf;
            let var = fit.iter().map(|f| (f - mean) * (f - mean)).sum::<f64>() / nf;
            if var.sqrt() <= TOL * mean.abs() {
                return finish(ctx, StopReason::Converged);
            }
        }
    }
    finish(ctx, StopReason::MaxIterations)
}

#[cfg(test)]
mod tests {
    use super::super::testmodel::setup;
    use super::*;
    use crate::calc::cam_law_fit::objective::Metric;
    use crate::numerics::Budget;

    #[test]
    fn de_is_reproducible_and_improves() {
        let truth = [0.1, 0.2, 0.05, 0.15, 0.2, 0.2, 0.1];
        let (m, y) = setup(&truth);
        let free = FreeGenes((0..7).collect());
        let go = |seed| {
            let b = Budget::unlimited().with_max_evaluations(3000);
            let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, b, false);
            let end = run(&mut ctx, &[1.0 / 7.0; 7], &free, seed);
            (end, ctx.evaluations())
        };
        let (a, ea) = go(1);
        let (b, eb) = go(1);
        assert_eq!(ea, eb);
        assert_eq!(a.g.map(f64::to_bits), b.g.map(f64::to_bits));
        assert_eq!(a.stop, StopReason::MaxEvaluations);
        let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, Budget::unlimited(), false);
        let f0 = ctx.value(&[1.0 / 7.0; 7]).unwrap_or(f64::NAN);
        assert!(a.f < 0.5 * f0, "{} vs {f0}", a.f);
    }
}
