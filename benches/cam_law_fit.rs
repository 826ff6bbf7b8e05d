//! Benchmarks of the cam-law fit (spec §7): coefficient error and objective against time for
//! every optimizer on the spec's §7.2 benchmark cases, the accuracy-vs-cost knobs (N, DTW band,
//! snap tolerance, DTW restarts, GA population/generations), and criterion timings of `auto` on
//! the Table-3 laws and of one objective evaluation.
//!
//! Run: `cargo bench --bench cam_law_fit`. The markdown tables for `benches/RESULTS.md` are
//! printed before criterion runs. `CAMFIT_BENCH_SEEDS` (default 3) sets the seeds per stochastic
//! method; `CAMFIT_BENCH_TABLES=0` skips the tables.
//!
//! Time to target: each run is repeated with a tracing model that records (time, objective,
//! coefficient error) at every improvement; the tracing doubles the objective work, so its
//! times are rescaled by (plain run time / traced run time).

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::cell::RefCell;
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use mechcalc::calc::cam_law::catalogue::{NamedLaw, TABLE3};
use mechcalc::calc::cam_law::law::{BoundaryConditions, Quantity, SevenSegmentLaw};
use mechcalc::calc::cam_law_fit::compute::{Algorithm, FitOutcome, LawModel, Settings, fit};
use mechcalc::calc::cam_law_fit::objective::{Ctx, CurveModel, Dtw, Metric, euclidean};
use mechcalc::calc::cam_law_fit::optim::ga::GaParams;
use mechcalc::calc::cam_law_fit::optim::normalized;
use mechcalc::numerics::Budget;
use mechcalc::numerics::grid::linspace;

#[path = "../tests/support/cam_table1.rs"]
mod cam_table1;
use cam_table1::{TABLE1_BC, TABLE1_C};

/// Best-known answer of the noisy Table-1 case (spec §5.4), used as its "truth".
const NOISY_BEST: [f64; 7] = [
    0.063652, 0.148306, 0.169314, 0.094919, 0.332718, 0.150644, 0.040448,
];

fn table1_columns() -> (Vec<f64>, Vec<f64>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cam_law_fit/table1_case_n300.csv");
    let text = std::fs::read_to_string(path).expect("data file");
    let (mut a, mut noisy) = (Vec::new(), Vec::new());
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.trim().parse().expect("number"))
            .collect();
        a.push(v[3]);
        noisy.push(v[4]);
    }
    (a, noisy)
}

/// One benchmark case of spec §7.2.
struct Case {
    name: &'static str,
    bc: BoundaryConditions,
    quantity: Quantity,
    metric: Metric,
    data: Vec<f64>,
    /// Reference coefficients (generating law or best-known point), if any.
    truth: Option<[f64; 7]>,
    /// Target objective f* (0 for representable laws).
    f_star: f64,
}

/// `n` equally spaced abscissae over [t_a, t_b] and the quantity `q` of the law (c, bc) there.
fn sampled(c: &[f64; 7], bc: &BoundaryConditions, q: Quantity, n: usize) -> (Vec<f64>, Vec<f64>) {
    let xs = linspace(bc.t_a, bc.t_b, n);
    let law = SevenSegmentLaw::try_new(c, bc).expect("law");
    let mut y = vec![0.0; n];
    law.eval_quantity_into(&xs, q, &mut y);
    (xs, y)
}

fn law_case(name: &'static str, c: [f64; 7], q: Quantity, metric: Metric) -> Case {
    let (_, y) = sampled(&c, &BoundaryConditions::UNIT_RISE, q, 300);
    Case {
        name,
        bc: BoundaryConditions::UNIT_RISE,
        quantity: q,
        metric,
        data: y,
        truth: Some(normalized(&c)),
        f_star: 0.0,
    }
}

fn poly_case(name: &'static str, law: NamedLaw, q: Quantity, metric: Metric, f_star: f64) -> Case {
    let xs = linspace(0.0, 1.0, 300);
    Case {
        name,
        bc: BoundaryConditions::UNIT_RISE,
        quantity: q,
        metric,
        data: xs.iter().map(|x| law.eval_normalized(*x).get(q)).collect(),
        truth: None,
        f_star,
    }
}

