//! Benchmarks of `bus_fuel_economy` (spec §9): criterion timings of the main use cases, and the
//! accuracy-vs-cost table over the knobs `substeps` × `motor_eval` / `loss_map_grid`
//! (error of FE against the fine reference: direct evaluation, 16 substeps, clip mode, demo IPMSM,
//! 15 100 kg).
//!
//! Run: `cargo bench --bench bus_fuel_economy` (add `-- --quick` for shorter criterion runs).
//! The accuracy tables are printed as markdown before the criterion groups; with
//! `BFE_TABLES_ONLY=1` only the tables are produced.

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use mechcalc::calc::bus_fuel_economy::{
    BusFuelEconomyRequest, MotorMapRequest, run, run_motor_map,
};
use mechcalc::numerics::Budget;
use serde_json::{Value, json};

#[path = "../tests/support/bus_demo_motor.rs"]
mod bus_demo_motor;
use bus_demo_motor::{demo_efficiency_map, demo_ipmsm_json as demo};

const CYCLES: [&str; 3] = ["manhattan", "hwfet", "hdudds"];
/// Repetitions per accuracy-table cell (median and worst are reported).
const REPS: usize = 5;

fn request(v: Value) -> BusFuelEconomyRequest {
    serde_json::from_value(v).expect("bench request decodes")
}

fn fe(req: &BusFuelEconomyRequest) -> f64 {
    run(req.clone(), &Budget::unlimited())
        .expect("runs")
        .results[0]
        .fe_km_per_kwh
        .expect("positive energy")
}

/// (label, motor_eval, grid) of the table rows.
const EVALS: [(&str, &str, (f64, f64)); 5] = [
    ("direct", "direct", (250.0, 50.0)),
    ("loss map 500×100", "loss_map", (500.0, 100.0)),
    ("loss map 250×50", "loss_map", (250.0, 50.0)),
    ("loss map 100×20", "loss_map", (100.0, 20.0)),
    ("loss map 50×10", "loss_map", (50.0, 10.0)),
];

/// `REPS` timed runs of `req`: the sorted wall times (ms) and the fuel economy.
fn timed_fe(req: &BusFuelEconomyRequest) -> (Vec<f64>, f64) {
    let mut times = Vec::with_capacity(REPS);
    let mut value = 0.0;
    for _ in 0..REPS {
        let t0 = Instant::now();
        value = fe(black_box(req));
        times.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    (times, value)
}

fn knob_request(cycle: &str, eval: &str, grid: (f64, f64), k: u32) -> BusFuelEconomyRequest {
    request(json!({
        "cycles": [cycle], "motors": [demo("demo", 0.0035)],
        "options": {"mode": "clip", "substeps": k, "motor_eval": eval,
                    "loss_map_grid": {"speed_step_rpm": grid.0, "torque_step_nm": grid.1}}
    }))
}

/// Accuracy vs cost: one motor over one cycle, wall time = validation + map build + simulation.
fn accuracy_table() {
    println!(
        "\n### Accuracy vs cost (clip mode, demo IPMSM, 15 100 kg; reference: direct, k = 16)\n"
    );
    println!(
        "| cycle | evaluation | k | median ms | worst ms | FE km/kWh | rel. error vs reference |"
    );
    println!("|---|---|---|---|---|---|---|");
    for cycle in CYCLES {
        let reference = fe(&knob_request(cycle, "direct", (250.0, 50.0), 16));
        for (label, eval, grid) in EVALS {
            for k in [1u32, 2, 4, 8, 16] {
                let req = knob_request(cycle, eval, grid, k);
                let (times, value) = timed_fe(&req);
                let default = if eval == "loss_map" && grid == (250.0, 50.0) && k == 1 {
                    " **(default)**"
                } else {
                    ""
                };
                println!(
                    "| {cycle} | {label}{default} | {k} | {:.2} | {:.2} | {value:.6} | {:+.1e} |",
                    times[REPS / 2],
                    times[REPS - 1],
                    value / reference - 1.0
                );
            }
        }
        println!("| {cycle} | reference FE | 16 | | | {reference:.6} | |");
    }
    println!();
}

/// Efficiency-map conversion (spec §8 item 2): FE error of the converted map vs direct evaluation.
fn efficiency_map_table() {
    println!(
        "\n### Efficiency map → loss map conversion (backward, demo IPMSM; error vs direct)\n"
    );
    println!("| grid | cycle | median ms | FE km/kWh | rel. error vs direct |");
    println!("|---|---|---|---|---|");
    for grid in [(500.0, 100.0), (250.0, 50.0)] {
        let motor = demo_efficiency_map(grid.0, grid.1);
        for cycle in CYCLES {
            let req = request(json!({"cycles": [cycle], "motors": [motor.clone()]}));
            let direct = fe(&request(
                json!({"cycles": [cycle], "motors": [demo("d", 0.0035)], "options": {"motor_eval": "direct"}}),
            ));
            let (times, value) = timed_fe(&req);
            println!(
                "| {} × {} | {cycle} | {:.2} | {value:.6} | {:+.1e} |",
                grid.0,
                grid.1,
                times[REPS / 2],
                value / direct - 1.0
            );
        }
    }
    println!();
}

fn benches(c: &mut Criterion) {
    accuracy_table();
    efficiency_map_table();
    if std::env::var("BFE_TABLES_ONLY").is_ok_and(|v| v == "1") {
        return;
    }
    let mut g = c.benchmark_group("one_motor_one_cycle");
    for cycle in CYCLES {
        for (label, eval) in [("loss_map_250x50", "loss_map"), ("direct", "direct")] {
            let req = request(
                json!({"cycles": [cycle], "motors": [demo("demo", 0.0035)], "options": {"motor_eval": eval}}),
            );
            g.bench_function(format!("{cycle}/{label}"), |b| {
                b.iter(|| run(black_box(req.clone()), &Budget::unlimited()))
            });
        }
        let req = request(
            json!({"cycles": [cycle], "motors": [{"id": "c", "model": "constant", "efficiency": 0.93}]}),
        );
        g.bench_function(format!("{cycle}/constant"), |b| {
            b.iter(|| run(black_box(req.clone()), &Budget::unlimited()))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("comparison");
    g.sample_size(10);
    let motors: Vec<Value> = (0..8)
        .map(|i| demo(&format!("m{i}"), 0.0002f64.mul_add(f64::from(i), 0.0025)))
        .collect();
    for eval in ["loss_map", "direct"] {
        let req =
            request(json!({"cycles": CYCLES, "motors": motors, "options": {"motor_eval": eval}}));
        g.bench_function(format!("8_motors_x_3_cycles/{eval}"), |b| {
            b.iter(|| run(black_box(req.clone()), &Budget::unlimited()))
        });
    }
    let req = request(
        json!({"cycles": CYCLES, "motors": [demo("a", 0.0035), demo("b", 0.0032)],
                             "options": {"outputs": ["loss_breakdown", "op_histogram"]}}),
    );
    g.bench_function("paper_example_2_motors_x_3_cycles", |b| {
        b.iter(|| run(black_box(req.clone()), &Budget::unlimited()))
    });
    g.finish();

    let mut g = c.benchmark_group("motor_map");
    let req: MotorMapRequest =
        serde_json::from_value(json!({"motor": demo("demo", 0.0035)})).expect("decodes");
    g.bench_function("demo_250x50", |b| {
        b.iter(|| run_motor_map(black_box(req.clone()), &Budget::unlimited()))
    });
    g.finish();
}

criterion_group!(bus_fuel_economy, benches);
criterion_main!(bus_fuel_economy);
