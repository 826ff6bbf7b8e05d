//! Benchmarks of the IREFC endpoints (specs `irefc_stress.md` and `irefc_efficiency.md`, "Accuracy-vs-cost
//! knobs and benchmark").
//!
//! Before criterion runs, plain tables are printed for `benches/RESULTS.md`:
//! 1. stress: max-stress error against time for the φ2 grid step × refine × load-sharing mode, over the
//!    spec's six designs plus three near-undercut designs; reference = step 0.001° + refine;
//! 2. the 6541-combination sweep (Z2 10..40 × χ 1.25..1.67 step 0.002) at the paper's setting (0.02°, no
//!    refine) and at the fast setting (1° + refine): total time and the largest σ difference;
//! 3. efficiency: |mean η − reference| against time for n_phase (reference n_phase = 20 000).
//!
//! Run: `cargo bench --bench irefc`. `IREFC_BENCH_REPS` sets the repetitions per timing (default 21).

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group};

#[path = "support/mod.rs"]
mod support;
use mechcalc::calc::irefc::efficiency::compute;
use mechcalc::calc::irefc::efficiency::input::EfficiencyInput;
use mechcalc::calc::irefc::stress::wire::{StressSingleResponse, StressSweepResponse};
use mechcalc::calc::irefc::{
    IrefcEfficiencyRequest, IrefcEfficiencyResponse, IrefcStressRequest, IrefcStressResponse,
    run_efficiency, run_stress,
};
use mechcalc::numerics::Budget;
use serde_json::{Value, json};

/// The spec's six designs (r2 = 20 mm, rb = 2 mm; χ spread over [1.25, 1.67]) and its three near-undercut
/// designs (Z2, χ, rb_mm).
const DESIGNS: [(u32, f64, f64); 9] = [
    (10, 1.25, 2.0),
    (14, 1.33, 2.0),
    (18, 1.42, 2.0),
    (26, 1.50, 2.0),
    (34, 1.58, 2.0),
    (40, 1.67, 2.0),
    (26, 1.40, 3.3),
    (12, 1.25, 5.2),
    (34, 1.31, 2.0),
];
const STEPS: [f64; 8] = [2.0, 1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01];
const REFERENCE_STEP: f64 = 0.001;

