//! Benchmarks of the vibration-absorber endpoint (spec §8): per number of modes n ∈ {3, 5, 10, 20,
//! 30} the cost of (1) model build + gains, (2) eig(A), (3) a 400-point FRF, (4) the exact time
//! response with 1e4 and 1e6 samples; the errors against a direct `expm(A_aug t_k) s(0)` at the
//! samples and against the 30-mode model; and the method knob (exact exosystem stepping vs ZOH
//! discretisation vs fixed-step RK4) on scenario S2.
//!
//! Run: `cargo bench --bench vibration_absorber -- --measurement-time 2 --warm-up-time 1`. The
//! tables for `benches/RESULTS.md` are printed before criterion runs.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

#[path = "support/mod.rs"]
mod support;

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use mechcalc::calc::vibration_absorber::compute::{
    augmented_system, ava_step, build_model, compute, excitation_hz, schur_response,
};
use mechcalc::calc::vibration_absorber::input::VibrationAbsorberInput;
use mechcalc::calc::vibration_absorber::model::Model;
use mechcalc::calc::vibration_absorber::response::{
    Stepper, eigen, frequency_response, step_metrics,
};
use mechcalc::calc::vibration_absorber::{VibrationAbsorberRequest, run};
use mechcalc::numerics::Budget;
use mechcalc::numerics::linalg::expm;
use nalgebra::{DMatrix, DVector};
use serde_json::{Value, json};
use support::time_for;

const NS: [u32; 5] = [3, 5, 10, 20, 30];

/// Scenario S2 of spec §8: k_a from the model's f₁, AVA at the tip tuned to the model's f₂, tip
/// force 1 N sin(2π f₂ t), ζ = 0.
fn s2(n: u32, outputs: &Value) -> Value {
    json!({
        "beam": {"n_modes": n},
        "absorber": {"passive_tuning_mode": 1},
        "control": {"mode": "active", "tuning_mode": 2},
        "excitation": {"type": "harmonic", "resonance_of_mode": 2},
        "outputs": outputs
    })
}

fn req(v: &Value) -> VibrationAbsorberRequest {
    serde_json::from_value(v.clone()).expect("valid request")
}

fn tip_series(v: &Value) -> Vec<f64> {
    let r = serde_json::to_value(run(req(v), &Budget::unlimited()).expect("runs")).expect("JSON");
    r["time_response"]["points"][0]["w_m"]
        .as_array()
        .expect("series")
        .iter()
        .filter_map(Value::as_f64)
        .collect()
}

/// `A_aug`, `s(0)` and the tip row of the S2 harmonic scenario.
fn augmented(m: &Model, f: f64) -> (DMatrix<f64>, DVector<f64>, DVector<f64>) {
    let (a, b) = (m.a_matrix(), m.b_vector());
    let n = a.nrows();
    let mut aug = DMatrix::zeros(n + 2, n + 2);
    aug.view_mut((0, 0), (n, n)).copy_from(&a);
    aug.view_mut((0, n), (n, 1)).copy_from(&b);
    aug[(n, n + 1)] = 2.0 * PI * f;
    aug[(n + 1, n)] = -2.0 * PI * f;
    let mut s0 = DVector::zeros(n + 2);
    s0[n + 1] = 1.0;
    let mut c = DVector::zeros(n + 2);
    c.rows_mut(0, n).copy_from(&m.row_deflection(1.0));
    (aug, s0, c)
}

fn model(n: u32) -> (Model, f64) {
    let input = VibrationAbsorberInput::try_from(req(&s2(n, &json!({})))).expect("valid");
    let (m, f, _) = build_model(&input);
    (m, f[1])
}

/// max |y_k − y_ref(t_k)| / max |y_ref| at 200 samples spread over the series (direct expm).
fn error_vs_direct(n: u32, w: &[f64], dt: f64) -> f64 {
    let (m, f2) = model(n);
    let (aug, s0, c) = augmented(&m, f2);
    let (mut worst, mut scale) = (0.0_f64, 0.0_f64);
    let stride = (w.len() / 200).max(1);
    for k in (0..w.len()).step_by(stride) {
        let y = c.dot(&(expm(&(&aug * (k as f64 * dt))).expect("finite") * &s0));
        worst = worst.max((w[k] - y).abs());
        scale = scale.max(y.abs());
    }
    worst / scale
}

