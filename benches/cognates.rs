//! Benchmarks of the cognates endpoint (spec §8): the O(1) part (construction, classification,
//! ranges, pose map), the cost of curves and verification as N grows, and the accuracy knob N:
//! chord error against the closed-form truth (16 sub-samples per chord in the natural parameter),
//! `sync` and `implicit` residuals.
//!
//! Run: `cargo bench --bench cognates` (`-- encode` for one group). Before criterion runs (when no
//! filter or a filter containing `tables` is given), plain tables (median and worst of
//! repeated timings) are printed for `benches/RESULTS.md`, and the accuracy sweep is written as
//! JSON to `target/cognates_accuracy.json`.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

#[path = "support/mod.rs"]
mod support;

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use mechcalc::calc::cognates::geometry::{FourBar, cognates};
use mechcalc::calc::cognates::input::CognatesInput;
use mechcalc::calc::cognates::sampling::{Spacing, chord_error};
use mechcalc::calc::cognates::{CognatesRequest, compute, run};
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};
use support::time_us;

const NS: [usize; 10] = [32, 64, 128, 256, 360, 512, 1024, 2048, 4096, 8192];
const DEFAULT_N: usize = 360;

fn table1(options: Value) -> Value {
    json!({
        "ground": {"A": [0, 0], "B": [3.10, 0]},
        "crank": 1.13, "coupler": 1.23, "rocker": 1.04,
        "coupler_point": {"d": 0.92, "e": 1.56, "side": 1},
        "input_angle_deg": 30.0, "branch": 1, "options": options
    })
}

fn crank_rocker(options: Value) -> Value {
    json!({
        "ground": {"A": [0, 0], "B": [4.0, 0]}, "crank": 1.0, "coupler": 3.5, "rocker": 3.0,
        "coupler_point": {"d": 2.0, "e": 2.5, "side": 1}, "input_angle_deg": 60.0, "options": options
    })
}

fn req(v: &Value) -> CognatesRequest {
    serde_json::from_value(v.clone()).expect("valid request")
}

/// 20 seeded random linkages (assemblable, P away from the joints), as request JSON.
fn random_linkages() -> Vec<Value> {
    let mut rng = ChaCha8Rng::seed_from_u64(2024);
    let mut out = Vec::new();
    while out.len() < 20 {
        let (l, a, b, c): (f64, f64, f64, f64) = (
            rng.random_range(0.3..2.0),
            rng.random_range(0.2..2.0),
            rng.random_range(0.2..2.0),
            rng.random_range(0.2..2.0_f64),
        );
        let longest = l.max(a).max(b).max(c);
        if longest > 0.95 * (l + a + b + c - longest) {
            continue;
        }
        let (u, v): (f64, f64) = (rng.random_range(-1.0..2.0), rng.random_range(-1.0..1.0));
        if u.hypot(v) < 0.1 || (1.0 - u).hypot(v) < 0.1 || v.abs() < 0.05 {
            continue;
        }
        out.push(json!({
            "ground": {"A": [0, 0], "B": [l, 0]}, "crank": a, "coupler": b, "rocker": c,
            "coupler_point": {"u": u * b, "v": v * b}
        }));
    }
    out
}

/// The original mechanism (normalised frame) and the frame scale.
fn mech(v: &Value) -> (FourBar, f64) {
    let input = CognatesInput::try_from(req(v)).expect("valid");
    (input.mech, input.scale)
}

fn reps_for(n: usize) -> usize {
    (200_000 / n).clamp(10, 400)
}