fn reps() -> usize {
    std::env::var("IREFC_BENCH_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(21)
}

fn stress_req(
    z2: u32,
    chi: f64,
    rb: f64,
    step: f64,
    refine: bool,
    mode: &str,
) -> IrefcStressRequest {
    serde_json::from_value(
        json!({"r2_mm": 20, "Z2": z2, "chi": chi, "rb_mm": rb, "lb_mm": 4,
        "torque_Nm": 119.366207, "step_deg": step, "refine": refine, "load_sharing": mode}),
    )
    .expect("valid request")
}

fn single(req: IrefcStressRequest) -> StressSingleResponse {
    match run_stress(req, &Budget::unlimited()).expect("feasible design") {
        IrefcStressResponse::Single(r) => *r,
        IrefcStressResponse::Sweep(_) => unreachable!("single request"),
    }
}

fn sweep_req(step: f64, refine: bool) -> IrefcStressRequest {
    serde_json::from_value(
        json!({"mode": "sweep", "r2_mm": 20, "rb_mm": 2, "torque_Nm": 119.366207,
        "step_deg": step, "refine": refine,
        "sweep": {"Z2": {"from": 10, "to": 40}, "chi": {"from": 1.25, "to": 1.67, "step": 0.002}}}),
    )
    .expect("valid request")
}

/// The sweep with the default budget (every core of the machine).
fn sweep(req: IrefcStressRequest) -> StressSweepResponse {
    sweep_with(req, &Budget::unlimited())
}

fn sweep_on(req: IrefcStressRequest, threads: usize) -> StressSweepResponse {
    sweep_with(req, &Budget::unlimited().with_threads(threads))
}

fn sweep_with(req: IrefcStressRequest, budget: &Budget) -> StressSweepResponse {
    match run_stress(req, budget).expect("valid sweep") {
        IrefcStressResponse::Sweep(r) => r,
        IrefcStressResponse::Single(_) => unreachable!("sweep request"),
    }
}

fn eff_req(z2: u32, n_phase: u32) -> IrefcEfficiencyRequest {
    serde_json::from_value(
        json!({"r2_mm": 20, "Z2": z2, "chi": 1.4, "rb_mm": 2, "power_W": 1500,
        "speed_rpm": 1500, "n_phase": n_phase, "include": {"elements": false}}),
    )
    .expect("valid request")
}

fn eff(req: IrefcEfficiencyRequest) -> IrefcEfficiencyResponse {
    run_efficiency(req, &Budget::unlimited()).expect("feasible")
}

/// Median and worst of `reps` wall times of `f` [µs] (the shared timing helper).
fn time_us<T>(reps: usize, f: impl FnMut() -> T) -> (f64, f64) {
    let (t, _) = support::time_runs(reps, f);
    (t.median_us(), t.worst_us())
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn stress_table() {
    let n = reps();
    println!(
        "\n### irefc stress: max contact stress error vs time (grid step x refine x load sharing)\n"
    );
    println!(
        "Reference per design and mode: step {REFERENCE_STEP} deg + refine. Error = worst relative error of"
    );
    println!(
        "the cam and crown maxima over the 9 designs; time = median (worst) per design of the median of"
    );
    println!("{n} calls of `run_stress` (elements on), averaged over the designs.\n");
    println!(
        "| load_sharing | step deg | refine | grid points scanned | median us/design | worst us/design | max rel err (6 spec designs) | max rel err (3 near-undercut) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for mode in ["paper_phase0", "phase_exact"] {
        let refs: Vec<(f64, f64)> = DESIGNS
            .iter()
            .map(|&(z, c, rb)| {
                let r = single(stress_req(z, c, rb, REFERENCE_STEP, true, mode));
                (r.max.cam.sigma_mpa, r.max.crown.sigma_mpa)
            })
            .collect();
        for refine in [false, true] {
            for step in STEPS {
                let mut med = 0.0;
                let mut worst: f64 = 0.0;
                let mut err = [0.0f64; 2];
                let mut scanned = (u64::MAX, 0u64);
                for (i, (&(z, c, rb), &(rc, rk))) in DESIGNS.iter().zip(&refs).enumerate() {
                    let r = single(stress_req(z, c, rb, step, refine, mode));
                    let e = rel(r.max.cam.sigma_mpa, rc).max(rel(r.max.crown.sigma_mpa, rk));
                    scanned = (scanned.0.min(r.meta.n_grid), scanned.1.max(r.meta.n_grid));
                    let slot = usize::from(i >= 6);
                    err[slot] = err[slot].max(e);
                    let (m, w) = time_us(n, || single(stress_req(z, c, rb, step, refine, mode)));
                    med += m / DESIGNS.len() as f64;
                    worst = worst.max(w);
                }
                let n_grid = if scanned.0 == scanned.1 {
                    scanned.0.to_string()
                } else {
                    format!("{}–{}", scanned.0, scanned.1)
                };
                let mark = if refine && (step - 1.0).abs() < 1e-12 && mode == "paper_phase0" {
                    " **(default)**"
                } else if !refine && (step - 0.02).abs() < 1e-12 && mode == "paper_phase0" {
                    " (paper)"
                } else {
                    ""
                };
                println!(
                    "| {mode} | {step}{mark} | {refine} | {n_grid} | {med:.1} | {worst:.1} | {:.1e} | {:.1e} |",
                    err[0], err[1]
                );
            }
        }
    }
}

fn sweep_table() {
    println!(
        "\n### irefc stress: 6541-combination sweep (Z2 10..40 x chi 1.25..1.67 step 0.002, r2 = 20, rb = 2)\n"
    );
    let n = (reps() / 4).max(5);
    let paper = sweep(sweep_req(0.02, false));
    let fast = sweep(sweep_req(1.0, true));
    let exact = sweep(sweep_req(0.01, true));
    let mut d_paper: f64 = 0.0;
    let mut d_fast: f64 = 0.0;
    for ((p, f), x) in paper.records.iter().zip(&fast.records).zip(&exact.records) {
        if let (Some(p), Some(f), Some(x)) = (p.sigma_max_mpa, f.sigma_max_mpa, x.sigma_max_mpa) {
            d_paper = d_paper.max(rel(p, x));
            d_fast = d_fast.max(rel(f, x));
        }
    }
    println!(
        "{} combinations, {} valid, {} infeasible; threads = {}. Max rel. difference of sigma_max against",
        paper.records.len(),
        paper.n_valid,
        paper.n_invalid,
        paper.meta.threads
    );
    println!(
        "0.01 deg + refine, over the valid records; times = median (worst) of {n} runs of `run_stress`.\n"
    );
    println!("| setting | median ms | worst ms | max rel diff of sigma_max |");
    println!("|---|---|---|---|");
    let (m, w) = time_us(n, || sweep(sweep_req(0.02, false)));
    println!(
        "| 0.02 deg, no refine (paper) | {:.1} | {:.1} | {d_paper:.1e} |",
        m / 1e3,
        w / 1e3
    );
    let (m, w) = time_us(n, || sweep(sweep_req(1.0, true)));
    println!(
        "| 1 deg + refine (default) | {:.1} | {:.1} | {d_fast:.1e} |",
        m / 1e3,
        w / 1e3
    );
    println!(
        "\nworst design of the sweep: record {:?}, best: record {:?} (same at both settings: {})",
        fast.worst,
        fast.best,
        fast.worst == paper.worst && fast.best == paper.best
    );
}

/// The sweep on 1 and 2 threads of the compute pool's budget: wall time, process CPU time, and
/// whether the records are identical.
fn threads_table() {
    println!(
        "\n### irefc stress: the 6541-combination sweep on 1 and 2 threads (default setting)\n"
    );
    let n = (reps() / 4).max(5);
    let one = sweep_on(sweep_req(1.0, true), 1);
    println!(
        "| threads | median ms | worst ms | process CPU ms per run | records identical to 1 thread |"
    );
    println!("|---|---|---|---|---|");
    for threads in [1, 2] {
        let cpu0 = support::process_cpu_ms();
        let (t, last) = support::time_runs(n, || sweep_on(sweep_req(1.0, true), threads));
        let cpu = (support::process_cpu_ms() - cpu0) / (n + 1) as f64;
        let same =
            serde_json::to_value(&last.records).ok() == serde_json::to_value(&one.records).ok();
        println!(
            "| {threads} | {:.1} | {:.1} | {cpu:.1} | {same} |",
            t.median_ms(),
            t.worst_ms()
        );
    }
}

fn efficiency_table() {
    let n = reps();
    println!(
        "\n### irefc efficiency: n_phase vs |mean eta - reference| (reference n_phase = 20 000, paper_table)\n"
    );
    println!(
        "| Z2 | n_phase | median us | worst us | abs err mean eta_product | abs err mean eta_linear |"
    );
    println!("|---|---|---|---|---|---|");
    for z2 in [10u32, 26, 40] {
        // n_phase = 20 000 is above the endpoint's limit: run the pure computation directly.
        let mut input = EfficiencyInput::try_from_request(&eff_req(z2, 1)).expect("valid");
        input.n_phase = 20_000;
        let reference = compute::compute(&input, &Budget::unlimited()).expect("computes");
        let rs = reference.stats.expect("stats");
        let rp = rs.eta_product.expect("positive").mean;
        let rl = rs.eta_linear.mean;
        for n_phase in [1u32, 4, 16, 64, 256, 1024] {
            let r = eff(eff_req(z2, n_phase));
            let (p, l) = match &r.phase_stats {
                Some(s) => (s.eta_product.mean.expect("positive"), s.eta_linear.mean),
                None => (r.totals.eta_product.expect("positive"), r.totals.eta_linear),
            };
            let (m, w) = time_us(n, || eff(eff_req(z2, n_phase)));
            let mark = if n_phase == 1 {
                " (paper, default)"
            } else {
                ""
            };
            println!(
                "| {z2} | {n_phase}{mark} | {m:.1} | {w:.1} | {:.1e} | {:.1e} |",
                (p - rp).abs(),
                (l - rl).abs()
            );
        }
    }
    let spread: Vec<String> = [1.0, 0.01]
        .iter()
        .flat_map(|&mu| {
            ["paper_table", "paper_abs", "rigid_body"].into_iter().map(move |model| {
                let req: IrefcEfficiencyRequest = serde_json::from_value::<IrefcEfficiencyRequest>(json!({
                    "r2_mm": 20, "Z2": 26, "chi": 1.4, "rb_mm": 2, "power_W": 1500, "speed_rpm": 1500,
                    "rolling_friction_mm": mu, "model": model}))
                .expect("valid");
                format!("{model} mu={mu} mm: {:.5}", eff(req).totals.eta_product.unwrap_or(f64::NAN))
            })
        })
        .collect();
    println!(
        "\nModel spread (E1 design, eta_product): {}",
        spread.join("; ")
    );
}

fn tables() {
    if std::env::args().any(|a| a == "--list" || a == "--test") {
        return;
    }
    stress_table();
    sweep_table();
    threads_table();
    efficiency_table();
    println!();
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("irefc_stress_single");
    for (name, step, refine) in [("1deg_refine", 1.0, true), ("0.02deg_paper", 0.02, false)] {
        for mode in ["paper_phase0", "phase_exact"] {
            g.bench_function(format!("{name}/{mode}"), |b| {
                b.iter(|| single(black_box(stress_req(26, 1.4, 2.0, step, refine, mode))));
            });
        }
    }
    g.finish();
    let mut g = c.benchmark_group("irefc_stress_sweep_6541");
    g.sample_size(10);
    g.bench_function("1deg_refine", |b| {
        b.iter(|| sweep(black_box(sweep_req(1.0, true))))
    });
    g.bench_function("0.02deg_paper", |b| {
        b.iter(|| sweep(black_box(sweep_req(0.02, false))))
    });
    g.finish();
    let mut g = c.benchmark_group("irefc_efficiency");
    let v: Value =
        json!({"r2_mm": 20, "Z2": 26, "chi": 1.4, "rb_mm": 2, "power_W": 1500, "speed_rpm": 1500});
    g.bench_function("e1_paper_table", |b| {
        b.iter(|| eff(serde_json::from_value(black_box(v.clone())).expect("valid")));
    });
    g.bench_function("e1_n_phase_64", |b| {
        b.iter(|| eff(black_box(eff_req(26, 64))))
    });
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    tables();
    benches();
    Criterion::default().configure_from_args().final_summary();
}