fn print_cost_table() {
    println!("\n### Cost and error per number of modes (scenario S2, ζ = 0)\n");
    println!(
        "| n | N | build + gains [µs] | eig(A) [µs] | FRF 400 pts [ms] | time 1e4 samples [ms] (worst) | time 1e6 samples [ms] | stepping error vs direct expm | tip error vs n = 30 (2 s) | FRF error at 10 Hz vs n = 30 |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let budget = Budget::unlimited();
    let reference_2s = tip_series(&s2(
        30,
        &json!({"time_response": {"t_end_s": 2.0, "dt_s": 0.001, "return_series": true}}),
    ));
    let ref_scale = reference_2s.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let frf10 = |n: u32| {
        let v = s2(
            n,
            &json!({"frequency_response": {"f_min_hz": 10.0, "f_max_hz": 10.0, "n_points": 1}}),
        );
        let r = serde_json::to_value(run(req(&v), &budget).expect("runs")).expect("JSON");
        r["frequency_response"]["points"][0]["magnitude_m_per_n"][0]
            .as_f64()
            .expect("|H|")
    };
    let frf10_ref = frf10(30);
    for n in NS {
        let input = VibrationAbsorberInput::try_from(req(&s2(n, &json!({})))).expect("valid");
        let (t_build, _) = time_for(Duration::from_millis(300), 2000, || build_model(&input));
        let (m, _) = model(n);
        let a = m.a_matrix();
        let (t_eig, _) = time_for(Duration::from_millis(300), 2000, || eigen(&a).expect("eig"));
        let frf = req(&s2(
            n,
            &json!({"frequency_response": {"f_min_hz": 0.5, "f_max_hz": 100.0, "n_points": 400, "log": true}}),
        ));
        let (t_frf, _) = time_for(Duration::from_millis(500), 200, || {
            run(frf.clone(), &budget).expect("runs")
        });
        let t4 = req(&s2(
            n,
            &json!({"time_response": {"t_end_s": 10.0, "dt_s": 0.001}}),
        ));
        let (t_1e4, _) = time_for(Duration::from_millis(500), 200, || {
            run(t4.clone(), &budget).expect("runs")
        });
        let t6 = req(&s2(
            n,
            &json!({"time_response": {"t_end_s": 1000.0, "dt_s": 0.001}}),
        ));
        let (t_1e6, _) = support::time_runs(1, || run(t6.clone(), &budget).expect("runs"));
        let series = tip_series(&s2(
            n,
            &json!({"time_response": {"t_end_s": 10.0, "dt_s": 0.001, "return_series": true}}),
        ));
        let err_direct = error_vs_direct(n, &series, 0.001);
        let short = &series[..reference_2s.len()];
        let err_modes = short
            .iter()
            .zip(&reference_2s)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0_f64, f64::max)
            / ref_scale;
        let err_frf = (frf10(n) / frf10_ref - 1.0).abs();
        let mark = if n == 3 { " (default)" } else { "" };
        println!(
            "| {n}{mark} | {} | {:.1} | {:.1} | {:.2} | {:.2} ({:.2}) | {:.0} | {err_direct:.1e} | {:.2} % | {:.3} % |",
            2 * n + 3,
            t_build.median_us(),
            t_eig.median_us(),
            t_frf.median_ms(),
            t_1e4.median_ms(),
            t_1e4.worst_ms(),
            t_1e6.median_ms(),
            err_modes * 100.0,
            err_frf * 100.0
        );
    }
}

