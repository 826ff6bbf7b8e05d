//! The fit pipeline (spec §3.5) and the response (spec §3.6, §4).

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::calc::cam_law::catalogue::{TABLE3, nearest};
use crate::calc::cam_law::law::{
    BoundaryConditions, JUMP_REL_TOL, Jump, Knot, LawNotice, Peaks, Quantity, SampledCurves,
    SevenSegmentLaw,
};
use crate::numerics::{Budget, StopReason};

use super::error::FitError;
pub use super::input::{Algorithm, Settings};
use super::input::{Channel, FitInput, MetricKind};
use super::objective::{Ctx, CurveModel, Dtw, Metric, euclidean};
use super::optim::cmaes::{self, CmaParams, default_lambda};
use super::optim::ga;
use super::optim::lsq::{self, MAX_EVALS_PER_START};
use super::optim::{FreeGenes, de, normalized};
use crate::numerics::grid;

/// Zero entries of a Table-3 start are replaced by this before renormalizing (spec §3.5.2 step 1).
const START_ZERO_FILL: f64 = 0.02;
/// A least-squares start whose EN is below this fraction of the data norm is an exact fit: no
/// other start can beat it, so the remaining starts are skipped (the zero-snap still runs).
const EXACT_FIT_REL: f64 = 1e-13;
/// Zero-snap acceptance: the snapped solution may be worse by this relative amount (spec §3.5.2
/// step 4: `EN ≤ EN·(1+1e-9) + 1e-12`).
const SNAP_ACCEPT_REL: f64 = 1e-9;
/// Zero-snap acceptance, absolute part.
const SNAP_ACCEPT_ABS: f64 = 1e-12;
/// DTW polish (spec §3.5.2 step 5a): CMA-ES step size and evaluation cap.
const DTW_POLISH_SIGMA: f64 = 0.01;
const DTW_POLISH_EVALS: u64 = 3000;
/// IPOP-CMA-ES restarts (spec §3.5.2 step 5b): step size and evaluation cap per run.
const IPOP_SIGMA: f64 = 0.1;
const IPOP_EVALS: u64 = 30_000;
/// Step size of the `cmaes` method (spec §3.5.2).
const CMAES_SIGMA: f64 = 0.1;

/// The 7-segment law sampled at fixed abscissae for one quantity: the model of the fit.
pub struct LawModel<'a> {
    /// Abscissae (inside `[t_a, t_b]`).
    pub xs: &'a [f64],
    /// Boundary conditions.
    pub bc: BoundaryConditions,
    /// Quantity compared.
    pub quantity: Quantity,
}

impl CurveModel for LawModel<'_> {
    fn curve(&self, g: &[f64; 7], out: &mut [f64]) -> bool {
        match SevenSegmentLaw::try_new(g, &self.bc) {
            Ok(law) => {
                law.eval_quantity_into(self.xs, self.quantity, out);
                true
            }
            Err(_) => false,
        }
    }
}

/// Result of the optimizer pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOutcome {
    /// Best genes (normalized).
    pub coefficients: [f64; 7],
    /// Objective at the initial coefficients.
    pub initial: f64,
    /// Best objective under the metric.
    pub best: f64,
    /// Why the pipeline stopped.
    pub stop: StopReason,
    /// Least-squares starts run.
    pub starts_used: u32,
    /// Segments set to zero by the snap.
    pub snapped: Vec<usize>,
}

/// The `auto` starts (spec §3.5.2 step 1): the initial solution, 1/7 each (when different), and
/// the Table-3 vectors with zeros replaced by 0.02, skipping those with a positive entry where
/// `fixed_zero` holds. Fixed genes are zeroed; duplicates are dropped.
#[must_use]
pub fn auto_starts(initial: &[f64; 7], fixed_zero: &[bool; 7]) -> Vec<[f64; 7]> {
    let mask = |mut g: [f64; 7]| {
        for (v, z) in g.iter_mut().zip(fixed_zero) {
            if *z {
                *v = 0.0;
            }
        }
        normalized(&g)
    };
    let mut out: Vec<[f64; 7]> = vec![*initial, mask([1.0 / 7.0; 7])];
    for entry in &TABLE3 {
        let c = entry.coefficients;
        if c.iter().zip(fixed_zero).any(|(v, z)| *z && *v > 0.0) {
            continue;
        }
        out.push(mask(c.map(|v| if v > 0.0 { v } else { START_ZERO_FILL })));
    }
    let mut unique: Vec<[f64; 7]> = Vec::with_capacity(out.len());
    for s in out {
        let dup = unique
            .iter()
            .any(|u| u.iter().zip(&s).all(|(a, b)| (a - b).abs() <= 1e-15));
        if !dup {
            unique.push(s);
        }
    }
    unique
}

