//! Benchmarks of the continuum-workspace endpoint (spec 8): rod tip error and time against RK4
//! steps, FK error against RK4 steps with the warm-start time per solve, the Newton tolerance,
//! the stability segments M, the 31 x 31 and 61 x 61 sweeps with each stability mode, the sweep
//! knobs (sub-steps, predictor, threads) and the assembly-mode search grid.
//!
//! Run: `cargo bench --bench continuum_workspace [filter]`; a filter runs the tables whose name
//! contains it (`rod`, `fk`, `fk_cold`, `stability`, `modes`, `sweep`) and the criterion
//! benchmarks whose id matches (`fk_cold` runs the cold-start table and `fk_cold/*`). Plain tables (median and worst of repeated
//! timings, plus process CPU time for the sweeps) are printed first for `benches/RESULTS.md`, then
//! criterion times the hot paths.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]
// Benchmark arithmetic stays in textbook form.
#![allow(clippy::suboptimal_flops)]

#[path = "support/mod.rs"]
mod support;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use mechcalc::calc::continuum_workspace::closed_form::elastica;
use mechcalc::calc::continuum_workspace::model::{Model, Params};
use mechcalc::calc::continuum_workspace::newton::{
    self, Counter, NewtonOptions, Solution, Stepping,
};
use mechcalc::calc::continuum_workspace::presets::Preset;
use mechcalc::calc::continuum_workspace::sweep::{self, Limits, StabilityCheck, SweepSettings};
use mechcalc::calc::continuum_workspace::{
    ContinuumWorkspaceRequest, compute, fk, modes, rod, run,
};
use mechcalc::numerics::Budget;
use serde_json::{Value, json};
use support::{process_cpu_ms, time_us};

const EI: f64 = 2.638_937_829_015_426;
const LEN: f64 = 0.5;

struct RodCase {
    name: &'static str,
    theta1: f64,
    psi: f64,
    k: f64,
    q: u32,
}

const ROD_CASES: [RodCase; 2] = [
    RodCase {
        name: "k 0.9, psi 0.3, theta1 -60 deg, mode 1 (spec 8)",
        theta1: -1.047_197_551_196_597_6,
        psi: 0.3,
        k: 0.9,
        q: 1,
    },
    RodCase {
        name: "k -0.7, psi 1.0, theta1 -60 deg, mode 2",
        theta1: -1.047_197_551_196_597_6,
        psi: 1.0,
        k: -0.7,
        q: 2,
    },
];

fn rod_table() {
    println!(
        "\n### Rod: tip error vs RK4 steps against the closed form (spec 4.4), time per integration\n"
    );
    println!(
        "| case | steps | tip error [m] | m(L) [N m] | plain µs (median / worst) | with sensitivities µs (median / worst) |"
    );
    println!("|---|---|---|---|---|---|");
    for c in &ROD_CASES {
        let e = elastica(EI, LEN, c.theta1, c.psi, c.k, c.q).expect("admissible");
        let q = [
            e.base_moment * LEN / EI,
            e.force[0] * LEN * LEN / EI,
            e.force[1] * LEN * LEN / EI,
        ];
        let ode = rod::RodOde {
            theta_c: c.theta1,
            ca: 0.0,
        };
        for steps in [4usize, 8, 16, 32, 64, 128, 256, 512] {
            let z = rod::shoot_plain(&ode, &q, steps);
            let err = (z[0] * LEN - e.tip[0]).hypot(z[1] * LEN - e.tip[1]);
            let reps = (200_000 / steps).clamp(200, 20_000);
            let (pm, pw) = time_us(reps, || {
                black_box(rod::shoot_plain(black_box(&ode), black_box(&q), steps));
            });
            let (sm, sw) = time_us(reps, || {
                black_box(rod::shoot(black_box(&ode), black_box(&q), steps));
            });
            let mark = if steps == 32 { " (default)" } else { "" };
            println!(
                "| {} | {steps}{mark} | {err:.2e} | {:.1e} | {pm:.2} / {pw:.1} | {sm:.2} / {sw:.1} |",
                c.name,
                z[3] * EI / LEN
            );
        }
    }
}

fn d1(steps: usize) -> Model {
    Model::new(Preset::KeopsD1.design(), steps, false)
}