/// Fixed-step RK4 of the S2 state space, sampled every 1 ms over 10 s.
fn rk4_tip(m: &Model, f2: f64, h: f64) -> Vec<f64> {
    let (a, b) = (m.a_matrix(), m.b_vector());
    let c = m.row_deflection(1.0);
    let rhs = |t: f64, s: &DVector<f64>| &a * s + &b * (2.0 * PI * f2 * t).sin();
    let steps = (10.0 / h).round() as usize;
    let every = (0.001 / h).round().max(1.0) as usize;
    let mut s = DVector::zeros(a.nrows());
    let mut out = vec![0.0];
    for k in 0..steps {
        let t = k as f64 * h;
        let k1 = rhs(t, &s);
        let k2 = rhs(t + h / 2.0, &(&s + &k1 * (h / 2.0)));
        let k3 = rhs(t + h / 2.0, &(&s + &k2 * (h / 2.0)));
        let k4 = rhs(t + h, &(&s + &k3 * h));
        s += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        if (k + 1) % every == 0 {
            out.push(c.dot(&s));
        }
    }
    out
}

/// Exact ZOH discretisation (input held over each 1 ms step): O(h) for a sine input.
fn zoh_tip(m: &Model, f2: f64, h: f64) -> Vec<f64> {
    let (a, b) = (m.a_matrix(), m.b_vector());
    let n = a.nrows();
    let mut big = DMatrix::zeros(n + 1, n + 1);
    big.view_mut((0, 0), (n, n)).copy_from(&a);
    big.view_mut((0, n), (n, 1)).copy_from(&b);
    let e = expm(&(big * h)).expect("finite");
    let (phi, gamma) = (
        e.view((0, 0), (n, n)).into_owned(),
        e.view((0, n), (n, 1)).into_owned(),
    );
    let c = m.row_deflection(1.0);
    let steps = (10.0 / h).round() as usize;
    let every = (0.001 / h).round().max(1.0) as usize;
    let mut s = DVector::zeros(n);
    let mut out = vec![0.0];
    for k in 0..steps {
        let p = (2.0 * PI * f2 * k as f64 * h).sin();
        s = &phi * &s + &gamma * p;
        if (k + 1) % every == 0 {
            out.push(c.dot(&s));
        }
    }
    out
}

fn print_method_table() {
    println!(
        "\n### Method knob (scenario S2, n = 3, 10 s, output every 1 ms; error = max|y − y_ref| / max|y_ref|, y_ref = direct expm at every sample)\n"
    );
    println!("| method | median [ms] | worst [ms] | rel. error |");
    println!("|---|---|---|---|");
    let (m, f2) = model(3);
    let (aug, s0, c) = augmented(&m, f2);
    let reference: Vec<f64> = (0..=10_000)
        .map(|k| c.dot(&(expm(&(&aug * (k as f64 * 0.001))).expect("finite") * &s0)))
        .collect();
    let scale = reference.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let err = |y: &[f64]| {
        y.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0_f64, f64::max)
            / scale
    };
    let exact = req(&s2(
        3,
        &json!({"time_response": {"t_end_s": 10.0, "dt_s": 0.001, "return_series": true}}),
    ));
    let budget = Budget::unlimited();
    let (t, r) = time_for(Duration::from_millis(500), 100, || {
        run(exact.clone(), &budget).expect("runs")
    });
    let y = r.time_response.expect("time").points[0]
        .w_m
        .clone()
        .expect("series");
    println!(
        "| expm + exosystem, Φᵏ stepping (default) | {:.2} | {:.2} | {:.1e} |",
        t.median_ms(),
        t.worst_ms(),
        err(&y)
    );
    for h in [1e-3, 1e-4] {
        let (t, y) = time_for(Duration::from_millis(300), 20, || zoh_tip(&m, f2, h));
        println!(
            "| ZOH discretisation, h = {} ms | {:.2} | {:.2} | {:.1e} |",
            h * 1e3,
            t.median_ms(),
            t.worst_ms(),
            err(&y)
        );
    }
    for h in [1e-3, 5e-4, 1e-4, 1e-5] {
        let (t, y) = time_for(Duration::from_millis(300), 10, || rk4_tip(&m, f2, h));
        println!(
            "| fixed RK4, h = {} ms | {:.2} | {:.2} | {:.1e} |",
            h * 1e3,
            t.median_ms(),
            t.worst_ms(),
            err(&y)
        );
    }
    println!("\n### Output step h of the exact method (cost only; n = 3, 10 s)\n");
    println!("| h [ms] | samples | median [ms] | error vs direct expm |");
    println!("|---|---|---|---|");
    for h in [10e-3, 1e-3, 1e-4] {
        let v = s2(
            3,
            &json!({"time_response": {"t_end_s": 10.0, "dt_s": h, "return_series": true}}),
        );
        let r = req(&v);
        let (t, _) = time_for(Duration::from_millis(300), 50, || {
            run(r.clone(), &budget).expect("runs")
        });
        let w = tip_series(&v);
        println!(
            "| {} | {} | {:.2} | {:.1e} |",
            h * 1e3,
            w.len(),
            t.median_ms(),
            error_vs_direct(3, &w, h)
        );
    }
    println!();
}