/// Least-squares phase result: best EN point.
#[derive(Debug, Clone, Copy)]
struct EnBest {
    en: f64,
    g: [f64; 7],
}

/// Zero-snap (spec §3.5.2 step 4). Returns the accepted point and the snapped indices.
fn snap<M: CurveModel>(
    ctx: &mut Ctx<'_, M>,
    best: EnBest,
    free: &FreeGenes,
    snap_tol: f64,
) -> (EnBest, Vec<usize>) {
    let c = normalized(&best.g);
    let mut z: Vec<usize> = free
        .0
        .iter()
        .copied()
        .filter(|&k| c[k] < snap_tol)
        .collect();
    // Keep both pulses non-empty: never snap the largest gene of a pulse that would empty.
    for pulse in [[0usize, 1, 2], [4, 5, 6]] {
        let empties = pulse.iter().all(|k| c[*k] <= 0.0 || z.contains(k));
        if empties
            && let Some(&kmax) = pulse
                .iter()
                .filter(|k| c[**k] > 0.0)
                .max_by(|a, b| c[**a].total_cmp(&c[**b]))
        {
            z.retain(|k| *k != kmax);
        }
    }
    // Genes that are exactly zero already need no snap.
    z.retain(|k| c[*k] > 0.0);
    if z.is_empty() || ctx.check().is_some() {
        return (best, Vec::new());
    }
    let mut g = c;
    for &k in &z {
        g[k] = 0.0;
    }
    let free2 = FreeGenes(free.0.iter().copied().filter(|k| !z.contains(k)).collect());
    let end = lsq::run(ctx, &g, &free2, MAX_EVALS_PER_START);
    if end.f <= best.en.mul_add(1.0 + SNAP_ACCEPT_REL, SNAP_ACCEPT_ABS) {
        (
            EnBest {
                en: end.f,
                g: end.g,
            },
            z,
        )
    } else {
        (best, Vec::new())
    }
}

/// Active-set rounds of one least-squares start (at most this many).
const MAX_ROUNDS: usize = 12;
/// Normalized value at which a zeroed gene is probed for the optimality (KKT) test.
const KKT_PROBE: f64 = 1e-6;
/// A probe must lower EN by this relative amount to release the gene.
const KKT_REL: f64 = 1e-12;