fn solve_home(model: &Model, lambda: [f64; 2], tol: f64) -> Solution {
    let home = compute::resolve_home(model).expect("home");
    let p = Params {
        lambda: lambda.to_vec(),
        force: [0.0, 0.0],
        moment: 0.0,
    };
    let k = fk::continuation_steps(model, &home.lambda, &p.lambda);
    fk::from_home(
        model,
        &home,
        &p,
        k,
        Stepping::Fixed,
        NewtonOptions::new(tol, 50),
        &Budget::unlimited(),
        &mut Counter::default(),
    )
    .expect("converges")
    .solution
}

/// A warm Newton solve of `p` from `from` with `opts`, and its median and worst time over 2000
/// repetitions [µs].
fn timed_warm_solve(
    model: &Model,
    p: &Params,
    from: &[f64],
    opts: NewtonOptions,
) -> (Solution, f64, f64) {
    let solve = || {
        newton::solve(
            model,
            p,
            black_box(from),
            opts,
            &Budget::unlimited(),
            &mut Counter::default(),
        )
    };
    let sol = solve().expect("a warm start converges");
    let (tm, tw) = time_us(2000, || {
        black_box(solve().ok());
    });
    (sol, tm, tw)
}

#[expect(
    clippy::too_many_lines,
    reason = "prints the three FK tables of benches/RESULTS.md (error vs RK4 steps, Newton tolerance, end-to-end requests) from one set of reference solutions"
)]
fn fk_table() {
    let target = [-0.05, 0.1725];
    let neighbour = [-0.06, 0.1725];
    let refm = d1(4096);
    let reference = solve_home(&refm, target, 1e-13);
    let rp = refm.position(&reference.v);
    let rt = refm.angle(&reference.v);
    println!(
        "\n### FK: error vs RK4 steps (d1 at (-0.05, 0.1725), F = 0; reference 4096 steps, tol 1e-13), warm start from a 10 mm neighbour\n"
    );
    println!(
        "Reference: p = ({:.10}, {:.10}) m, theta = {:.8} deg (spec 6.2: (0.0569633347, -0.4839533093), -0.9044944).\n",
        rp[0],
        rp[1],
        rt.to_degrees()
    );
    println!(
        "| rk4_steps | position error [m] | angle error [deg] | force error [N] | Newton iterations | warm solve µs (median / worst) |"
    );
    println!("|---|---|---|---|---|---|");
    for steps in [8usize, 16, 32, 64, 128] {
        let model = d1(steps);
        let from = solve_home(&model, neighbour, 1e-10);
        let p = Params {
            lambda: target.to_vec(),
            force: [0.0, 0.0],
            moment: 0.0,
        };
        let (sol, tm, tw) = timed_warm_solve(&model, &p, &from.v, NewtonOptions::new(1e-10, 50));
        let pos = model.position(&sol.v);
        let perr = (pos[0] - rp[0]).hypot(pos[1] - rp[1]);
        let terr = (model.angle(&sol.v) - rt).to_degrees().abs();
        let ferr = sol
            .eval
            .forces
            .iter()
            .zip(&reference.eval.forces)
            .fold(0.0f64, |m, (a, b)| {
                m.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs())
            });
        let mark = if steps == 32 { " (default)" } else { "" };
        println!(
            "| {steps}{mark} | {perr:.2e} | {terr:.2e} | {ferr:.2e} | {} | {tm:.1} / {tw:.0} |",
            sol.iterations
        );
    }

    println!(
        "\n### FK: Newton tolerance (32 steps, same warm start; error vs the 32-step solution at tol 1e-14)\n"
    );
    println!("| tol | position change [m] | iterations | warm solve µs (median / worst) |");
    println!("|---|---|---|---|");
    let model = d1(32);
    let from = solve_home(&model, neighbour, 1e-10);
    let p = Params {
        lambda: target.to_vec(),
        force: [0.0, 0.0],
        moment: 0.0,
    };
    let tight = newton::solve(
        &model,
        &p,
        &from.v,
        NewtonOptions::new(1e-14, 50),
        &Budget::unlimited(),
        &mut Counter::default(),
    )
    .expect("tight");
    let tp = model.position(&tight.v);
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14] {
        let (sol, tm, tw) = timed_warm_solve(&model, &p, &from.v, NewtonOptions::new(tol, 50));
        let pos = model.position(&sol.v);
        let mark = if (tol - 1e-10).abs() < 1e-20 {
            " (default)"
        } else {
            ""
        };
        println!(
            "| {tol:e}{mark} | {:.1e} | {} | {tm:.1} / {tw:.0} |",
            (pos[0] - tp[0]).hypot(pos[1] - tp[1]),
            sol.iterations
        );
    }

    println!(
        "\n### FK requests end to end (`run()`, JSON-free; d1 at (-0.15, 0.2225), F = (0, -50) N)\n"
    );
    println!("| request | median µs | worst µs |");
    println!("|---|---|---|");
    let req = |extra: Value| -> ContinuumWorkspaceRequest {
        let mut v = json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.15, 0.2225], "load": {"force_n": [0, -50]}});
        if let (Some(o), Some(e)) = (v.as_object_mut(), extra.as_object()) {
            for (k, x) in e {
                o.insert(k.clone(), x.clone());
            }
        }
        serde_json::from_value(v).expect("valid")
    };
    let budget = Budget::unlimited();
    for (name, extra) in [
        (
            "home start (adaptive continuation, default), no stability",
            json!({"outputs": {"stability": false}}),
        ),
        (
            "home start (fixed: 20 equal continuation steps), no stability",
            json!({"outputs": {"stability": false}, "start": {"kind": "home", "continuation": "fixed"}}),
        ),
        (
            "home start, stability M = 20",
            json!({"outputs": {"stability_segments": 20}}),
        ),
        ("home start, stability M = 40 (default)", json!({})),
        (
            "warm start (guess = the solution), no stability",
            json!({"outputs": {"stability": false}, "start": {"kind": "guess", "state": {"v": [-0.567_191, 0.279_439, -2.367_666, -0.51573, -0.261_704, -0.775_534, 0.541_469, -0.017_735, -1.593_555, 0.049_818, -0.934_123, 0.002_546]}}}),
        ),
        (
            "warm start, stability M = 40",
            json!({"start": {"kind": "guess", "state": {"v": [-0.567_191, 0.279_439, -2.367_666, -0.51573, -0.261_704, -0.775_534, 0.541_469, -0.017_735, -1.593_555, 0.049_818, -0.934_123, 0.002_546]}}}),
        ),
    ] {
        let r = req(extra);
        let (m, w) = time_us(300, || {
            black_box(run(r.clone(), &budget).ok());
        });
        println!("| {name} | {m:.0} | {w:.0} |");
    }
}