/// Thirteen requests shaped like the `api/` examples (issue 27): the three examples and ten
/// variations over configuration, forcing, modes, position, gains and outputs.
fn api_cases() -> Vec<(&'static str, Value)> {
    let file = |s: &str| serde_json::from_str::<Value>(s).expect("example");
    let paper = file(include_str!("../api/vibration_absorber/paper_case.json"));
    let with = |base: &Value, patch: Value| {
        let mut v = base.clone();
        for (k, p) in patch.as_object().expect("object") {
            v[k] = p.clone();
        }
        v
    };
    let frf = |n: u32, pts: Value| json!({"f_min_hz": 0.5, "f_max_hz": 100.0, "n_points": n, "log": true, "points_m": pts});
    let time = |t: f64, dt: f64, pts: Value| json!({"t_end_s": t, "dt_s": dt, "points_m": pts});
    vec![
        ("paper_case", paper.clone()),
        (
            "frequency_sweep",
            file(include_str!(
                "../api/vibration_absorber/frequency_sweep.json"
            )),
        ),
        (
            "two_harmonics",
            file(include_str!("../api/vibration_absorber/two_harmonics.json")),
        ),
        (
            "paper_passive",
            with(
                &paper,
                json!({"control": {"mode": "passive"},
            "outputs": {"natural_frequencies": true, "eigenvalues": true, "frequency_response": frf(200, json!([1.0])), "time_response": time(10.0, 1e-3, json!([1.0]))}}),
            ),
        ),
        (
            "none_at_f1",
            json!({"control": {"mode": "none"}, "excitation": {"type": "harmonic", "resonance_of_mode": 1},
            "outputs": {"eigenvalues": true, "time_response": time(10.0, 1e-3, json!([1.0]))}}),
        ),
        (
            "active_t5",
            s2(
                3,
                &json!({"eigenvalues": true, "time_response": time(10.0, 1e-3, json!([1.0, 0.5]))}),
            ),
        ),
        (
            "shorted_frf",
            json!({"control": {"mode": "passive_shorted"}, "beam": {"modal_damping_ratio": 0.002},
            "outputs": {"eigenvalues": true, "frequency_response": frf(400, json!([1.0, 0.5]))}}),
        ),
        (
            "impulse_n5",
            json!({"beam": {"n_modes": 5, "modal_damping_ratio": 0.005}, "excitation": {"type": "impulse"},
            "outputs": {"time_response": time(2.0, 1e-4, json!([1.0]))}}),
        ),
        (
            "step_damped",
            json!({"beam": {"modal_damping_ratio": 0.01}, "excitation": {"type": "step"},
            "outputs": {"ava_step": true, "time_response": time(5.0, 1e-3, json!([1.0]))}}),
        ),
        (
            "ava_only",
            with(
                &paper,
                json!({"outputs": {"ava_step": true,
            "ava_frequency_response": {"f_min_hz": 1.0, "f_max_hz": 100.0, "n_points": 400, "log": true}}}),
            ),
        ),
        (
            "third_span_n4",
            json!({"beam": {"n_modes": 4, "modal_damping_ratio": 0.001}, "absorber": {"position_m": 0.3333},
            "control": {"mode": "active", "tuning_mode": 2}, "excitation": {"type": "harmonic", "resonance_of_mode": 2},
            "outputs": {"frequency_response": frf(300, json!([1.0])), "time_response": time(10.0, 1e-3, json!([1.0]))}}),
        ),
        (
            "explicit_gains",
            with(
                &paper,
                json!({"control": {"mode": "active", "kp_v_m": 500.0, "kd_v_s_m": -3.0},
            "outputs": {"ava_step": true, "eigenvalues": true, "time_response": time(3.0, 1e-3, json!([1.0]))}}),
            ),
        ),
        (
            "n10_frf_time",
            s2(
                10,
                &json!({"frequency_response": frf(400, json!([1.0])), "time_response": time(2.0, 1e-3, json!([1.0]))}),
            ),
        ),
    ]
}

