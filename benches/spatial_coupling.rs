//! Benchmarks of the spatial-coupling endpoint (spec §8): time per point of θ1 sweeps (361, 3601,
//! 10⁶ points; core + summary vs every group with the series), the 3600-point sweep of the issue
//! end to end (`run`, JSON-free, and with JSON encoding), the accuracy against the golden
//! reference, and the numerical-derivative variant against the analytic rates (§7.4).
//!
//! Run: `cargo bench --bench spatial_coupling -- --measurement-time 2 --warm-up-time 1`. Before
//! criterion runs, plain tables (median and worst of repeated timings) are printed for
//! `benches/RESULTS.md`.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

// The shared helpers keep their own formatting (first user of this file; not reformatted here).
#[rustfmt::skip]
#[path = "support/mod.rs"]
mod support;

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use mechcalc::calc::spatial_coupling::{
    SpatialCouplingInput, SpatialCouplingRequest, compute, run,
};
use mechcalc::numerics::Budget;
use serde_json::{Value, json};

use support::time_for;

fn req(v: &Value) -> SpatialCouplingRequest {
    serde_json::from_value(v.clone()).expect("valid request")
}

fn sweep(n: u64, all: bool) -> Value {
    let outputs = if all {
        json!({"contact": true, "relative_1": true, "relative_2": true, "frames": true, "check": true,
               "summary": true, "series": true})
    } else {
        json!({"summary": true})
    };
    json!({"alpha_deg": 15, "beta_deg": 5, "sweep": {"start_deg": 0, "end_deg": 360, "n_points": n},
           "outputs": outputs})
}

/// Independent full-precision reference (spec §6 golden points; vector implementation of §3):
/// (α, β, θ1, θ2, i12, rB, ω31, ω32).
#[allow(clippy::type_complexity, reason = "a literal table")]
const REFERENCE: &[(f64, f64, f64, f64, f64, [f64; 3], f64, f64)] = &[
    (
        15.0,
        15.0,
        30.0,
        56.309_932_474_020_22,
        -1.065_877_420_042_386_2,
        [
            -0.500_000_000_000_000_2,
            -0.224_143_868_042_013_33,
            -0.836_516_303_737_807_9,
        ],
        -0.461_538_461_538_461_56,
        -0.277_350_098_112_614_5,
    ),
    (
        15.0,
        15.0,
        135.0,
        319.106_605_350_869_1,
        -0.989_743_318_610_787,
        [
            1.922_962_686_383_564e-16,
            0.258_819_045_102_520_8,
            0.965_925_826_289_068_4,
        ],
        0.349_927_106_111_882_5,
        -0.377_964_473_009_227_14,
    ),
    (
        15.0,
        5.0,
        30.0,
        56.309_932_474_020_22,
        -1.065_877_420_042_386_2,
        [
            -0.462_771_574_867_289_54,
            -0.074_741_263_337_424_42,
            -0.854_296_549_121_22,
        ],
        -0.461_538_461_538_461_56,
        -0.277_350_098_112_614_5,
    ),
];

fn accuracy() -> f64 {
    let mut worst: f64 = 0.0;
    for &(alpha, beta, t, th2, i12, rb, w31, w32) in REFERENCE {
        let r = run(
            req(
                &json!({"alpha_deg": alpha, "beta_deg": beta, "theta1_deg": [t],
                        "outputs": {"contact": true, "relative_1": true, "relative_2": true}}),
            ),
            &Budget::unlimited(),
        )
        .expect("runs");
        let v = serde_json::to_value(r).expect("json");
        let p = &v["points"][0];
        let f = |x: &Value| x.as_f64().expect("number");
        let mut e =
            |got: f64, want: f64| worst = worst.max((got - want).abs() / want.abs().max(1.0));
        e(f(&p["theta2_deg"]), th2);
        e(f(&p["i12"]), i12);
        for k in 0..3 {
            e(f(&p["contact"]["rB_m"][k]), rb[k]);
        }
        e(f(&p["relative_1"]["omega31_rad_s"]), w31);
        e(f(&p["relative_2"]["omega32_rad_s"]), w32);
    }
    worst
}

