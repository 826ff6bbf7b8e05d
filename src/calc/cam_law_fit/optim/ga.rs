//! The paper's elitist genetic algorithm (Table 2), with every unstated operator fixed as the spec
//! reads it (§3.5.1):
//!
//! 1. Population 0: individual 0 is the initial solution (1/7 each by default), individuals
//!    1..P−1 are uniform in `[0,1]⁷`.
//! 2. Generation `g = 1..G`: range `r = range0·range_factor^⌊(g−1)/range_every⌋` (0.10, ×0.25
//!    every 50 generations).
//! 3. New population: slot 0 is the best of the old one (elitism, not re-evaluated). The rest is
//!    filled pairwise: each parent by binary tournament (lower objective wins, ties go to the
//!    first drawn); with `p_crossover` one-point crossover (cut uniform in 1..=6, tails swapped),
//!    else copies; for each child: with `p_inversion` the genes between two distinct cut points
//!    drawn from 0..=7 are reversed; each gene with `p_range_mutation` gets `g ← clamp(g +
//!    U(−r, r), 0, 1)`; each gene with `p_mutation` gets `g ← U(0, 1)`; all-zero children are
//!    reset to 1/7. The second child of the last pair is dropped when P − 1 is odd.
//! 4. Stop after G generations, after `stall_generations` generations without a relative
//!    improvement > 1e-12, at objective 0, or on the budget.
//!
//! Random numbers are drawn in this fixed serial order from a ChaCha8 stream seeded with the
//! request's seed; children are evaluated after the whole generation has been bred.
//! `fixed_zero` genes are held at 0 after every operator.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::super::objective::{Ctx, CurveModel};
use super::{RunEnd, eval};
use crate::numerics::StopReason;

/// Relative improvement below which a generation counts as stalled (spec §3.5.1 item 4).
const STALL_REL_TOL: f64 = 1e-12;

/// GA settings (paper Table 2; defaults are the paper's values).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaParams {
    /// Individuals per generation (paper: 100).
    pub population: usize,
    /// Maximum generations (paper: 500).
    pub generations: u64,
    /// Probability of one-point crossover per pair (paper: 0.85).
    pub p_crossover: f64,
    /// Probability of inversion per child (paper: 0.1).
    pub p_inversion: f64,
    /// Probability per gene of "mutation around the range" (paper: 0.1).
    pub p_range_mutation: f64,
    /// Initial mutation range, absolute in the gene domain \[0,1\] (paper: 10 %).
    pub range0: f64,
    /// Factor applied to the range every `range_every` generations (paper: "reduced by 75 %").
    pub range_factor: f64,
    /// Generations between range reductions (paper: 50).
    pub range_every: u64,
    /// Probability per gene of classic uniform mutation (spec: 0.01).
    pub p_mutation: f64,
    /// Stop after this many generations without improvement (spec: 100).
    pub stall_generations: u64,
}

impl Default for GaParams {
    fn default() -> Self {
        Self {
            population: 100,
            generations: 500,
            p_crossover: 0.85,
            p_inversion: 0.1,
            p_range_mutation: 0.1,
            range0: 0.10,
            range_factor: 0.25,
            range_every: 50,
            p_mutation: 0.01,
            stall_generations: 100,
        }
    }
}

fn repair(g: &mut [f64; 7], fixed_zero: &[bool; 7]) {
    for (v, &z) in g.iter_mut().zip(fixed_zero) {
        if z {
            *v = 0.0;
        }
    }
    if g.iter().all(|v| *v <= 0.0) {
        for (v, &z) in g.iter_mut().zip(fixed_zero) {
            *v = if z { 0.0 } else { 1.0 / 7.0 };
        }
    }
}

fn tournament<R: Rng>(rng: &mut R, fit: &[f64]) -> usize {
    let i = rng.random_range(0..fit.len());
    let j = rng.random_range(0..fit.len());
    if fit[j] < fit[i] { j } else { i }
}

fn mutate<R: Rng>(rng: &mut R, g: &mut [f64; 7], p: &GaParams, range: f64, fixed: &[bool; 7]) {
    if rng.random::<f64>() < p.p_inversion {
        let a = rng.random_range(0..=7usize);
        let mut b = rng.random_range(0..=6usize);
        // Distinct second cut point: skip over `a`.
        if b >= a {
            b += 1;
        }
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        g[lo..hi].reverse();
    }
    for v in g.iter_mut() {
        if rng.random::<f64>() < p.p_range_mutation {
            let delta = rng.random::<f64>().mul_add(2.0 * range, -range);
            *v = (*v + delta).clamp(0.0, 1.0);
        }
        if rng.random::<f64>() < p.p_mutation {
            *v = rng.random::<f64>();
        }
    }
    repair(g, fixed);
}