/// The stages issue 27 changed, run by the previous dense implementations (kept in
/// `response`): eigenvalues by their own Schur iteration, each absorber step response on its own
/// (heap 4 × 4 matrices, an exponential per bisection step), a complex LU per frequency, the
/// time response stepped with the dense `Φ` in the original coordinates.
fn stages_before(input: &VibrationAbsorberInput, budget: &Budget) -> f64 {
    let (m, freqs, gains) = build_model(input);
    let (a, b) = (m.a_matrix(), m.b_vector());
    let o = &input.outputs;
    let mut acc = 0.0;
    let eig = (o.eigenvalues || o.frf.is_some()).then(|| eigen(&a).expect("eig"));
    if o.ava_step {
        let (fa, fb) = m.dev.fixed_base();
        let dc = (m.dev.ka > 0.0).then(|| m.dev.kc / (m.dev.ka * m.dev.r));
        let ec = step_metrics(&fa, &fb, &DVector::from_vec(vec![1.0, 0.0, 0.0]), dc, false);
        acc += ec.settling.unwrap_or(0.0);
        if let Some(g) = gains {
            let c = DVector::from_vec(vec![g.kp, g.kd, 0.0]);
            let err = step_metrics(&fa, &fb, &c, dc.map(|d| d * g.kp), false);
            acc += err.settling.unwrap_or(0.0);
        }
    }
    if let Some((grid, points)) = &o.frf {
        let w: Vec<f64> = grid.frequencies().iter().map(|f| 2.0 * PI * f).collect();
        let rows: Vec<DVector<f64>> = points.iter().map(|x| m.row_deflection(*x)).collect();
        let ev = eig
            .as_ref()
            .map(|e| e.values.as_slice())
            .unwrap_or_default();
        let h = frequency_response(&a, &b, &rows, &w, ev, budget).expect("FRF");
        acc += h.len() as f64;
    }
    if let Some(t) = &o.time {
        let fe = excitation_hz(input, &freqs);
        let sys = augmented_system(&m, (&a, &b), input, t, &fe);
        let st = Stepper {
            a: &sys.a,
            s0: &sys.s0,
            rows: &sys.rows,
            steps: t.steps,
            dt: t.dt,
            last_from: sys.last_from,
            decimate: t.series.then_some(t.decimate),
        };
        acc += st.run(budget).expect("time").max_abs[0];
    }
    acc
}

/// The same stages by the paths `compute` now calls (the time response keeps the dense stepping).
fn stages_after(input: &VibrationAbsorberInput, budget: &Budget) -> f64 {
    let (m, freqs, gains) = build_model(input);
    let (a, b) = (m.a_matrix(), m.b_vector());
    let o = &input.outputs;
    let mut acc = 0.0;
    let dec =
        (o.eigenvalues || o.frf.is_some()).then(|| schur_response::decompose(&a).expect("eig"));
    if o.ava_step {
        let (ec, err) = ava_step::step_pair(&m.dev, gains.as_ref(), false);
        acc += ec.settling.unwrap_or(0.0) + err.and_then(|e| e.settling).unwrap_or(0.0);
    }
    if let Some((grid, points)) = &o.frf {
        let w: Vec<f64> = grid.frequencies().iter().map(|f| 2.0 * PI * f).collect();
        let rows: Vec<DVector<f64>> = points.iter().map(|x| m.row_deflection(*x)).collect();
        let schur = dec.as_ref().and_then(|d| d.1.as_ref()).expect("Schur form");
        let h = schur_response::frequency_response(schur, &b, &rows, &w, budget).expect("FRF");
        acc += h.len() as f64;
    }
    if let Some(t) = &o.time {
        let fe = excitation_hz(input, &freqs);
        let sys = augmented_system(&m, (&a, &b), input, t, &fe);
        let st = Stepper {
            a: &sys.a,
            s0: &sys.s0,
            rows: &sys.rows,
            steps: t.steps,
            dt: t.dt,
            last_from: sys.last_from,
            decimate: t.series.then_some(t.decimate),
        };
        acc += st.run(budget).expect("time").max_abs[0];
    }
    acc
}