/// Spec 9 FK request (d1 at (-0.15, 0.2225), F = (0, -50) N) with `extra` merged at the top
/// level and into `start`.
fn spec_fk_request(start: Value, solver: Value) -> ContinuumWorkspaceRequest {
    serde_json::from_value(json!({"mode": "fk", "design": {"preset": "keops_d1"},
        "inputs_m": [-0.15, 0.2225], "load": {"force_n": [0, -50]}, "solver": solver,
        "start": start, "outputs": {"stability": false}}))
    .expect("valid")
}

/// Deterministic uniform numbers in [0, 1) (splitmix64).
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// Issue 17: cold FK from home, adaptive against the spec's fixed-step continuation.
#[expect(
    clippy::too_many_lines,
    reason = "prints the two cold-FK tables of benches/RESULTS.md (spec 9 request, random targets) from one reference model, accumulating the per-path statistics"
)]
fn fk_cold_table() {
    let model = d1(32);
    let refm = d1(4096);
    let home = compute::resolve_home(&model).expect("home");
    let p = Params {
        lambda: vec![-0.15, 0.2225],
        force: [0.0, -50.0],
        moment: 0.0,
    };
    let rhome = compute::resolve_home(&refm).expect("home");
    let reference = fk::from_home(
        &refm,
        &rhome,
        &p,
        30,
        Stepping::Fixed,
        NewtonOptions::new(1e-13, 50),
        &Budget::unlimited(),
        &mut Counter::default(),
    )
    .expect("reference")
    .solution;
    let (rp, rt) = (refm.position(&reference.v), refm.angle(&reference.v));
    println!(
        "\n### Cold FK from home: adaptive vs fixed-step continuation (spec 9 request: d1 at (-0.15, 0.2225), F = (0, -50) N, 32 RK4 steps, no stability; reference 4096 steps, tol 1e-13)\n"
    );
    println!(
        "| continuation | continuation_steps | tol | steps taken | Newton iterations | evaluations | `run()` wall µs (median / worst) | `run()` CPU µs (mean) | position error [m] | angle error [deg] | Δp vs fixed, same k and tol [m] |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (k, tol) in [
        (20u32, 1e-10f64),
        (10, 1e-10),
        (30, 1e-10),
        (20, 1e-8),
        (20, 1e-12),
    ] {
        let mut fixed_pos = [f64::NAN; 2];
        for kind in ["fixed", "adaptive"] {
            let r = spec_fk_request(
                json!({"kind": "home", "continuation_steps": k, "continuation": kind}),
                json!({"rk4_steps": 32, "tol": tol}),
            );
            let (t, out) = support::time_for(Duration::from_millis(400), 2000, || {
                run(r.clone(), &Budget::unlimited()).expect("fk")
            });
            let v = serde_json::to_value(&out).expect("json");
            let pos = [
                v["platform"]["position_m"][0].as_f64().unwrap_or(f64::NAN),
                v["platform"]["position_m"][1].as_f64().unwrap_or(f64::NAN),
            ];
            let th = v["platform"]["parasitic_angle_deg"]
                .as_f64()
                .unwrap_or(f64::NAN);
            if kind == "fixed" {
                fixed_pos = pos;
            }
            let default = k == 20 && (tol - 1e-10).abs() < 1e-20 && kind == "adaptive";
            let mark = if default { " (default)" } else { "" };
            println!(
                "| {kind}{mark} | {k} | {tol:e} | {} | {} | {} | {:.0} / {:.0} | {:.0} | {:.2e} | {:.2e} | {:.1e} |",
                v["diagnostics"]["continuation_steps"],
                v["report"]["iterations"],
                v["report"]["evaluations"],
                t.median_us(),
                t.worst_us(),
                t.cpu_s.map_or(f64::NAN, |c| c * 1e6),
                (pos[0] - rp[0]).hypot(pos[1] - rp[1]),
                (th - rt.to_degrees()).abs(),
                (pos[0] - fixed_pos[0]).hypot(pos[1] - fixed_pos[1]),
            );
        }
    }

    // The warm solve of the same request: start from the solution of a 10 mm neighbour.
    let neighbour = run(
        serde_json::from_value(json!({"mode": "fk", "design": {"preset": "keops_d1"},
            "inputs_m": [-0.14, 0.2225], "load": {"force_n": [0, -50]},
            "solver": {"rk4_steps": 32, "tol": 1e-10}, "outputs": {"stability": false}}))
        .expect("valid"),
        &Budget::unlimited(),
    )
    .expect("fk");
    let state = serde_json::to_value(&neighbour).expect("json")["solver_state"].clone();
    let cold = spec_fk_request(
        json!({"kind": "home"}),
        json!({"rk4_steps": 32, "tol": 1e-10}),
    );
    let warm = spec_fk_request(
        json!({"kind": "guess", "state": state}),
        json!({"rk4_steps": 32, "tol": 1e-10}),
    );
    // Interleaved, so that both see the same load.
    let (mut tc, mut tw) = (Vec::new(), Vec::new());
    for _ in 0..5 {
        for (r, v) in [(&cold, &mut tc), (&warm, &mut tw)] {
            let (t, _) = support::time_for(Duration::from_millis(200), 2000, || {
                run(r.clone(), &Budget::unlimited()).expect("fk")
            });
            v.push((t.median_us(), t.cpu_s.map_or(f64::NAN, |c| c * 1e6)));
        }
    }
    let med = |v: &mut Vec<(f64, f64)>, i: usize| {
        let mut x: Vec<f64> = v.iter().map(|p| if i == 0 { p.0 } else { p.1 }).collect();
        x.sort_by(f64::total_cmp);
        x[x.len() / 2]
    };
    let (cw, cc, ww, wc) = (
        med(&mut tc, 0),
        med(&mut tc, 1),
        med(&mut tw, 0),
        med(&mut tw, 1),
    );
    println!(
        "\nCold (home, default adaptive) vs warm (guess = solution at a 10 mm neighbour, (-0.14, 0.2225) m) `run()` of the spec 9 request, interleaved, medians of 5 rounds: cold {cw:.0} µs wall / {cc:.0} µs CPU, warm {ww:.0} µs wall / {wc:.0} µs CPU: cold = {:.2}x warm (wall), {:.2}x (CPU)",
        cw / ww,
        cc / wc
    );

    let n: usize = std::env::var("CW_BENCH_TARGETS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    println!(
        "\n### Cold FK over {n} random targets (d1, inputs in [-0.35, -0.12] x [0.17, 0.37] m, F in [-20, 20]^2 N, 32 RK4 steps, tol 1e-10, default k; targets whose fixed-path solution is stable at M = 20)\n"
    );
    let opts = NewtonOptions::new(1e-10, 50);
    let mut rng = Uniform(20_261_121);
    let mut stats = [ColdStats::default(), ColdStats::default()];
    let (mut stable, mut adaptive_failed, mut agree) = (0usize, 0usize, 0usize);
    let (mut worst_dp, mut worst_dt, mut worst_dv, mut worst_df) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let tol_l = 1e-9 * model.l_ref;
    for _ in 0..n {
        let p = Params {
            lambda: vec![rng.range(-0.35, -0.12), rng.range(0.17, 0.37)],
            force: [rng.range(-20.0, 20.0), rng.range(-20.0, 20.0)],
            moment: 0.0,
        };
        let k = fk::continuation_steps(&model, &home.lambda, &p.lambda);
        let solve = |s: Stepping| {
            let mut c = Counter::default();
            let r = fk::from_home(&model, &home, &p, k, s, opts, &Budget::unlimited(), &mut c);
            (r, c.evaluations)
        };
        let (Ok(fixed), fe) = solve(Stepping::Fixed) else {
            continue;
        };
        if !fk::margin_of(&model, &fixed.solution, 20).is_some_and(|g| g > fk::STABLE_MARGIN) {
            continue;
        }
        stable += 1;
        let (adaptive, ae) = solve(Stepping::Adaptive);
        let Ok(adaptive) = adaptive else {
            adaptive_failed += 1;
            continue;
        };
        let (a, f) = (&adaptive.solution.v, &fixed.solution.v);
        let (pa, pf) = (model.position(a), model.position(f));
        let dp = (pa[0] - pf[0]).hypot(pa[1] - pf[1]);
        let dt = (model.angle(a) - model.angle(f)).abs() * model.l_ref;
        let dv = a
            .iter()
            .zip(f)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        let df = adaptive
            .solution
            .eval
            .forces
            .iter()
            .zip(&fixed.solution.eval.forces)
            .fold(0.0f64, |m, (x, y)| {
                m.max((x[0] - y[0]).abs()).max((x[1] - y[1]).abs())
            });
        if dp <= tol_l && dt <= tol_l {
            agree += 1;
        }
        worst_dp = worst_dp.max(dp);
        worst_dt = worst_dt.max(dt);
        worst_dv = worst_dv.max(dv);
        worst_df = worst_df.max(df);
        let [sf, sa] = &mut stats;
        for (st, s, r, e) in [
            (sf, Stepping::Fixed, &fixed, fe),
            (sa, Stepping::Adaptive, &adaptive, ae),
        ] {
            let (t, _) = support::time_runs(3, || solve(s));
            st.add(r.steps, r.newton_iterations, e, t.median_us());
        }
    }
    println!(
        "Stable targets: {stable}; adaptive failed where fixed converged: {adaptive_failed}; same solution (|Δp| and L_ref |Δθ| <= 1e-9 L_ref = {tol_l:.1e} m): {agree} of {}. Worst |Δp| {worst_dp:.2e} m, worst L_ref |Δθ| {worst_dt:.2e} m, worst scaled unknown {worst_dv:.2e}, worst rod force {worst_df:.2e} N.\n",
        stable - adaptive_failed
    );
    println!(
        "| continuation | steps (mean / max) | Newton iterations (mean / max) | evaluations (mean) | solve wall µs (median / worst over targets of each target's median of 3 runs) |"
    );
    println!("|---|---|---|---|---|");
    for (name, st) in [("fixed", &stats[0]), ("adaptive (default)", &stats[1])] {
        println!("| {name} | {} |", st.row());
    }
}

