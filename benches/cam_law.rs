//! Benchmarks of the cam-law evaluator (spec §3.2, §7.1): cost per sample of
//! `eval_quantity_into` on N = 300 (the fit's typical grid) and N = 200 000 (the evaluate
//! endpoint's maximum), per quantity, and the cost of building a law (the fit builds one per
//! candidate). The evaluator is closed form: it has no accuracy knob, so the only "knob" is N.
//!
//! Run: `cargo bench --bench cam_law`. Before criterion runs, a plain table (median and worst of
//! repeated timings, ns per sample) is printed for `benches/RESULTS.md`.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use mechcalc::calc::cam_law::catalogue::TABLE3;
use mechcalc::calc::cam_law::law::{Quantity, SevenSegmentLaw};
use mechcalc::calc::cam_law::run;
use mechcalc::calc::cam_law::wire::EvaluateRequest;
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "../tests/support/cam_table1.rs"]
mod cam_table1;
use cam_table1::{TABLE1_BC, TABLE1_C};

fn grid(n: usize) -> Vec<f64> {
    #[allow(clippy::cast_precision_loss)] // n ≤ 200 000
    let step = 1.0 / (n - 1) as f64;
    #[allow(clippy::cast_precision_loss)]
    (0..n).map(|k| k as f64 * step).collect()
}

/// Seeded random coefficient vectors (some zeros), as the fit's candidates look.
fn candidates(n: usize) -> Vec<[f64; 7]> {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    (0..n)
        .map(|_| {
            let mut c: [f64; 7] = std::array::from_fn(|_| {
                if rng.random_bool(0.2) {
                    0.0
                } else {
                    rng.random::<f64>()
                }
            });
            c[1] += 0.01;
            c[5] += 0.01;
            c
        })
        .collect()
}

/// Median and worst of `reps` timings of `f`, in ns, each divided by `per`.
fn time_ns(reps: usize, per: usize, mut f: impl FnMut()) -> (f64, f64) {
    f();
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let s = Instant::now();
            f();
            #[allow(clippy::cast_precision_loss)]
            let ns = s.elapsed().as_nanos() as f64 / per as f64;
            ns
        })
        .collect();
    t.sort_by(f64::total_cmp);
    (t[t.len() / 2], t[t.len() - 1])
}

fn print_table() {
    let law = SevenSegmentLaw::try_new(&TABLE1_C, &TABLE1_BC).expect("Table-1 law");
    println!("\n| case | N | median ns/sample | worst ns/sample |");
    println!("|---|---|---|---|");
    for n in [300usize, 200_000] {
        let xs = grid(n);
        let mut out = vec![0.0; n];
        let reps = if n == 300 { 20_000 } else { 200 };
        for q in Quantity::ALL {
            let (med, worst) = time_ns(reps, n, || {
                law.eval_quantity_into(black_box(&xs), q, black_box(&mut out))
            });
            println!("| eval_quantity_into {q:?}, sorted grid | {n} | {med:.2} | {worst:.2} |");
        }
        let (med, worst) = time_ns(reps, n, || {
            for (x, o) in xs.iter().zip(out.iter_mut()) {
                *o = black_box(&law).eval(*x).s;
            }
        });
        println!("| eval (all four, point by point) | {n} | {med:.2} | {worst:.2} |");
        let mut shuffled = xs.clone();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for i in (1..shuffled.len()).rev() {
            shuffled.swap(i, rng.random_range(0..=i));
        }
        let (med, worst) = time_ns(reps, n, || {
            law.eval_quantity_into(black_box(&shuffled), Quantity::A, black_box(&mut out))
        });
        println!("| eval_quantity_into A, unsorted | {n} | {med:.2} | {worst:.2} |");
    }
    println!("\n| construction | median ns/law | worst ns/law |");
    println!("|---|---|---|");
    let cs = candidates(1000);
    let bc = TABLE1_BC;
    let (med, worst) = time_ns(2000, cs.len(), || {
        for c in &cs {
            black_box(SevenSegmentLaw::try_new(black_box(c), &bc).ok());
        }
    });
    println!("| try_new (random candidates) | {med:.1} | {worst:.1} |");
    let (med, worst) = time_ns(2000, cs.len(), || {
        for c in &cs {
            black_box(
                SevenSegmentLaw::try_new(black_box(c), &bc)
                    .map(|l| l.peaks())
                    .ok(),
            );
        }
    });
    println!("| try_new + peaks | {med:.1} | {worst:.1} |");
    let xs = grid(300);
    let mut out = vec![0.0; 300];
    let (med, worst) = time_ns(200, cs.len(), || {
        for c in &cs {
            if let Ok(l) = SevenSegmentLaw::try_new(black_box(c), &bc) {
                l.eval_quantity_into(&xs, Quantity::A, &mut out);
            }
        }
    });
    println!("| fit candidate: try_new + A on N = 300 | {med:.1} | {worst:.1} |");
    let req = r#"{"coefficients": [0.0645, 0.129, 0.1935, 0.0968, 0.2581, 0.2258, 0.0323],
        "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0, "v_a": 0.2, "v_b": 0.5, "a_a": 1.4, "a_b": 1.2},
        "abscissa": {"grid": {"start": 0.0, "end": 1.0, "count": 200000}}}"#;
    let req: EvaluateRequest = serde_json::from_str(req).expect("request");
    let (med, worst) = time_ns(50, 1, || {
        black_box(run(req.clone(), &Budget::unlimited()).ok());
    });
    println!("| run(): evaluate, 200 000-point grid, s v a j (no JSON) | {med:.0} | {worst:.0} |");
    println!();
}

fn benches(c: &mut Criterion) {
    print_table();
    let law = SevenSegmentLaw::try_new(&TABLE1_C, &TABLE1_BC).expect("Table-1 law");
    for n in [300usize, 200_000] {
        let mut g = c.benchmark_group(format!("cam_law/eval_quantity_into/N={n}"));
        g.throughput(Throughput::Elements(n as u64));
        if n > 1000 {
            g.sample_size(20).measurement_time(Duration::from_secs(3));
        }
        let xs = grid(n);
        let mut out = vec![0.0; n];
        for q in Quantity::ALL {
            g.bench_with_input(
                BenchmarkId::from_parameter(format!("{q:?}")),
                &q,
                |b, &q| {
                    b.iter(|| law.eval_quantity_into(black_box(&xs), q, black_box(&mut out)));
                },
            );
        }
        g.finish();
    }
    let mut g = c.benchmark_group("cam_law/construct");
    let mt = TABLE3[4].coefficients;
    let bc = TABLE1_BC;
    g.bench_function("try_new", |b| {
        b.iter(|| SevenSegmentLaw::try_new(black_box(&TABLE1_C), black_box(&bc)))
    });
    g.bench_function("try_new+peaks", |b| {
        b.iter(|| SevenSegmentLaw::try_new(black_box(&mt), black_box(&bc)).map(|l| l.peaks()))
    });
    g.finish();
}

criterion_group!(cam_law, benches);
criterion_main!(cam_law);