fn tables() {
    println!(
        "\nspatial_coupling: time per point of a θ1 sweep (α = 15°, β = 5°; 2-core shared machine; load average {})",
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim()
    );
    println!("| points | outputs | path | threads | median ns/point | worst ns/point |");
    println!("|---|---|---|---|---|---|");
    for n in [361u64, 3601, 1_000_000] {
        for all in [false, true] {
            if n == 1_000_000 && all {
                continue; // the series of 10⁶ points with every group is a 1.5 GB answer
            }
            // One chunk of work below 4096 points: more threads change nothing there.
            let thread_counts: &[usize] = if n > 10_000 { &[1, 2] } else { &[1] };
            for &threads in thread_counts {
                let r = req(&sweep(n, all));
                let input = SpatialCouplingInput::try_from(r.clone()).expect("valid");
                let budget = Budget::unlimited().with_threads(threads);
                let target = Duration::from_millis(if n > 10_000 { 2000 } else { 600 });
                let (t, _) = time_for(target, 2000, || {
                    black_box(compute(&input, &budget).expect("computes"))
                });
                let per = |s: f64| s * 1e9 / n as f64;
                let what = if all {
                    "all groups + series"
                } else {
                    "core + summary"
                };
                println!(
                    "| {n} | {what} | compute | {threads} | {:.1} | {:.1} |",
                    per(t.median_s),
                    per(t.worst_s)
                );
                let (t, _) = time_for(target, 2000, || {
                    black_box(run(r.clone(), &budget).expect("runs"))
                });
                println!(
                    "| {n} | {what} | run (no JSON) | {threads} | {:.1} | {:.1} |",
                    per(t.median_s),
                    per(t.worst_s)
                );
                if n <= 3601 {
                    let (t, _) = time_for(target, 2000, || {
                        black_box(
                            serde_json::to_vec(&run(r.clone(), &budget).expect("runs"))
                                .expect("json")
                                .len(),
                        )
                    });
                    println!(
                        "| {n} | {what} | run + JSON | {threads} | {:.1} | {:.1} |",
                        per(t.median_s),
                        per(t.worst_s)
                    );
                }
            }
        }
    }
    println!(
        "\nmax relative deviation from the golden reference (spec §6, independent implementation): {:.1e}",
        accuracy()
    );
    println!(
        "\n§7.4: ω31 by central differences of θ31 on a periodic sweep vs the analytic rate (α = 15°)"
    );
    println!(
        "| points/rev | max abs error of ω31/ω1 (FD) | analytic | ns/point (sweep with relative_1) |"
    );
    println!("|---|---|---|---|");
    for n in [37u64, 73, 361, 721, 3601] {
        let r = req(
            &json!({"alpha_deg": 15, "sweep": {"start_deg": 0, "end_deg": 360, "n_points": n},
                            "outputs": {"relative_1": true, "series": true, "summary": false}}),
        );
        let budget = Budget::unlimited();
        let (t, out) = time_for(Duration::from_millis(300), 2000, || {
            run(r.clone(), &budget).expect("runs")
        });
        let v = serde_json::to_value(out).expect("json");
        let s = v["series"].as_array().expect("series");
        let th: Vec<f64> = s
            .iter()
            .map(|p| {
                p["relative_1"]["theta31_deg"]
                    .as_f64()
                    .expect("θ31")
                    .to_radians()
            })
            .collect();
        let w: Vec<f64> = s
            .iter()
            .map(|p| p["relative_1"]["omega31_rad_s"].as_f64().expect("ω31"))
            .collect();
        let m = th.len() - 1; // periodic: point m equals point 0
        let h = std::f64::consts::TAU / m as f64;
        let err = (0..m)
            .map(|k| {
                let fd = (th[(k + 1) % m] - th[(k + m - 1) % m]) / (2.0 * h);
                (fd - w[k]).abs()
            })
            .fold(0.0, f64::max);
        println!(
            "| {} | {err:.1e} | exact (closed form) | {:.1} |",
            m,
            t.median_s * 1e9 / n as f64
        );
    }
}

fn benches(c: &mut Criterion) {
    tables();
    let mut g = c.benchmark_group("spatial_coupling");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1));
    let budget = Budget::unlimited().with_threads(1);
    for (name, all) in [
        ("sweep_3600_core_summary", false),
        ("sweep_3600_all_groups", true),
    ] {
        let input = SpatialCouplingInput::try_from(req(&sweep(3601, all))).expect("valid");
        g.bench_function(name, |b| {
            b.iter(|| black_box(compute(&input, &budget).expect("computes")))
        });
    }
    g.finish();
    // The 10⁶-point sweep (core + summary), on one thread and on the job's two threads.
    let mut g = c.benchmark_group("spatial_coupling_1e6");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1));
    let input = SpatialCouplingInput::try_from(req(&sweep(1_000_000, false))).expect("valid");
    for threads in [1usize, 2] {
        let budget = Budget::unlimited().with_threads(threads);
        g.bench_function(format!("sweep_core_summary_{threads}t"), |b| {
            b.iter(|| black_box(compute(&input, &budget).expect("computes")))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("spatial_coupling");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1));
    let budget = Budget::unlimited().with_threads(1);
    let one = req(
        &json!({"theta1_deg": [30], "outputs": {"contact": true, "relative_1": true, "relative_2": true}}),
    );
    g.bench_function("one_point_run", |b| {
        b.iter(|| black_box(run(one.clone(), &budget).expect("runs")))
    });
    g.finish();
}

criterion_group!(spatial_coupling_bench, benches);
criterion_main!(spatial_coupling_bench);