/// One least-squares start as an active-set method (spec §3.5.2 steps 2 and 4 interleaved).
///
/// The run stops early when a gene falls below `snap_tol`; that gene is set to exactly zero and
/// the run continues on the remaining genes (the x² parametrization approaches a zero optimum
/// only linearly, and a zero segment adjacent to a sampled acceleration jump is a discontinuity
/// no continuous step can cross, spec §6 item 3). At convergence every zeroed gene is probed:
/// if reopening it to `KKT_PROBE` lowers EN, it is released (and exempt from further snapping)
/// and the run continues. The result is a point where the zero genes satisfy the bound
/// optimality condition; it is returned unless an earlier point of the start was better by
/// more than the zero-snap acceptance tolerance.
fn descend<M: CurveModel>(
    ctx: &mut Ctx<'_, M>,
    start: &[f64; 7],
    free: &FreeGenes,
    snap_tol: f64,
    cap: u64,
    target: f64,
) -> EnBest {
    let first_eval = ctx.evaluations();
    let mut g = normalized(start);
    let mut act = free.clone();
    let mut exempt = [false; 7];
    let mut early = snap_tol > 0.0;
    let mut best_seen = EnBest {
        en: f64::INFINITY,
        g,
    };
    let mut last = best_seen;
    let mut scratch = vec![0.0; ctx.data().len()];
    for _ in 0..MAX_ROUNDS {
        let used = ctx.evaluations() - first_eval;
        if used >= cap || ctx.check().is_some() {
            break;
        }
        let opts = lsq::Options {
            cap: cap - used,
            target,
            early_snap: early.then_some((snap_tol, exempt)),
        };
        let end = lsq::run_with(ctx, &g, &act, &opts);
        if end.run.f.is_finite() {
            last = EnBest {
                en: end.run.f,
                g: normalized(&end.run.g),
            };
            g = last.g;
            if last.en < best_seen.en {
                best_seen = last;
            }
        }
        if end.early_snap {
            let mut small: Vec<usize> = act
                .0
                .iter()
                .copied()
                .filter(|&k| !exempt[k] && g[k] < snap_tol)
                .collect();
            for pulse in [[0usize, 1, 2], [4, 5, 6]] {
                let survivors = pulse
                    .iter()
                    .filter(|k| g[**k] > 0.0 && !small.contains(k))
                    .count();
                if survivors == 0
                    && let Some(&kmax) = pulse
                        .iter()
                        .filter(|k| g[**k] > 0.0)
                        .max_by(|a, b| g[**a].total_cmp(&g[**b]))
                {
                    small.retain(|k| *k != kmax);
                }
            }
            if small.is_empty() {
                early = false;
            } else {
                for &k in &small {
                    g[k] = 0.0;
                }
                g = normalized(&g);
                act.0.retain(|k| !small.contains(k));
                last.en = f64::INFINITY;
            }
            continue;
        }
        if last.en <= target {
            break;
        }
        // Optimality of the zeroed genes: does reopening one lower EN?
        let zeros: Vec<usize> = free.0.iter().copied().filter(|&k| g[k] <= 0.0).collect();
        let mut released = Vec::new();
        for &k in &zeros {
            let mut p = g;
            p[k] = KKT_PROBE;
            match ctx.residuals(&p, &mut scratch) {
                Ok(Some(en)) if en < last.en * (1.0 - KKT_REL) => released.push(k),
                Err(_) => break,
                _ => {}
            }
        }
        if released.is_empty() {
            break;
        }
        for &k in &released {
            g[k] = snap_tol.max(KKT_PROBE);
            exempt[k] = true;
            act.0.push(k);
        }
        act.0.sort_unstable();
        g = normalized(&g);
        last.en = f64::INFINITY;
    }
    if last.en <= best_seen.en.mul_add(1.0 + SNAP_ACCEPT_REL, SNAP_ACCEPT_ABS) {
        last
    } else {
        best_seen
    }
}

/// Least squares from `start` then zero-snap: the polish of spec §3.5.2 steps 2–4.
fn polish_en<M: CurveModel>(
    ctx: &mut Ctx<'_, M>,
    start: EnBest,
    free: &FreeGenes,
    snap_tol: f64,
    cap: u64,
) -> (EnBest, Vec<usize>) {
    let end = lsq::run(ctx, &start.g, free, cap);
    let best = if end.f < start.en {
        EnBest {
            en: end.f,
            g: end.g,
        }
    } else {
        start
    };
    snap(ctx, best, free, snap_tol)
}