fn cases() -> Vec<Case> {
    let (a, noisy) = table1_columns();
    let t1 = |name, data, metric, truth, f_star| Case {
        name,
        bc: TABLE1_BC,
        quantity: Quantity::A,
        metric,
        data,
        truth: Some(truth),
        f_star,
    };
    vec![
        t1(
            "Table-1 clean, a/EN",
            a.clone(),
            Metric::Euclidean,
            normalized(&TABLE1_C),
            0.0,
        ),
        law_case(
            "L1 modified sine, a/EN",
            TABLE3[0].coefficients,
            Quantity::A,
            Metric::Euclidean,
        ),
        law_case(
            "L4 harmonic, a/EN",
            TABLE3[3].coefficients,
            Quantity::A,
            Metric::Euclidean,
        ),
        law_case(
            "L9 asymmetric, a/EN",
            TABLE3[8].coefficients,
            Quantity::A,
            Metric::Euclidean,
        ),
        law_case(
            "L7, v/EN",
            TABLE3[6].coefficients,
            Quantity::V,
            Metric::Euclidean,
        ),
        poly_case(
            "4-5-6-7 poly, a/EN",
            NamedLaw::Polynomial4567,
            Quantity::A,
            Metric::Euclidean,
            9.37968,
        ),
        t1(
            "Table-1 noisy, a/EN",
            noisy,
            Metric::Euclidean,
            NOISY_BEST,
            16.6840,
        ),
        t1(
            "Table-1 clean, a/DTW",
            a,
            Metric::Dtw { window: 1 },
            normalized(&TABLE1_C),
            0.0,
        ),
        poly_case(
            "3-4-5 poly, s/DTW",
            NamedLaw::Polynomial345,
            Quantity::S,
            Metric::Dtw { window: 1 },
            0.023959,
        ),
    ]
}

/// Best objective so far, DTW scratch, and the improvements (time [s], objective, error).
type TraceState = (f64, Dtw, Vec<(f64, f64, f64)>);

/// A model that also computes the objective and records every improvement.
struct Traced<'a> {
    inner: LawModel<'a>,
    data: &'a [f64],
    metric: Metric,
    truth: Option<[f64; 7]>,
    start: Instant,
    state: RefCell<TraceState>,
}

impl CurveModel for Traced<'_> {
    fn curve(&self, g: &[f64; 7], out: &mut [f64]) -> bool {
        let ok = self.inner.curve(g, out);
        if ok {
            let mut st = self.state.borrow_mut();
            let f = match self.metric {
                Metric::Euclidean => euclidean(out, self.data),
                Metric::Dtw { window } => st.1.distance(out, self.data, window),
            };
            if f < st.0 {
                st.0 = f;
                let err = self.truth.map_or(f64::NAN, |t| max_err(&normalized(g), &t));
                st.2.push((self.start.elapsed().as_secs_f64(), f, err));
            }
        }
        ok
    }
}