/// Per-path totals of the random-target table.
#[derive(Default)]
struct ColdStats {
    steps: Vec<usize>,
    iters: Vec<usize>,
    evals: Vec<u64>,
    us: Vec<f64>,
}

impl ColdStats {
    fn add(&mut self, steps: usize, iters: usize, evals: u64, us: f64) {
        self.steps.push(steps);
        self.iters.push(iters);
        self.evals.push(evals);
        self.us.push(us);
    }
    fn row(&self) -> String {
        let n = self.steps.len().max(1) as f64;
        let mean = |v: &[usize]| v.iter().sum::<usize>() as f64 / n;
        let max = |v: &[usize]| v.iter().copied().max().unwrap_or(0);
        let mut us = self.us.clone();
        us.sort_by(f64::total_cmp);
        let med = us.get(us.len() / 2).copied().unwrap_or(f64::NAN);
        let worst = us.last().copied().unwrap_or(f64::NAN);
        format!(
            "{:.1} / {} | {:.1} / {} | {:.0} | {med:.0} / {worst:.0}",
            mean(&self.steps),
            max(&self.steps),
            mean(&self.iters),
            max(&self.iters),
            self.evals.iter().sum::<u64>() as f64 / n,
        )
    }
}

fn stability_table() {
    let model = d1(32);
    let sol = solve_home(&model, [-0.05, 0.1725], 1e-12);
    let reference = fk::margin_of(&model, &sol, 640).expect("margin");
    println!(
        "\n### Stability margin vs segments M (d1 at (-0.05, 0.1725); reference M = 640: {reference:.4}; spec: true 7.765)\n"
    );
    println!("| M | margin | error vs M = 640 | µs (median / worst) |");
    println!("|---|---|---|---|");
    for m in [10usize, 20, 40, 80, 160] {
        let g = fk::margin_of(&model, &sol, m).expect("margin");
        let reps = if m >= 160 { 20 } else { 200 };
        let (tm, tw) = time_us(reps, || {
            black_box(fk::margin_of(&model, black_box(&sol), m));
        });
        let mark = match m {
            20 => " (sweep default)",
            40 => " (FK default)",
            _ => "",
        };
        println!(
            "| {m}{mark} | {g:.4} | {:.1e} | {tm:.0} / {tw:.0} |",
            (g - reference).abs() / reference
        );
    }
}