/// Run the configured optimizer on `ctx` (spec §3.5). The initial objective is evaluated first
/// (always, even on a spent budget), so the outcome is never worse than the initial solution.
#[expect(
    clippy::too_many_lines,
    reason = "the spec §3.5 pipeline: the auto branch (multi-start least squares with zero snapping, the plain repeat of trapped starts, DTW polish and IPOP restarts), the single-method branches and the common epilogue share snapped, snapped_choice, starts_used and one RNG stream"
)]
pub fn fit<M: CurveModel>(ctx: &mut Ctx<'_, M>, s: &Settings) -> FitOutcome {
    let initial = ctx.value_forced(&s.initial);
    let free = FreeGenes::from_mask(&s.fixed_zero);
    let euclid = ctx.metric() == Metric::Euclidean;
    let mut starts_used = 0u32;
    let mut snapped = Vec::new();
    // The EN solution that overrides the context's best-so-far when the snap was accepted.
    let mut snapped_choice: Option<EnBest> = None;
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);

    let main_stop = match s.method {
        Algorithm::Auto => {
            let y_norm = euclidean(ctx.data(), &vec![0.0; ctx.data().len()]);
            let exact = EXACT_FIT_REL * y_norm;
            let mut best = EnBest {
                en: f64::INFINITY,
                g: s.initial,
            };
            let mut examined: Vec<f64> = Vec::new();
            for start in auto_starts(&s.initial, &s.fixed_zero) {
                if ctx.check().is_some() {
                    break;
                }
                starts_used += 1;
                let mut end = descend(ctx, &start, &free, s.snap_tol, MAX_EVALS_PER_START, exact);
                // The early snap can trap a start at a zero that is only locally optimal; when
                // the start did not reach an exact fit, it is repeated as the plain least-squares
                // run of spec §3.5.2 step 2, and the zero-snapped result is kept unless the plain
                // one is better beyond the snap acceptance tolerance.
                // One repetition per distinct trapped value: starts that end at an EN already
                // examined (within 1e-9) are the same local minimum.
                let snapped_any = free.0.iter().any(|&k| end.g[k] <= 0.0);
                let seen = examined
                    .iter()
                    .any(|e: &f64| (end.en - e).abs() <= SNAP_ACCEPT_REL * e.abs());
                if end.en > exact && snapped_any && !seen && ctx.check().is_none() {
                    examined.push(end.en);
                    let plain = lsq::run_with(
                        ctx,
                        &start,
                        &free,
                        &lsq::Options {
                            cap: MAX_EVALS_PER_START,
                            target: exact,
                            early_snap: None,
                        },
                    )
                    .run;
                    if plain.f.mul_add(1.0 + SNAP_ACCEPT_REL, SNAP_ACCEPT_ABS) < end.en {
                        end = EnBest {
                            en: plain.f,
                            g: normalized(&plain.g),
                        };
                    }
                }
                if end.en < best.en {
                    best = end;
                }
                if best.en <= exact {
                    break;
                }
            }
            let (after, _) = snap(ctx, best, &free, s.snap_tol);
            snapped = free
                .0
                .iter()
                .copied()
                .filter(|&k| after.g[k] <= 0.0)
                .collect();
            snapped_choice = Some(after);
            if !euclid {
                // DTW (step 5): the least-squares point, then CMA-ES polish and IPOP restarts.
                snapped_choice = None;
                if after.en.is_finite() {
                    let _ = ctx.value(&normalized(&after.g));
                }
                // DTW ≥ 0: an exact match (DTW at round-off level) cannot be improved.
                let y_l1: f64 = ctx.data().iter().map(|v| v.abs()).sum();
                let dtw_exact = EXACT_FIT_REL * y_l1;
                let nz = FreeGenes(
                    free.0
                        .iter()
                        .copied()
                        .filter(|&k| after.g[k] > 0.0)
                        .collect(),
                );
                let done =
                    |ctx: &mut Ctx<'_, M>| ctx.check().is_some() || ctx.best().0 <= dtw_exact;
                if !done(ctx) && !nz.is_empty() {
                    let x0 = nz.project(&normalized(&ctx.best().1));
                    let p = CmaParams {
                        sigma0: DTW_POLISH_SIGMA,
                        lambda: default_lambda(nz.len()),
                        max_evaluations: DTW_POLISH_EVALS,
                    };
                    cmaes::run(ctx, &nz, &x0, &p, &mut rng);
                }
                for r in 1..=s.dtw_global_restarts {
                    if done(ctx) {
                        break;
                    }
                    let x0 = free.project(&normalized(&ctx.best().1));
                    let p = CmaParams {
                        sigma0: IPOP_SIGMA,
                        lambda: default_lambda(free.len()) << r,
                        max_evaluations: IPOP_EVALS,
                    };
                    cmaes::run(ctx, &free, &x0, &p, &mut rng);
                }
            }
            StopReason::Converged
        }
        Algorithm::Lsq => {
            starts_used = 1;
            let end = lsq::run(ctx, &s.initial, &free, s.max_evaluations);
            if s.polish {
                let (after, z) = snap(
                    ctx,
                    EnBest {
                        en: end.f,
                        g: end.g,
                    },
                    &free,
                    s.snap_tol,
                );
                if !z.is_empty() {
                    snapped = z;
                    snapped_choice = Some(after);
                }
            }
            end.stop
        }
        Algorithm::Ga | Algorithm::De | Algorithm::Cmaes => {
            let end = match s.method {
                Algorithm::Ga => ga::run(ctx, &s.ga, &s.initial, &s.fixed_zero, s.seed),
                Algorithm::De => de::run(ctx, &s.initial, &free, s.seed),
                _ => {
                    let p = CmaParams {
                        sigma0: CMAES_SIGMA,
                        lambda: default_lambda(free.len()),
                        max_evaluations: u64::MAX,
                    };
                    cmaes::run(ctx, &free, &free.project(&s.initial), &p, &mut rng)
                }
            };
            if s.polish && euclid && ctx.check().is_none() {
                let (f, g) = ctx.best();
                starts_used = 1;
                let (after, z) = polish_en(
                    ctx,
                    EnBest { en: f, g },
                    &free,
                    s.snap_tol,
                    MAX_EVALS_PER_START,
                );
                if !z.is_empty() {
                    snapped = z;
                    snapped_choice = Some(after);
                }
            }
            end.stop
        }
    };

    let (best_f, best_g) = match snapped_choice {
        Some(c) if c.en.is_finite() => (c.en, c.g),
        _ => ctx.best(),
    };
    let stop = ctx.stop().unwrap_or(main_stop);
    // Report only snapped segments that are still zero in the answer (a DTW restart may reopen).
    snapped.retain(|k| best_g[*k] <= 0.0);
    FitOutcome {
        coefficients: normalized(&best_g),
        initial,
        best: best_f,
        stop,
        starts_used,
        snapped,
    }
}