fn max_err(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[derive(Clone, Copy)]
struct Variant {
    label: &'static str,
    method: Algorithm,
    polish: bool,
    stochastic: bool,
    dtw: bool,
}

const VARIANTS: [Variant; 6] = [
    Variant {
        label: "GA (paper)",
        method: Algorithm::Ga,
        polish: false,
        stochastic: true,
        dtw: true,
    },
    Variant {
        label: "DE",
        method: Algorithm::De,
        polish: false,
        stochastic: true,
        dtw: true,
    },
    Variant {
        label: "DE+LSQ",
        method: Algorithm::De,
        polish: true,
        stochastic: true,
        dtw: false,
    },
    Variant {
        label: "CMA-ES",
        method: Algorithm::Cmaes,
        polish: false,
        stochastic: true,
        dtw: true,
    },
    Variant {
        label: "LSQ from 1/7",
        method: Algorithm::Lsq,
        polish: false,
        stochastic: false,
        dtw: false,
    },
    Variant {
        label: "auto",
        method: Algorithm::Auto,
        polish: true,
        stochastic: false,
        dtw: true,
    },
];

fn settings(v: Variant, seed: u64, restarts: u32) -> Settings {
    Settings {
        method: v.method,
        seed,
        ga: GaParams::default(),
        dtw_global_restarts: restarts,
        polish: v.polish,
        snap_tol: 2e-3,
        initial: [1.0 / 7.0; 7],
        fixed_zero: [false; 7],
        max_evaluations: 50_000,
    }
}

struct RunStats {
    secs: f64,
    f: f64,
    err: f64,
    evals: u64,
    /// Rescaled time at which the objective first met the target, if it did.
    hit: Option<f64>,
}

/// One fit run plain (timed), then again with the tracing model; the trace's times are rescaled
/// to the plain run (module docs).
struct TracedFit {
    secs: f64,
    evals: u64,
    out: FitOutcome,
    /// (rescaled time [s], objective, coefficient error) at every improvement.
    trace: Vec<(f64, f64, f64)>,
}

/// One fit of `case` with `s` under `budget`: the outcome, its wall time [s] and the objective
/// evaluations it made.
fn plain_fit(case: &Case, s: &Settings, budget: Budget) -> (FitOutcome, f64, u64) {
    let xs = linspace(0.0, 1.0, case.data.len());
    let model = LawModel {
        xs: &xs,
        bc: case.bc,
        quantity: case.quantity,
    };
    let t = Instant::now();
    let mut ctx = Ctx::new(&model, &case.data, case.metric, budget, false);
    let out = fit(&mut ctx, s);
    (out, t.elapsed().as_secs_f64(), ctx.evaluations())
}

fn traced_fit(case: &Case, s: &Settings) -> TracedFit {
    let budget = || Budget::unlimited().with_max_evaluations(50_000);
    let (out, secs, evals) = plain_fit(case, s, budget());
    let xs = linspace(0.0, 1.0, case.data.len());
    let traced = Traced {
        inner: LawModel {
            xs: &xs,
            bc: case.bc,
            quantity: case.quantity,
        },
        data: &case.data,
        metric: case.metric,
        truth: case.truth,
        start: Instant::now(),
        state: RefCell::new((f64::INFINITY, Dtw::new(), Vec::new())),
    };
    let mut ctx = Ctx::new(&traced, &case.data, case.metric, budget(), false);
    let _ = fit(&mut ctx, s);
    let traced_secs = traced.start.elapsed().as_secs_f64();
    let scale = if traced_secs > 0.0 {
        secs / traced_secs
    } else {
        1.0
    };
    let trace = traced
        .state
        .borrow()
        .2
        .iter()
        .map(|&(t, f, e)| (t * scale, f, e))
        .collect();
    TracedFit {
        secs,
        evals,
        out,
        trace,
    }
}

fn run_case(case: &Case, s: &Settings) -> RunStats {
    let run = traced_fit(case, s);
    let target = case.f_star.mul_add(1.0 + 1e-4, 1e-8);
    let hit = run
        .trace
        .iter()
        .find(|(_, f, _)| *f <= target)
        .map(|(t, _, _)| *t);
    RunStats {
        secs: run.secs,
        f: run.out.best,
        err: case
            .truth
            .map_or(f64::NAN, |t| max_err(&run.out.coefficients, &t)),
        evals: run.evals,
        hit,
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

fn fmt_err(e: f64) -> String {
    if e.is_nan() {
        "—".into()
    } else {
        format!("{e:.1e}")
    }
}

fn optimizer_table(seeds: u64) {
    println!(
        "\n### Optimizers on the spec §7.2 cases (N = 300; {seeds} seeds per stochastic method)\n"
    );
    println!(
        "Cell: hits/runs, median time to target, median final max coefficient error (or final objective f when no reference coefficients), median total time and evaluations of the run.\n"
    );
    let cs = cases();
    print!("| case |");
    for v in VARIANTS {
        print!(" {} |", v.label);
    }
    println!();
    print!("|---|");
    for _ in VARIANTS {
        print!("---|");
    }
    println!();
    for case in &cs {
        print!("| {} |", case.name);
        let is_dtw = matches!(case.metric, Metric::Dtw { .. });
        for v in VARIANTS {
            if is_dtw && !v.dtw {
                print!(" n/a |");
                continue;
            }
            let n_seeds = if v.stochastic { seeds } else { 1 };
            let runs: Vec<RunStats> = (0..n_seeds)
                .map(|seed| run_case(case, &settings(v, seed, 3)))
                .collect();
            let hits: Vec<f64> = runs.iter().filter_map(|r| r.hit).collect();
            let mut hit_times = hits.clone();
            let mut errs: Vec<f64> = runs
                .iter()
                .map(|r| if case.truth.is_some() { r.err } else { r.f })
                .collect();
            let mut secs: Vec<f64> = runs.iter().map(|r| r.secs).collect();
            #[allow(clippy::cast_precision_loss)]
            let mut evals: Vec<f64> = runs.iter().map(|r| r.evals as f64).collect();
            let hit_str = if hits.is_empty() {
                String::new()
            } else {
                format!(" @{:.3} s", median(&mut hit_times))
            };
            let e = median(&mut errs);
            let e_str = if case.truth.is_some() {
                format!("err {}", fmt_err(e))
            } else {
                format!("f {e:.6}")
            };
            print!(
                " {}/{}{hit_str}; {e_str}; {:.3} s, {:.0} ev |",
                hits.len(),
                runs.len(),
                median(&mut secs),
                median(&mut evals)
            );
        }
        println!();
    }
}

fn ga_error_vs_time(seeds: u64) {
    println!(
        "\n### Paper GA on the Table-1 case: max coefficient error of the best-so-far vs time (median of {seeds} seeds)\n"
    );
    let case = &cases()[0];
    let marks = [0.05, 0.1, 0.2, 0.4, 0.8, 1.6];
    let mut per_mark: Vec<Vec<f64>> = vec![Vec::new(); marks.len()];
    for seed in 0..seeds {
        let run = traced_fit(case, &settings(VARIANTS[0], seed, 0));
        for (m, slot) in marks.iter().zip(per_mark.iter_mut()) {
            let e = run
                .trace
                .iter()
                .rev()
                .find(|(t, _, _)| t <= m)
                .map(|(_, _, e)| *e)
                .unwrap_or(f64::NAN);
            slot.push(e);
        }
    }
    println!(
        "| time [s] | {} |",
        marks.map(|m| format!("{m}")).join(" | ")
    );
    println!("|---|{}", "---|".repeat(marks.len()));
    let cells: Vec<String> = per_mark.iter_mut().map(|v| fmt_err(median(v))).collect();
    println!("| max coefficient error | {} |", cells.join(" | "));
}

fn time_runs(reps: usize, mut f: impl FnMut() -> f64) -> (f64, f64, f64) {
    let mut t = Vec::with_capacity(reps);
    let mut err = 0.0;
    for _ in 0..reps {
        let s = Instant::now();
        err = f();
        t.push(s.elapsed().as_secs_f64() * 1e3);
    }
    t.sort_by(f64::total_cmp);
    (t[t.len() / 2], t[t.len() - 1], err)
}

fn auto_fit(
    c: &[f64; 7],
    bc: &BoundaryConditions,
    q: Quantity,
    metric: Metric,
    n: usize,
    snap: f64,
    restarts: u32,
) -> (f64, u64) {
    let (xs, y) = sampled(c, bc, q, n);
    let model = LawModel {
        xs: &xs,
        bc: *bc,
        quantity: q,
    };
    let mut ctx = Ctx::new(
        &model,
        &y,
        metric,
        Budget::unlimited().with_max_evaluations(50_000),
        false,
    );
    let mut s = settings(VARIANTS[5], 0, restarts);
    s.snap_tol = snap;
    let out = fit(&mut ctx, &s);
    (
        max_err(&out.coefficients, &normalized(c)),
        ctx.evaluations(),
    )
}

#[expect(
    clippy::too_many_lines,
    reason = "prints the six knob tables of benches/RESULTS.md (auto on Table 3, N, snap_tol, dtw_window, dtw_global_restarts, GA size) in the order they appear there"
)]
fn knob_tables() {
    println!(
        "\n### `auto`, every Table-3 law from noiseless samples, N = 300, EN (target: error ≤ 1e-9 in < 10 ms)\n"
    );
    println!("| law | fit_on | median ms | worst ms | max coefficient error | evaluations |");
    println!("|---|---|---|---|---|---|");
    for q in [Quantity::A, Quantity::V] {
        for e in &TABLE3 {
            let mut evals = 0;
            let (med, worst, err) = time_runs(7, || {
                let (err, ev) = auto_fit(
                    &e.coefficients,
                    &BoundaryConditions::UNIT_RISE,
                    q,
                    Metric::Euclidean,
                    300,
                    2e-3,
                    3,
                );
                evals = ev;
                err
            });
            println!(
                "| {} {} | {q:?} | {med:.2} | {worst:.2} | {err:.1e} | {evals} |",
                e.id, e.name
            );
        }
    }

    println!("\n### Knob N (`auto`, Table-1 law, acceleration, EN)\n");
    println!("| N | median ms | worst ms | max coefficient error | evaluations |");
    println!("|---|---|---|---|---|");
    for n in [30usize, 100, 300, 1_000, 10_000, 100_000] {
        let reps = if n >= 10_000 { 3 } else { 7 };
        let mut evals = 0;
        let (med, worst, err) = time_runs(reps, || {
            let (err, ev) = auto_fit(
                &TABLE1_C,
                &TABLE1_BC,
                Quantity::A,
                Metric::Euclidean,
                n,
                2e-3,
                3,
            );
            evals = ev;
            err
        });
        let mark = if n == 300 { " (spec case)" } else { "" };
        println!("| {n}{mark} | {med:.2} | {worst:.2} | {err:.1e} | {evals} |");
    }

    println!("\n### Knob snap_tol (`auto`, N = 300, EN, acceleration)\n");
    println!("| snap_tol | law | median ms | worst ms | max coefficient error | evaluations |");
    println!("|---|---|---|---|---|---|");
    for snap in [0.0, 1e-4, 2e-3, 1e-2, 5e-2] {
        for idx in [2usize, 3, 8] {
            let e = &TABLE3[idx];
            let mut evals = 0;
            let (med, worst, err) = time_runs(5, || {
                let (err, ev) = auto_fit(
                    &e.coefficients,
                    &BoundaryConditions::UNIT_RISE,
                    Quantity::A,
                    Metric::Euclidean,
                    300,
                    snap,
                    3,
                );
                evals = ev;
                err
            });
            let mark = if (snap - 2e-3).abs() < 1e-15 {
                " (default)"
            } else {
                ""
            };
            println!(
                "| {snap}{mark} | {} | {med:.2} | {worst:.2} | {err:.1e} | {evals} |",
                e.id
            );
        }
    }

    println!(
        "\n### Knob dtw_window: cost of one objective evaluation (Table-1 law, N = 300; EN for comparison)\n"
    );
    println!("| objective | median µs/evaluation | worst µs/evaluation |");
    println!("|---|---|---|");
    let (xs, data) = sampled(&TABLE1_C, &TABLE1_BC, Quantity::A, 300);
    let model = LawModel {
        xs: &xs,
        bc: TABLE1_BC,
        quantity: Quantity::A,
    };
    let g = [1.0; 7];
    for (label, metric) in [
        ("EN", Metric::Euclidean),
        ("DTW w = 0", Metric::Dtw { window: 0 }),
        ("DTW w = 1 (default)", Metric::Dtw { window: 1 }),
        ("DTW w = 5", Metric::Dtw { window: 5 }),
        ("DTW w = 30 (N/10)", Metric::Dtw { window: 30 }),
        ("DTW full (w = N)", Metric::Dtw { window: 300 }),
    ] {
        let mut ctx = Ctx::new(&model, &data, metric, Budget::unlimited(), false);
        let reps = 2000;
        let mut t = Vec::with_capacity(50);
        for _ in 0..50 {
            let s = Instant::now();
            for _ in 0..reps / 50 {
                black_box(ctx.value(black_box(&g)).ok());
            }
            #[allow(clippy::cast_precision_loss)]
            t.push(s.elapsed().as_secs_f64() * 1e6 / (reps / 50) as f64);
        }
        t.sort_by(f64::total_cmp);
        println!(
            "| {label} | {:.2} | {:.2} |",
            t[t.len() / 2],
            t[t.len() - 1]
        );
    }

    println!("\n### Knob dtw_global_restarts (`auto`, 3-4-5 s/DTW, f* = 0.023959; seeds 0..5)\n");
    println!("| restarts | hits (f ≤ 1.02 f*) | median f | median s | median evaluations |");
    println!("|---|---|---|---|---|");
    let case = poly_case(
        "3-4-5 poly, s/DTW",
        NamedLaw::Polynomial345,
        Quantity::S,
        Metric::Dtw { window: 1 },
        0.023959,
    );
    for restarts in [0u32, 1, 3, 5] {
        let mut fs = Vec::new();
        let mut secs = Vec::new();
        let mut evs = Vec::new();
        for seed in 0..6 {
            let (out, t, evals) = plain_fit(
                &case,
                &settings(VARIANTS[5], seed, restarts),
                Budget::unlimited().with_max_evaluations(200_000),
            );
            secs.push(t);
            fs.push(out.best);
            #[allow(clippy::cast_precision_loss)]
            evs.push(evals as f64);
        }
        let hits = fs.iter().filter(|f| **f <= 1.02 * case.f_star).count();
        let mark = if restarts == 3 { " (default)" } else { "" };
        println!(
            "| {restarts}{mark} | {hits}/6 | {:.6} | {:.3} | {:.0} |",
            median(&mut fs),
            median(&mut secs),
            median(&mut evs)
        );
    }

    println!("\n### Knob GA population × generations (paper GA alone, Table-1 clean, 3 seeds)\n");
    println!(
        "| population × generations | median s | median max coefficient error | worst error |"
    );
    println!("|---|---|---|---|");
    let case = &cases()[0];
    for (pop, gens) in [(50usize, 250u64), (100, 250), (100, 500), (200, 500)] {
        let mut errs = Vec::new();
        let mut secs = Vec::new();
        for seed in 0..3 {
            let mut s = settings(VARIANTS[0], seed, 0);
            s.ga.population = pop;
            s.ga.generations = gens;
            let (out, t, _) = plain_fit(case, &s, Budget::unlimited());
            secs.push(t);
            errs.push(max_err(&out.coefficients, &normalized(&TABLE1_C)));
        }
        let worst = errs.iter().copied().fold(0.0, f64::max);
        let mark = if pop == 100 && gens == 500 {
            " (paper)"
        } else {
            ""
        };
        println!(
            "| {pop} × {gens}{mark} | {:.3} | {} | {} |",
            median(&mut secs),
            fmt_err(median(&mut errs)),
            fmt_err(worst)
        );
    }
}

fn print_tables() {
    if std::env::var("CAMFIT_BENCH_TABLES").is_ok_and(|v| v == "0") {
        return;
    }
    let seeds: u64 = std::env::var("CAMFIT_BENCH_SEEDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    knob_tables();
    optimizer_table(seeds);
    ga_error_vs_time(seeds);
    println!();
}

fn benches(c: &mut Criterion) {
    print_tables();
    let mut g = c.benchmark_group("cam_law_fit/auto_en_accel_n300");
    g.sample_size(20).measurement_time(Duration::from_secs(2));
    for e in &TABLE3 {
        g.bench_with_input(
            BenchmarkId::from_parameter(e.id),
            &e.coefficients,
            |b, c| {
                b.iter(|| {
                    auto_fit(
                        black_box(c),
                        &BoundaryConditions::UNIT_RISE,
                        Quantity::A,
                        Metric::Euclidean,
                        300,
                        2e-3,
                        3,
                    )
                });
            },
        );
    }
    g.finish();
    let mut g = c.benchmark_group("cam_law_fit/objective_n300");
    let (xs, data) = sampled(&TABLE1_C, &TABLE1_BC, Quantity::A, 300);
    let model = LawModel {
        xs: &xs,
        bc: TABLE1_BC,
        quantity: Quantity::A,
    };
    for (label, metric) in [
        ("EN", Metric::Euclidean),
        ("DTW_w1", Metric::Dtw { window: 1 }),
        ("DTW_w5", Metric::Dtw { window: 5 }),
    ] {
        let mut ctx = Ctx::new(&model, &data, metric, Budget::unlimited(), false);
        g.bench_function(label, |b| b.iter(|| ctx.value(black_box(&[1.0; 7])).ok()));
    }
    g.finish();
}

criterion_group!(cam_law_fit, benches);
criterion_main!(cam_law_fit);