/// Median of `runs` interleaved timings of `f` and `g` [s].
fn interleaved<A, B>(
    runs: usize,
    mut f: impl FnMut() -> A,
    mut g: impl FnMut() -> B,
) -> (f64, f64) {
    let (mut tf, mut tg) = (Vec::with_capacity(runs), Vec::with_capacity(runs));
    black_box(f());
    black_box(g());
    for _ in 0..runs {
        let t = std::time::Instant::now();
        black_box(f());
        tf.push(t.elapsed().as_secs_f64());
        let t = std::time::Instant::now();
        black_box(g());
        tg.push(t.elapsed().as_secs_f64());
    }
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (med(&mut tf), med(&mut tg))
}

/// Issue 27: the changed stages before (dense reference paths) and after (fixed-size steps,
/// one Schur form), interleaved in one session on the 13 api-like cases, and the whole
/// `compute` after; "compute before" = compute after − stages after + stages before (the rest
/// of compute did not change).
fn print_issue27_table() {
    println!(
        "\n### Issue 27: compute on 13 api-like cases, changed stages before/after (interleaved medians)\n"
    );
    println!(
        "| case | stages before [ms] | stages after [ms] | ratio | compute after [ms] | compute before (derived) [ms] | ratio |"
    );
    println!("|---|---|---|---|---|---|---|");
    let budget = Budget::unlimited();
    let (mut sb, mut sa, mut ca, mut cb) = (0.0, 0.0, 0.0, 0.0);
    for (name, v) in api_cases() {
        let input = VibrationAbsorberInput::try_from(req(&v)).expect("valid");
        let (before, after) = interleaved(
            41,
            || stages_before(&input, &budget),
            || stages_after(&input, &budget),
        );
        let (full, _) = interleaved(41, || compute(&input, &budget).expect("computes"), || ());
        let derived = full - after + before;
        sb += before;
        sa += after;
        ca += full;
        cb += derived;
        println!(
            "| {name} | {:.3} | {:.3} | {:.1}× | {:.3} | {:.3} | {:.1}× |",
            before * 1e3,
            after * 1e3,
            before / after,
            full * 1e3,
            derived * 1e3,
            derived / full
        );
    }
    println!(
        "| **all 13** | {:.3} | {:.3} | {:.1}× | {:.3} | {:.3} | {:.1}× |",
        sb * 1e3,
        sa * 1e3,
        sb / sa,
        ca * 1e3,
        cb * 1e3,
        cb / ca
    );
    println!();
}

fn benches(c: &mut Criterion) {
    print_issue27_table();
    if std::env::var_os("VA_ISSUE27_ONLY").is_some() {
        return;
    }
    print_cost_table();
    print_method_table();
    let budget = Budget::unlimited();
    let mut g = c.benchmark_group("vibration_absorber");
    g.sample_size(10).measurement_time(Duration::from_secs(2));
    let paper: Value =
        serde_json::from_str(include_str!("../api/vibration_absorber/paper_case.json"))
            .expect("example");
    let paper = req(&paper);
    g.bench_function("paper_case_all_outputs", |b| {
        b.iter(|| run(black_box(paper.clone()), &budget))
    });
    g.finish();
}

criterion_group!(vibration_absorber_bench, benches);
criterion_main!(vibration_absorber_bench);