fn check_finite(values: &[f64], quantity: &'static str) -> Result<(), FitError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(FitError::NonFinite { quantity })
    }
}

/// Objective of `law` against the fitted channel (uncounted; used for reporting).
fn objective_of(law: &SevenSegmentLaw, input: &FitInput, data: &[f64], dtw: &mut Dtw) -> f64 {
    let mut model = vec![0.0; data.len()];
    let xs = &input.data.xs_model;
    law.eval_quantity_into(xs, input.objective.on.quantity(), &mut model);
    match input.objective.metric {
        MetricKind::Euclidean => euclidean(&model, data),
        MetricKind::Dtw => dtw.distance(&model, data, input.objective.dtw_window),
    }
}

/// Distances between the fitted law and one supplied channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelErrors {
    /// Euclidean norm.
    pub euclidean: f64,
    /// DTW at the request's band radius.
    pub dtw: f64,
}

/// The objective at the initial and the reported law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectiveValues {
    /// At the initial coefficients.
    pub initial: f64,
    /// At the reported coefficients.
    pub final_value: f64,
}

/// What the optimizer did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunStats {
    /// Objective evaluations.
    pub evaluations: u64,
    /// Optimizer iterations.
    pub iterations: u64,
    /// CPU time of the fit \[ms\].
    pub cpu_ms: f64,
    /// Why the pipeline stopped.
    pub stop: StopReason,
    /// Least-squares starts run.
    pub starts_used: u32,
    /// Segments set to zero by the snap.
    pub snapped: Vec<usize>,
}

/// The fitted law and what was asked about it.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOutput {
    /// Normalized coefficients of the reported law.
    pub coefficients: Vec<f64>,
    /// Segment durations.
    pub durations: Vec<f64>,
    /// The 8 knots.
    pub knots: Vec<Knot>,
    /// Exact peaks.
    pub peaks: Peaks,
    /// Acceleration jumps.
    pub jumps: Vec<Jump>,
    /// Objective values.
    pub objective: ObjectiveValues,
    /// Per supplied channel (s, v, a): distances to the law, when asked for.
    pub error_table: Option<[Option<ChannelErrors>; 3]>,
    /// The nearest Table-3 law (`id name`) and the largest coefficient difference, when asked for.
    pub classification: Option<(String, f64)>,
    /// Dense curves, when asked for.
    pub curves: Option<SampledCurves>,
    /// Best objective per iteration (finite values), when asked for.
    pub history: Option<Vec<f64>>,
    /// Optimizer statistics.
    pub stats: RunStats,
    /// Findings (validation findings first).
    pub warnings: Vec<LawNotice>,
}