fn sweep_request(n: u32, stability: &str, extra: Value) -> ContinuumWorkspaceRequest {
    let mut w = json!({"grid": [n, n], "stability_check": stability, "limits": {"min_actuator_gap_m": 0.05}});
    if let (Some(o), Some(e)) = (w.as_object_mut(), extra.as_object()) {
        for (k, x) in e {
            o.insert(k.clone(), x.clone());
        }
    }
    serde_json::from_value(
        json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "workspace": w}),
    )
    .expect("valid")
}

fn run_sweep(req: &ContinuumWorkspaceRequest) -> (Value, f64, f64) {
    let c0 = process_cpu_ms();
    let t0 = Instant::now();
    let r = run(req.clone(), &Budget::unlimited()).expect("sweep");
    let wall = t0.elapsed().as_secs_f64() * 1e3;
    let cpu = process_cpu_ms() - c0;
    (serde_json::to_value(r).expect("json"), wall, cpu)
}

fn sweep_tables() {
    println!(
        "\n### Sweeps: design 1, ranges home +/- 0.45 m, gap limit 0.05 m, F = 0, 8 sub-steps, M = 20 (spec 6.2 reference: ~705 nodes, union 0.2333 m^2, 35 folded, 3.18 deg, QT 0.1252 m^2)\n"
    );
    println!(
        "| grid | stability | wall ms (median / worst of reps) | CPU ms (both threads) | µs CPU per attempted node | accepted | union m^2 | sum m^2 | folded | max angle deg | QT m^2 |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (n, reps) in [(31u32, 3usize), (61, 1)] {
        for st in ["full", "det_sign", "none"] {
            let req = sweep_request(n, st, json!({}));
            let mut walls = Vec::new();
            let mut cpus = Vec::new();
            let mut last = Value::Null;
            for _ in 0..reps {
                let (v, w, c) = run_sweep(&req);
                walls.push(w);
                cpus.push(c);
                last = v;
            }
            walls.sort_by(f64::total_cmp);
            cpus.sort_by(f64::total_cmp);
            let m = &last["metrics"];
            let attempts = last["report"]["iterations"].as_f64().unwrap_or(f64::NAN);
            println!(
                "| {n} x {n} | {st} | {:.0} / {:.0} | {:.0} | {:.0} | {} | {:.4} | {:.4} | {} | {:.2} | {:.4} |",
                walls[walls.len() / 2],
                walls[walls.len() - 1],
                cpus[cpus.len() / 2],
                cpus[cpus.len() / 2] * 1e3 / attempts,
                m["n_accepted"],
                m["area_union_m2"].as_f64().unwrap_or(f64::NAN),
                m["area_sum_m2"].as_f64().unwrap_or(f64::NAN),
                m["folded_cells"],
                m["max_abs_parasitic_deg"].as_f64().unwrap_or(f64::NAN),
                m["quasi_translational_area_m2"]
                    .as_f64()
                    .unwrap_or(f64::NAN),
            );
        }
    }

    println!("\n### Sweep knobs (31 x 31, det_sign unless stated; one run each)\n");
    println!("| knob | wall ms | CPU ms | accepted | union m^2 | max angle deg | failures |");
    println!("|---|---|---|---|---|---|---|");
    let knobs: [(&str, &str, Value); 10] = [
        ("max_substeps 1", "det_sign", json!({"max_substeps": 1})),
        ("max_substeps 2", "det_sign", json!({"max_substeps": 2})),
        ("max_substeps 4", "det_sign", json!({"max_substeps": 4})),
        (
            "max_substeps 8 (default)",
            "det_sign",
            json!({"max_substeps": 8}),
        ),
        ("max_substeps 16", "det_sign", json!({"max_substeps": 16})),
        ("predictor off", "det_sign", json!({"predictor": false})),
        (
            "substep_max_iter 50 (no sweep cap)",
            "det_sign",
            json!({"substep_max_iter": 50}),
        ),
        (
            "full stability, M = 40",
            "full",
            json!({"stability_segments": 40}),
        ),
        ("8 neighbours", "det_sign", json!({"neighbours": 8})),
        ("area_method sum", "det_sign", json!({"area_method": "sum"})),
    ];
    for (name, stability, overrides) in knobs {
        let req = sweep_request(31, stability, overrides);
        let (v, w, c) = run_sweep(&req);
        let m = &v["metrics"];
        println!(
            "| {name} | {w:.0} | {c:.0} | {} | {} | {:.2} | {} |",
            m["n_accepted"],
            m["area_union_m2"]
                .as_f64()
                .map_or("-".to_string(), |a| format!("{a:.4}")),
            m["max_abs_parasitic_deg"].as_f64().unwrap_or(f64::NAN),
            v["failures"]
        );
    }

    println!("\n### Threads (31 x 31, det_sign, wave only; results are identical)\n");
    println!("| threads | wall ms | CPU ms |");
    println!("|---|---|---|");
    let model = d1(32);
    let base = Params {
        lambda: vec![-0.25, 0.2725],
        force: [0.0, 0.0],
        moment: 0.0,
    };
    for threads in [1usize, 2] {
        let s = SweepSettings {
            stability: StabilityCheck::DetSign,
            limits: Limits {
                min_gap: Some(0.05),
                sigma_allow: None,
                rod_crossing: false,
            },
            threads,
            ..SweepSettings::with_defaults([31, 31], [[-0.7, 0.2], [-0.1775, 0.7225]])
        };
        let seed_sol = solve_home(&model, [-0.25, 0.2725], 1e-10);
        let seed = sweep::accept(&model, &s, &[-0.25, 0.2725], &seed_sol, None).expect("seed");
        let c0 = process_cpu_ms();
        let t0 = Instant::now();
        let w = sweep::wave(
            &model,
            &base,
            &s,
            (15, 15),
            seed,
            NewtonOptions::new(1e-10, 50),
            &Budget::unlimited(),
        );
        let wall = t0.elapsed().as_secs_f64() * 1e3;
        black_box(w);
        println!("| {threads} | {wall:.0} | {:.0} |", process_cpu_ms() - c0);
    }
}