#[expect(
    clippy::too_many_lines,
    reason = "prints the three tables of benches/RESULTS.md (O(1) part, time vs N, accuracy vs N) in the order they appear there"
)]
fn print_tables() {
    let budget = Budget::unlimited();
    println!("\n### O(1) part (no curves, no verification)\n");
    println!("| case | median µs | worst µs |");
    println!("|---|---|---|");
    let t1 = req(&table1(json!({})));
    let (m, w) = time_us(20_000, || {
        black_box(run(black_box(t1.clone()), &budget).ok());
    });
    println!("| run(): Table 1 + snapshot (validate, compute, wire) | {m:.2} | {w:.1} |");
    let input = CognatesInput::try_from(t1.clone()).expect("valid");
    let (m, w) = time_us(20_000, || {
        black_box(compute(black_box(&input), &budget).ok());
    });
    println!("| compute(): Table 1 + snapshot | {m:.2} | {w:.1} |");
    let (m, w) = time_us(20_000, || {
        let f = cognates(black_box(&input.mech));
        for mm in &f.mechs {
            black_box((mm.grashof(1e-9), mm.input_range()));
        }
    });
    println!("| geometry only: construction + 3× Grashof + 3× range | {m:.3} | {w:.1} |");
    let t1_json = serde_json::to_string(&table1(json!({}))).expect("json");
    let (m, w) = time_us(20_000, || {
        let r: CognatesRequest = serde_json::from_str(black_box(&t1_json)).expect("decodes");
        let resp = run(r, &budget).expect("runs");
        black_box(serde_json::to_vec(&resp).ok());
    });
    println!("| JSON in → run() → JSON out: Table 1 + snapshot | {m:.2} | {w:.1} |");
    let randoms: Vec<CognatesRequest> = random_linkages()
        .iter()
        .map(|v| {
            let mut v = v.clone();
            v["input_angle_deg"] = json!(45.0);
            req(&v)
        })
        .collect();
    let (m, w) = time_us(2_000, || {
        for r in &randoms {
            black_box(run(r.clone(), &budget).ok());
        }
    });
    println!(
        "| run(): 20 random linkages, per linkage | {:.2} | {:.1} |",
        m / 20.0,
        w / 20.0
    );

    println!("\n### Time per request vs N (Table 1, one circuit per mechanism: 3·N points)\n");
    println!(
        "| N | curves µs (median / worst) | curves + sync µs | curves + sync + implicit µs | + JSON out µs |"
    );
    println!("|---|---|---|---|---|");
    for n in NS {
        let reps = reps_for(n);
        let c = req(&table1(json!({"curves": true, "points_per_circuit": n})));
        let cs = req(&table1(
            json!({"curves": true, "points_per_circuit": n, "verify": ["sync"]}),
        ));
        let csi = req(&table1(
            json!({"curves": true, "points_per_circuit": n, "verify": ["sync", "implicit"]}),
        ));
        let (a, aw) = time_us(reps, || {
            black_box(run(c.clone(), &budget).ok());
        });
        let (b, bw) = time_us(reps, || {
            black_box(run(cs.clone(), &budget).ok());
        });
        let (d, dw) = time_us(reps, || {
            black_box(run(csi.clone(), &budget).ok());
        });
        let (e, ew) = time_us(reps, || {
            let r = run(c.clone(), &budget).expect("runs");
            black_box(serde_json::to_vec(&r).ok());
        });
        let mark = if n == DEFAULT_N { " (default)" } else { "" };
        println!(
            "| {n}{mark} | {a:.1} / {aw:.1} | {b:.1} / {bw:.1} | {d:.1} / {dw:.1} | {e:.1} / {ew:.1} |"
        );
    }
    let cr = req(&crank_rocker(
        json!({"curves": true, "points_per_circuit": 1024, "verify": ["sync"]}),
    ));
    let (m, w) = time_us(100, || {
        black_box(run(cr.clone(), &budget).ok());
    });
    println!(
        "\nCrank-rocker (two circuits per mechanism, 6·N points), N = 1024, curves + sync: {m:.1} µs median, {w:.1} µs worst."
    );
    let h = req(&table1(
        json!({"curves": true, "points_per_circuit": 1024, "verify": ["hausdorff"]}),
    ));
    let (m, w) = time_us(50, || {
        black_box(run(h.clone(), &budget).ok());
    });
    println!(
        "Table 1, N = 1024, curves + hausdorff (grid index): {m:.1} µs median, {w:.1} µs worst."
    );

    println!(
        "\n### Accuracy vs N (chord error, length unit of the input; slope = log2 e(N/2)/e(N), doublings only)\n"
    );
    println!(
        "| N | paper, cosine (auto) | slope | paper, uniform | slope | crank-rocker, auto | slope | 20 random, auto: max e·N²/L | sync max_dev_regular / L (paper; random max) | implicit max_dist / L (paper; random max) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let (paper, sp) = mech(&table1(json!({})));
    let (crm, sc) = mech(&crank_rocker(json!({})));
    let randoms: Vec<(FourBar, f64)> = random_linkages().iter().map(mech).collect();
    let mut seen: Vec<(usize, (f64, f64, f64))> = Vec::new();
    let mut report = Vec::new();
    for n in NS {
        let e_cos = chord_error(&paper, n, Spacing::Auto, 16) * sp;
        let e_uni = chord_error(&paper, n, Spacing::Uniform, 16) * sp;
        let e_cr = chord_error(&crm, n, Spacing::Auto, 16) * sc;
        #[allow(clippy::cast_precision_loss, reason = "n ≤ 8192")]
        let nf = n as f64;
        let rand_norm = randoms
            .iter()
            .map(|(m, _)| chord_error(m, n, Spacing::Auto, 16) * nf * nf / m.scale())
            .fold(0.0, f64::max);
        let slope = |p: f64, c: f64| (p / c).log2();
        // Slope against N/2 (only for doublings).
        let (s1, s2, s3) = seen
            .iter()
            .find(|(m, _)| 2 * m == n)
            .map_or((f64::NAN, f64::NAN, f64::NAN), |(_, (a, b, c))| {
                (slope(*a, e_cos), slope(*b, e_uni), slope(*c, e_cr))
            });
        let verify = json!({"points_per_circuit": n, "verify": ["sync", "implicit"]});
        let rv = run(req(&table1(verify.clone())), &budget).expect("runs");
        let v = rv.verification.expect("verification");
        let (sync_p, imp_p) = (
            v.sync.expect("sync").max_dev_regular / 3.1,
            v.implicit.expect("implicit").max_dist / 3.1,
        );
        let (mut sync_r, mut imp_r) = (0.0_f64, 0.0_f64);
        for lk in random_linkages() {
            let mut lk = lk;
            lk["options"] = verify.clone();
            let (m, s) = mech(&lk);
            let l = m.scale() * s;
            let r = run(req(&lk), &budget).expect("runs");
            let v = r.verification.expect("verification");
            sync_r = sync_r.max(v.sync.expect("sync").max_dev_regular / l);
            imp_r = imp_r.max(v.implicit.expect("implicit").max_dist / l);
        }
        let mark = if n == DEFAULT_N { " (default)" } else { "" };
        let fmt_slope = |s: f64| {
            if s.is_nan() {
                "—".to_string()
            } else {
                format!("{s:.2}")
            }
        };
        println!(
            "| {n}{mark} | {e_cos:.3e} | {} | {e_uni:.3e} | {} | {e_cr:.3e} | {} | {rand_norm:.3} | {sync_p:.1e}; {sync_r:.1e} | {imp_p:.1e}; {imp_r:.1e} |",
            fmt_slope(s1),
            fmt_slope(s2),
            fmt_slope(s3)
        );
        report.push(json!({
            "n": n, "paper_cosine": e_cos, "paper_uniform": e_uni, "crank_rocker_auto": e_cr,
            "random_max_e_n2_over_l": rand_norm, "sync_paper_rel": sync_p, "sync_random_rel": sync_r,
            "implicit_paper_rel": imp_p, "implicit_random_rel": imp_r
        }));
        seen.push((n, (e_cos, e_uni, e_cr)));
    }
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/cognates_accuracy.json");
    if let Ok(s) = serde_json::to_string_pretty(&report) {
        let _ = std::fs::write(&path, s);
    }
    println!();
}

fn benches(c: &mut Criterion) {
    if support::sweep_filters("tables").is_some() {
        print_tables();
    }
    let budget = Budget::unlimited();
    let mut g = c.benchmark_group("cognates/request");
    g.sample_size(50).measurement_time(Duration::from_secs(3));
    let t1 = req(&table1(json!({})));
    g.bench_function("table1_no_curves", |b| {
        b.iter(|| run(black_box(t1.clone()), &budget))
    });
    let fb = req(&table1(json!({"geared_fivebars": true})));
    g.bench_function("table1_fivebars", |b| {
        b.iter(|| run(black_box(fb.clone()), &budget))
    });
    g.finish();
    let mut g = c.benchmark_group("cognates/curves");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    for (name, opts) in [
        ("N=360", json!({"curves": true, "points_per_circuit": 360})),
        (
            "N=1024+sync",
            json!({"curves": true, "points_per_circuit": 1024, "verify": ["sync"]}),
        ),
        (
            "N=1024+sync+implicit",
            json!({"curves": true, "points_per_circuit": 1024, "verify": ["sync", "implicit"]}),
        ),
        (
            "N=1024+metrics",
            json!({"points_per_circuit": 1024, "metrics": true}),
        ),
    ] {
        let r = req(&table1(opts));
        g.bench_function(name, |b| b.iter(|| run(black_box(r.clone()), &budget)));
    }
    g.finish();
    // The answer of the `api/` example (71 KB of JSON, 3375 numbers): the encoding the service
    // runs on the compute pool (finite-number guard + JSON), and its two parts.
    let ex: Value = serde_json::from_str(
        &std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cognates/table1.json"),
        )
        .expect("api example"),
    )
    .expect("json");
    let out = run(req(&ex), &budget).expect("answer");
    let mut g = c.benchmark_group("cognates/encode");
    g.sample_size(50).measurement_time(Duration::from_secs(3));
    g.bench_function("api_table1_encode", |b| {
        b.iter(|| mechcalc::http::encode(black_box(&out)))
    });
    g.bench_function("api_table1_finite_guard", |b| {
        b.iter(|| mechcalc::http::finite::all_finite(black_box(&out)))
    });
    g.bench_function("api_table1_serde_json", |b| {
        b.iter(|| serde_json::to_vec(black_box(&out)))
    });
    g.finish();
}

criterion_group!(cognates_bench, benches);
criterion_main!(cognates_bench);