/// Validated input → the fitted law (spec §3.5–§4).
///
/// # Errors
/// [`FitError`] when the fitted law cannot be represented in f64 (not expected after
/// validation; never a panic).
pub fn compute(input: &FitInput, budget: &Budget) -> Result<FitOutput, FitError> {
    let started = Instant::now();
    let cap = budget
        .max_evaluations()
        .map_or(input.settings.max_evaluations, |m| {
            m.min(input.settings.max_evaluations)
        });
    let run_budget = budget.clone().with_max_evaluations(cap);
    let on = input.objective.on;
    // Validation guarantees the fit channel exists (supplied or derived).
    let data: &[f64] = input.data.channels[on.index()].as_deref().unwrap_or(&[]);
    let model = LawModel {
        xs: &input.data.xs_model,
        bc: input.bc,
        quantity: on.quantity(),
    };
    let metric = match input.objective.metric {
        MetricKind::Euclidean => Metric::Euclidean,
        MetricKind::Dtw => Metric::Dtw {
            window: input.objective.dtw_window,
        },
    };
    let settings = Settings {
        max_evaluations: cap,
        ..input.settings.clone()
    };
    let mut ctx = Ctx::new(&model, data, metric, run_budget, input.outputs.history);
    let out = fit(&mut ctx, &settings);
    let evaluations = ctx.evaluations();
    let iterations = ctx.iterations;
    let history = ctx
        .history
        .take()
        .map(|h| h.into_iter().filter(|v| v.is_finite()).collect());
    let cpu_ms = started.elapsed().as_secs_f64() * 1e3;

    // The reported law is rebuilt from the normalized coefficients and its objective recomputed,
    // so that `coefficients` and `objective.final` agree exactly. Elitism: never report a law
    // worse than the initial one.
    let initial = &input.settings.initial;
    let mut dtw = Dtw::new();
    let mut law = SevenSegmentLaw::try_new(&out.coefficients, &input.bc)
        .or_else(|_| SevenSegmentLaw::try_new(initial, &input.bc))?;
    let mut final_value = objective_of(&law, input, data, &mut dtw);
    let initial_law = SevenSegmentLaw::try_new(initial, &input.bc)?;
    let initial_value = objective_of(&initial_law, input, data, &mut dtw);
    if final_value.is_nan() || final_value > initial_value {
        law = initial_law;
        final_value = initial_value;
    }
    check_finite(&[final_value, initial_value], "objective")?;

    let peaks = law.peaks();
    let knots = law.knots().to_vec();
    let jumps = law.jumps();
    check_finite(
        &[
            peaks.a1,
            peaks.a2,
            peaks.a_max_abs,
            peaks.v_max_abs,
            peaks.jerk_max_abs_finite,
        ],
        "peaks",
    )?;
    check_finite(
        &knots
            .iter()
            .flat_map(|k| [k.s, k.v, k.a_left, k.a_right])
            .collect::<Vec<_>>(),
        "knots",
    )?;
    let warnings = warnings(input, &law, &jumps, out.stop);

    // Optional outputs, each computed only when requested.
    let error_table = if input.outputs.error_table {
        Some(error_table(input, &law, &mut dtw)?)
    } else {
        None
    };
    let classification = input.outputs.classify.then(|| {
        let (entry, dist) = nearest(law.coefficients());
        (format!("{} {}", entry.id, entry.name), dist)
    });
    let curves = curves(input, &law)?;

    Ok(FitOutput {
        coefficients: law.coefficients().to_vec(),
        durations: law.durations().to_vec(),
        knots,
        peaks,
        jumps,
        objective: ObjectiveValues {
            initial: initial_value,
            final_value,
        },
        error_table,
        classification,
        curves,
        history,
        stats: RunStats {
            evaluations,
            iterations,
            cpu_ms,
            stop: out.stop,
            starts_used: out.starts_used,
            snapped: out.snapped,
        },
        warnings,
    })
}