fn modes_table() {
    println!(
        "\n### Assembly-mode search (d1 at (-0.22, 0.2425), F = 0; spec 6.2 (cell 2): N_grid 6 / Tol 0.45 -> 4 solutions, 2 stable; N_grid 9 / Tol 0.5 -> 10, 5 stable)\n"
    );
    println!(
        "Missed = modes of the N_grid 9 / Tol 0.5 / max_refine 20 000 search (the reference set) not found.\n"
    );
    println!(
        "| N_grid | Tol | cell | max_refine | combinations examined | candidates | refined | solutions | stable | missed | ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let model = d1(32);
    let p = Params {
        lambda: vec![-0.22, 0.2425],
        force: [0.0, 0.0],
        moment: 0.0,
    };
    let search = |n_grid: usize, tol: f64, cell: usize, max_refine: usize| {
        let t0 = Instant::now();
        let r = modes::search(
            &model,
            &p,
            modes::ModeSearch {
                n_grid,
                tol,
                cell,
                max_refine,
            },
            NewtonOptions::new(1e-10, 50),
            40,
            &Budget::unlimited(),
            &mut Counter::default(),
        );
        (r, t0.elapsed().as_secs_f64() * 1e3)
    };
    let (reference, _) = search(9, 0.5, 2, 20_000);
    let nr = model.n_rods();
    let pose = |s: &modes::ModeSolution| {
        [
            s.solution.v[3 * nr],
            s.solution.v[3 * nr + 1],
            s.solution.v[3 * nr + 2],
        ]
    };
    for (ng, tol, cell, max_refine) in [
        (3usize, 0.45, 2usize, 4000usize),
        (4, 0.45, 2, 4000),
        (5, 0.3, 2, 4000),
        (5, 0.45, 2, 4000),
        (6, 0.45, 1, 4000),
        (6, 0.45, 2, 4000),
        (6, 0.45, 3, 4000),
        (7, 0.45, 2, 4000),
        (7, 0.5, 2, 4000),
        (8, 0.5, 2, 4000),
        (9, 0.5, 2, 1000),
        (9, 0.5, 1, 4000),
        (9, 0.5, 2, 4000),
        (9, 0.5, 3, 4000),
        (9, 0.5, 2, 20_000),
    ] {
        let (r, ms) = search(ng, tol, cell, max_refine);
        let missed = reference
            .solutions
            .iter()
            .filter(|want| {
                let w = pose(want);
                !r.solutions.iter().any(|got| {
                    let g = pose(got);
                    (g[0] - w[0]).abs() < 1e-6
                        && (g[1] - w[1]).abs() < 1e-6
                        && mechcalc::numerics::angles::wrap_pi(g[2] - w[2]).abs() < 1e-6
                })
            })
            .count();
        let mark = match (ng, cell, max_refine) {
            (9, 2, 4000) => " (default, 3 rods)",
            (6, 2, 4000) if tol < 0.46 => " (default of the no-home start)",
            _ => "",
        };
        println!(
            "| {ng}{mark} | {tol} | {cell} | {max_refine} | {} | {} | {} | {} | {} | {missed} | {ms:.0} |",
            r.combinations,
            r.candidates,
            r.refined,
            r.solutions.len(),
            r.solutions.iter().filter(|s| s.stable).count()
        );
    }
}

fn criterion_benches(c: &mut Criterion) {
    let e = elastica(EI, LEN, ROD_CASES[0].theta1, 0.3, 0.9, 1).expect("admissible");
    let q = [
        e.base_moment * LEN / EI,
        e.force[0] * LEN * LEN / EI,
        e.force[1] * LEN * LEN / EI,
    ];
    let ode = rod::RodOde {
        theta_c: ROD_CASES[0].theta1,
        ca: 0.0,
    };
    let mut g = c.benchmark_group("rod_32_steps");
    g.bench_function("plain", |b| {
        b.iter(|| rod::shoot_plain(black_box(&ode), black_box(&q), 32))
    });
    g.bench_function("with_sensitivities", |b| {
        b.iter(|| rod::shoot(black_box(&ode), black_box(&q), 32))
    });
    g.finish();

    let model = d1(32);
    let from = solve_home(&model, [-0.06, 0.1725], 1e-10);
    let p = Params {
        lambda: vec![-0.05, 0.1725],
        force: [0.0, 0.0],
        moment: 0.0,
    };
    let sol = solve_home(&model, [-0.05, 0.1725], 1e-10);
    let mut g = c.benchmark_group("fk_d1");
    g.bench_function("warm_solve_10mm", |b| {
        b.iter(|| {
            newton::solve(
                &model,
                &p,
                black_box(&from.v),
                NewtonOptions::new(1e-10, 50),
                &Budget::unlimited(),
                &mut Counter::default(),
            )
            .ok()
        })
    });
    g.bench_function("stability_m20", |b| {
        b.iter(|| fk::margin_of(&model, black_box(&sol), 20))
    });
    g.bench_function("stability_m40", |b| {
        b.iter(|| fk::margin_of(&model, black_box(&sol), 40))
    });
    g.finish();

    // Issue 17: the cold FK request of spec 9 (no stability), `run()` end to end.
    let mut g = c.benchmark_group("fk_cold");
    for kind in ["adaptive", "fixed"] {
        let r = spec_fk_request(
            json!({"kind": "home", "continuation": kind}),
            json!({"rk4_steps": 32, "tol": 1e-10}),
        );
        g.bench_function(kind, |b| {
            b.iter(|| run(black_box(r.clone()), &Budget::unlimited()).ok())
        });
    }
    g.finish();
}

fn tables(_: &mut Criterion) {
    println!(
        "\n## continuum_workspace tables (load average at start: {})",
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim()
    );
    // A positional argument (criterion's filter; option values are numbers) selects the tables whose name contains it.
    let filters: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-') && a.parse::<f64>().is_err())
        .collect();
    let wanted =
        |name: &str| filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()));
    let all: [(&str, fn()); 6] = [
        ("rod", rod_table),
        ("fk", fk_table),
        ("fk_cold", fk_cold_table),
        ("stability", stability_table),
        ("modes", modes_table),
        ("sweep", sweep_tables),
    ];
    for (name, table) in all {
        if wanted(name) {
            table();
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30);
    targets = tables, criterion_benches
}
criterion_main!(benches);