/// Run the GA from `initial` (individual 0). The best individual is left in `ctx`; the returned
/// [`RunEnd`] holds it with the stop reason.
pub fn run<M: CurveModel>(
    ctx: &mut Ctx<'_, M>,
    p: &GaParams,
    initial: &[f64; 7],
    fixed_zero: &[bool; 7],
    seed: u64,
) -> RunEnd {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let size = p.population.max(2);
    let mut pop: Vec<[f64; 7]> = Vec::with_capacity(size);
    let mut first = *initial;
    repair(&mut first, fixed_zero);
    pop.push(first);
    for _ in 1..size {
        let mut g = [0.0; 7];
        for v in &mut g {
            *v = rng.random::<f64>();
        }
        repair(&mut g, fixed_zero);
        pop.push(g);
    }
    let mut fit = vec![f64::INFINITY; size];
    let finish = |ctx: &Ctx<'_, M>, stop: StopReason| {
        let (f, g) = ctx.best();
        RunEnd { stop, f, g }
    };
    for (f, g) in fit.iter_mut().zip(&pop) {
        match eval(ctx, g) {
            Some(v) => *f = v,
            None => return finish(ctx, ctx.stop().unwrap_or(StopReason::Deadline)),
        }
    }
    let mut best = fit.iter().copied().fold(f64::INFINITY, f64::min);
    let mut stalled = 0u64;
    let mut next: Vec<[f64; 7]> = Vec::with_capacity(size);
    for generation in 1..=p.generations {
        if let Some(reason) = ctx.check() {
            return finish(ctx, reason);
        }
        if best <= 0.0 {
            return finish(ctx, StopReason::Converged);
        }
        let steps = (generation - 1) / p.range_every.max(1);
        let range = p.range0
            * p.range_factor
                .powi(i32::try_from(steps).unwrap_or(i32::MAX));
        // Elitism: slot 0 is the best of the old population.
        let elite = fit
            .iter()
            .enumerate()
            .fold(0, |bi, (i, f)| if *f < fit[bi] { i } else { bi });
        next.clear();
        next.push(pop[elite]);
        let elite_fit = fit[elite];
        while next.len() < size {
            let a = pop[tournament(&mut rng, &fit)];
            let b = pop[tournament(&mut rng, &fit)];
            let (mut c1, mut c2) = (a, b);
            if rng.random::<f64>() < p.p_crossover {
                let cut = rng.random_range(1..=6usize);
                c1[cut..].copy_from_slice(&b[cut..]);
                c2[cut..].copy_from_slice(&a[cut..]);
            }
            mutate(&mut rng, &mut c1, p, range, fixed_zero);
            mutate(&mut rng, &mut c2, p, range, fixed_zero);
            next.push(c1);
            if next.len() < size {
                next.push(c2);
            }
        }
        std::mem::swap(&mut pop, &mut next);
        fit[0] = elite_fit;
        let mut refused = None;
        for (f, g) in fit.iter_mut().zip(&pop).skip(1) {
            match eval(ctx, g) {
                Some(v) => *f = v,
                None => {
                    refused = ctx.stop();
                    *f = f64::INFINITY;
                }
            }
        }
        let gen_best = fit.iter().copied().fold(f64::INFINITY, f64::min);
        if gen_best < STALL_REL_TOL.mul_add(-best.abs(), best) {
            stalled = 0;
        } else {
            stalled += 1;
        }
        best = best.min(gen_best);
        ctx.record_iteration();
        if let Some(reason) = refused {
            return finish(ctx, reason);
        }
        if stalled >= p.stall_generations {
            return finish(ctx, StopReason::Stall);
        }
    }
    let stop = if best <= 0.0 {
        StopReason::Converged
    } else {
        StopReason::MaxIterations
    };
    finish(ctx, stop)
}

#[cfg(test)]
mod tests {
    use super::super::testmodel::setup;
    use super::*;
    use crate::calc::cam_law_fit::objective::Metric;
    use crate::numerics::Budget;

    #[test]
    fn ga_is_reproducible_and_improves() {
        let truth = [0.1, 0.2, 0.05, 0.15, 0.2, 0.2, 0.1];
        let (m, y) = setup(&truth);
        let p = GaParams {
            generations: 40,
            ..GaParams::default()
        };
        let run_once = |seed| {
            let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, Budget::unlimited(), true);
            let end = run(&mut ctx, &p, &[1.0 / 7.0; 7], &[false; 7], seed);
            (
                end,
                ctx.evaluations(),
                ctx.history.clone().unwrap_or_default(),
            )
        };
        let (a, ea, ha) = run_once(3);
        let (b, eb, _) = run_once(3);
        assert_eq!(ea, eb);
        assert_eq!(a.f.to_bits(), b.f.to_bits());
        assert_eq!(a.g.map(f64::to_bits), b.g.map(f64::to_bits));
        assert_eq!(ea, 100 + 40 * 99);
        assert_eq!(ha.len(), 40);
        assert!(ha.windows(2).all(|w| w[1] <= w[0]));
        let mut ctx = Ctx::new(&m, &y, Metric::Euclidean, Budget::unlimited(), false);
        let f0 = ctx.value(&[1.0 / 7.0; 7]).unwrap_or(f64::NAN);
        assert!(a.f < 0.5 * f0, "{} vs {f0}", a.f);
    }
}