/// The findings of spec §4 (validation findings first).
fn warnings(
    input: &FitInput,
    law: &SevenSegmentLaw,
    jumps: &[Jump],
    stop: StopReason,
) -> Vec<LawNotice> {
    let mut warnings = input.warnings.clone();
    let bc = &input.bc;
    let ds = bc.s_b - bc.s_a;
    let a_tol = JUMP_REL_TOL * law.peaks().a_max_abs.max(bc.a_a.abs()).max(bc.a_b.abs());
    if ds != 0.0 && (ds.signum() * law.a1() < -a_tol || ds.signum() * law.a2() > a_tol) {
        warnings.push(LawNotice::PeakSignUnusual);
    }
    if segment_below_resolution(law, &input.data.xs_model, jumps) {
        warnings.push(LawNotice::SegmentBelowResolution);
    }
    if matches!(stop, StopReason::Deadline | StopReason::MaxEvaluations) {
        warnings.push(LawNotice::BudgetExhausted);
    }
    warnings
}

/// Distances between the law and every supplied (or derived) channel, indexed s, v, a.
fn error_table(
    input: &FitInput,
    law: &SevenSegmentLaw,
    dtw: &mut Dtw,
) -> Result<[Option<ChannelErrors>; 3], FitError> {
    let mut table = [None; 3];
    for q in Channel::ALL {
        if let Some(d) = input.data.channels[q.index()].as_deref() {
            let mut m = vec![0.0; d.len()];
            law.eval_quantity_into(&input.data.xs_model, q.quantity(), &mut m);
            let e = ChannelErrors {
                euclidean: euclidean(&m, d),
                dtw: dtw.distance(&m, d, input.objective.dtw_window),
            };
            check_finite(&[e.euclidean, e.dtw], "error table")?;
            table[q.index()] = Some(e);
        }
    }
    Ok(table)
}

/// The law on a uniform grid over `[t_a, t_b]`, when asked for.
fn curves(input: &FitInput, law: &SevenSegmentLaw) -> Result<Option<SampledCurves>, FitError> {
    let asked = &input.outputs;
    if asked.curve_count == 0 {
        return Ok(None);
    }
    let xs = grid::linspace(input.bc.t_a, input.bc.t_b, asked.curve_count);
    let mut c = SampledCurves::at(&xs);
    for &q in &asked.curve_quantities {
        let mut v = vec![0.0; xs.len()];
        law.eval_quantity_into(&xs, q, &mut v);
        check_finite(&v, "curves")?;
        c.set(q, v);
    }
    Ok(Some(c))
}

/// `segment_below_resolution` (spec §4, §6 item 4): a non-zero segment shorter than the local
/// sample spacing that either touches an acceleration jump of the fitted law or is itself a
/// transition segment (0, 2, 4, 6) whose acceleration change the samples cannot resolve.
fn segment_below_resolution(law: &SevenSegmentLaw, xs: &[f64], jumps: &[Jump]) -> bool {
    if xs.len() < 2 {
        return false;
    }
    let t = law.knot_times();
    let dur = law.durations();
    let knots = law.knots();
    let scale = law.peaks().a_max_abs;
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (t[7] - t[0]);
    (0..7).any(|k| {
        let c = dur[k];
        if c <= 0.0 {
            return false;
        }
        let mid = 0.5 * (t[k] + t[k + 1]);
        let j = xs.partition_point(|x| *x <= mid).clamp(1, xs.len() - 1);
        let h = xs[j] - xs[j - 1];
        if c >= h {
            return false;
        }
        let touches_jump = jumps
            .iter()
            .any(|jp| near(jp.x, t[k]) || near(jp.x, t[k + 1]));
        let transition = matches!(k, 0 | 2 | 4 | 6)
            && (knots[k].a_right - knots[k + 1].a_left).abs() > JUMP_REL_TOL * scale;
        touches_jump || transition
    })
}
