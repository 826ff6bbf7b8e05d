//! Validation cases of the vibration-absorber spec (`shared/specs/vibration_absorber.md` §6: V1–V12
//! and the time scenarios T1–T7), driven through the public entry point `run`, plus the
//! independent check of the exact time response against a fine fixed-step RK4 of the same state
//! space.
//!
//! Tolerances: the spec's column where it gives one; otherwise half a unit of the last printed
//! digit of the reference value. The paper's own numbers are checked at the bands spec §4 states
//! (they are not all reproducible; the reasons are next to each case).

use mechcalc::calc::vibration_absorber::beam::{ModeShape, beta_l};
use mechcalc::calc::vibration_absorber::compute::build_model;
use mechcalc::calc::vibration_absorber::input::VibrationAbsorberInput;
use mechcalc::calc::vibration_absorber::{VibrationAbsorberRequest, run};
use mechcalc::numerics::Budget;
use mechcalc::numerics::linalg::eigenvalues;
use nalgebra::{Complex, DMatrix, DVector};
use serde_json::{Value, json};

fn request(v: Value) -> VibrationAbsorberRequest {
    serde_json::from_value(v).expect("valid request JSON")
}

fn answer(v: Value) -> Value {
    let r = run(request(v), &Budget::unlimited()).expect("the request succeeds");
    serde_json::to_value(r).expect("serialisable")
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(num).collect()
}

fn close(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got:.10e}, want {want:.10e} ± {tol:e} (diff {:.3e})",
        (got - want).abs()
    );
}

fn close_rel(what: &str, got: f64, want: f64, rel: f64) {
    close(what, got, want, rel * want.abs());
}

/// The paper case of spec §3.E (explicit 4.14 Hz passive tuning, 26.26 Hz target).
fn paper_case() -> Value {
    json!({
        "beam": {"length_m": 1.0, "youngs_modulus_pa": 2.1e11, "density_kg_m3": 7850,
                 "section": {"width_m": 0.05, "thickness_m": 0.005}, "n_modes": 3, "modal_damping_ratio": 0.0},
        "absorber": {"mass_kg": 0.05, "passive_tuning_hz": 4.14, "damping_n_s_m": 0.01, "position_m": 1.0},
        "actuator": {"resistance_ohm": 1.6, "inductance_h": 0.00075, "force_constant_n_a": 3.5, "back_emf_v_s_m": 3.5},
        "control": {"mode": "active", "tuning_hz": 26.26}
    })
}

#[test]
fn v1_frequency_equation_roots() {
    let want = [
        1.875_104_069,
        4.694_091_133,
        7.854_757_438,
        10.995_540_73,
        14.137_168_39,
    ];
    for (k, w) in want.iter().enumerate() {
        close(&format!("β_{}L", k + 1), beta_l(k + 1), *w, 1e-8);
    }
    // The spec's §3.A 12-digit values, at 1e-9 (V1 tolerance).
    let exact = [
        1.875_104_068_712,
        4.694_091_132_974,
        7.854_757_438_238,
        10.995_540_734_875,
        14.137_168_391_046,
    ];
    for (k, w) in exact.iter().enumerate() {
        close(
            &format!("β_{}L (12 digits)", k + 1),
            beta_l(k + 1),
            *w,
            1e-9,
        );
    }
}

#[test]
fn v2_bare_beam_frequencies() {
    for (rho, want) in [
        (7850.0, [4.177_583, 26.180_466, 73.306_062]),
        (7800.0, [4.190_951, 26.264_243, 73.540_642]),
    ] {
        let mut req = paper_case();
        req["beam"]["density_kg_m3"] = json!(rho);
        let a = answer(req);
        let f = nums(&a["beam"]["natural_frequencies_hz"]);
        for k in 0..3 {
            close_rel(&format!("f{} at ρ={rho}", k + 1), f[k], want[k], 1e-6);
        }
    }
    // Paper Table 2 (4.14, 26.26, 73.53): spec V2 says f2, f3 "within 0.3 %", but its own
    // reference values are 0.3029 % (26.1805 vs 26.26) and 0.3046 % (73.3061 vs 73.53) off at
    // ρ = 7850, so the band is 0.31 %; f1 is 0.908 % off and not reproducible by any consistent
    // reading (spec §4 item 4), checked at 1 %.
    let f = nums(&answer(paper_case())["beam"]["natural_frequencies_hz"]);
    close_rel("paper f1", f[0], 4.14, 0.01);
    close_rel("paper f2", f[1], 26.26, 0.0031);
    close_rel("paper f3", f[2], 73.53, 0.0031);
}

#[test]
fn v3_nodes_of_modes_2_and_3() {
    let n2 = ModeShape::new(2).nodes();
    assert_eq!(n2.len(), 1);
    close("node of mode 2", n2[0], 0.783_445, 1e-5);
    let n3 = ModeShape::new(3).nodes();
    assert_eq!(n3.len(), 2);
    close("node 1 of mode 3", n3[0], 0.503_548, 1e-5);
    close("node 2 of mode 3", n3[1], 0.867_678, 1e-5);
    // The response names the nodes of the tuned mode (26.26 Hz → mode 2).
    let nodes = nums(&answer(paper_case())["beam"]["tuned_mode_nodes_m"]);
    close("tuned-mode node [m]", nodes[0], 0.783_445, 1e-5);
}

#[test]
fn v4_v5_v8_v12_gains_mass_ratio_third_pole() {
    let a = answer(paper_case());
    close(
        "mass ratio",
        num(&a["absorber"]["mass_ratio"]),
        0.025_48,
        5e-6,
    );
    close(
        "k_a",
        num(&a["absorber"]["stiffness_n_m"]),
        33.832_214,
        5e-7,
    );
    let g = &a["gains"];
    // V5: reference 606.851 / −3.22010; paper 606.87 / −3.22 (both at the spec's 0.05 / 5e-4).
    close("K_p vs reference", num(&g["kp_v_m"]), 606.851, 5e-4);
    close("K_p vs paper", num(&g["kp_v_m"]), 606.87, 0.05);
    // Eq. (8) gives −3.220137 exactly (−(0.016 − 0.995519 + 12.25)/3.5); the spec's −3.22010 is
    // off in its 5th decimal, so the spec's V5 tolerance 5e-4 is the one that decides.
    close("K_d vs reference", num(&g["kd_v_s_m"]), -3.220_10, 5e-4);
    close("K_d by Eq. (8)", num(&g["kd_v_s_m"]), -3.220_137, 5e-7);
    close("K_d vs paper", num(&g["kd_v_s_m"]), -3.22, 5e-4);
    close_rel(
        "third pole (V8)",
        num(&g["third_pole_1_s"]),
        -2133.533,
        1e-6,
    );
    close_rel(
        "k_art (V12)",
        num(&g["artificial_stiffness_n_m"]),
        1327.359,
        1e-6,
    );
}

#[test]
fn v6_gains_tuned_to_the_passive_frequency() {
    let mut req = paper_case();
    req["control"]["tuning_hz"] = json!(4.14);
    let g = &answer(req)["gains"];
    close("K_p at 4.14 Hz", num(&g["kp_v_m"]), 1.450e-3, 1e-6);
    close("K_d at 4.14 Hz", num(&g["kd_v_s_m"]), -3.504_57, 5e-6);
}

#[test]
fn v7_absorber_step_settling_times() {
    let mut req = paper_case();
    req["outputs"] = json!({"ava_step": true});
    let a = answer(req);
    let ec = &a["ava_step"]["xa_over_ec"];
    let err = &a["ava_step"]["xa_over_err"];
    close("T_s of G_ec", num(&ec["settling_time_s"]), 0.868_88, 1e-4);
    close("T_s of G_err", num(&err["settling_time_s"]), 0.874_13, 1e-4);
    close("overshoot G_ec", num(&ec["overshoot_pct"]), 0.0, 0.0);
    close("overshoot G_err", num(&err["overshoot_pct"]), 0.0, 0.0);
    close_rel("DC of G_ec", num(&ec["dc_gain"]), 0.064_657_3, 1e-6);
    close_rel("DC of G_err", num(&err["dc_gain"]), 39.2374, 2e-6);
    // Paper: 0.87 s and 0.875 s (printed to 2–3 digits).
    close("paper T_s G_ec", num(&ec["settling_time_s"]), 0.87, 0.005);
    // 0.875 is 0.874126 rounded at the 3rd decimal: within 1e-3.
    close(
        "paper T_s G_err",
        num(&err["settling_time_s"]),
        0.875,
        0.001,
    );
}

#[test]
fn v9_fixed_base_closed_loop_poles_sit_on_the_axis_at_fc() {
    for fc in [4.14, 26.26] {
        let mut req = paper_case();
        req["control"]["tuning_hz"] = json!(fc);
        let input = VibrationAbsorberInput::try_from(request(req)).expect("valid");
        let (model, _, gains) = build_model(&input);
        let g = gains.expect("active gains");
        let (mut a, _) = model.dev.fixed_base();
        // Closed loop: e_c = −(K_p x + K_d ẋ) enters the coil row.
        a[(2, 0)] -= g.kp / model.dev.lc;
        a[(2, 1)] -= g.kd / model.dev.lc;
        let ev = eigenvalues(&a).expect("converges");
        let wc = 2.0 * std::f64::consts::PI * fc;
        let osc = ev.iter().find(|z| z.im > 0.0).expect("an oscillatory pair");
        close_rel("Im λ = ω_c", osc.im, wc, 1e-12);
        assert!(osc.re.abs() < 1e-9 * osc.norm(), "Re λ = {:e}", osc.re);
        let real = ev.iter().find(|z| z.im == 0.0).expect("a real pole");
        close_rel("third pole", real.re, -2133.533, 1e-6);
    }
}

#[test]
fn v10_with_absorber_natural_frequencies() {
    let mut req = paper_case();
    req["outputs"] = json!({"natural_frequencies": true});
    let a = answer(req);
    let f = nums(&a["natural_frequencies"]["with_passive_absorber_hz"]);
    assert_eq!(f.len(), 4);
    // Reference printed to 4–5 significant digits: half a unit of the last digit.
    for (k, (got, want)) in f.iter().zip([3.548, 4.868, 26.215, 73.318]).enumerate() {
        close(&format!("with-absorber f{}", k + 1), *got, want, 5e-4);
    }
    // Paper 3.50 / 4.93 / 26.26 within 2 % (not reproduced exactly, spec §4 item 8).
    for (got, paper) in f.iter().zip([3.50, 4.93, 26.26]) {
        close_rel("paper Table 2 with absorber", *got, paper, 0.02);
    }
    // The quoted "15 % and 19 %" split become 14.3 % and 17.6 %.
    let f1 = num(&a["natural_frequencies"]["without_absorber_hz"][0]);
    close("lower split", (1.0 - f[0] / f1) * 100.0, 15.1, 0.1);
}

#[test]
fn v11_coupled_closed_loop_poles() {
    let mut req = paper_case();
    req["outputs"] = json!({"eigenvalues": true});
    let a = answer(req);
    let cl = &a["closed_loop"];
    let ev = cl["eigenvalues"].as_array().expect("eigenvalues");
    let osc: Vec<f64> = ev
        .iter()
        .map(|e| num(&e["im_hz"]))
        .filter(|f| *f > 0.0)
        .collect();
    for (got, want) in osc.iter().zip([3.974_88, 22.910_52, 31.297_01, 73.870_08]) {
        close_rel("closed-loop frequency", *got, want, 1e-5);
    }
    let real: Vec<f64> = ev
        .iter()
        .filter(|e| num(&e["im_hz"]) == 0.0)
        .map(|e| num(&e["re_1_s"]))
        .collect();
    assert_eq!(real.len(), 1);
    close("real pole", real[0], -2133.6, 0.05);
    close("max Re λ", num(&cl["max_real_part_1_s"]), 3.75e-5, 0.05e-5);
    assert_eq!(cl["stability"], "unstable");
    assert_eq!(cl["state_size"], 9);
    assert!(
        a["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .any(|w| w["code"] == "MARGINAL_STABILITY"),
        "ζ = 0 with active control warns (spec §7 item 1)"
    );
}

#[test]
fn v12_steady_state_actuator_force_is_minus_k_art_times_stroke() {
    // Damped beam so the steady state is reached; at f_c the ratio u/r = −(k_art − j b_a ω_c)
    // whatever the beam: the least-squares slope of u on r over the last period is −k_art.
    let mut req = paper_case();
    req["beam"]["modal_damping_ratio"] = json!(0.02);
    req["excitation"] = json!({"type": "harmonic", "frequency_hz": 26.26});
    req["outputs"] =
        json!({"time_response": {"t_end_s": 12.0, "dt_s": 1e-4, "return_series": true}});
    let a = answer(req);
    let t = &a["time_response"];
    let (r, u) = (nums(&t["stroke_m"]), nums(&t["force_n"]));
    let last = r.len() - (1.0_f64 / 26.26 / 1e-4).round() as usize * 3;
    let (r, u) = (&r[last..], &u[last..]);
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let (mr, mu) = (mean(r), mean(u));
    let sxy: f64 = r.iter().zip(u).map(|(a, b)| (a - mr) * (b - mu)).sum();
    let sxx: f64 = r.iter().map(|a| (a - mr).powi(2)).sum();
    let syy: f64 = u.iter().map(|b| (b - mu).powi(2)).sum();
    close_rel("regression slope u on r", sxy / sxx, -1327.35, 1e-3);
    assert!(sxy / (sxx * syy).sqrt() < -0.9999, "correlation");
}

/// Scenario base of spec §6 (model-consistent: tuning and excitation by mode index).
fn scenario(mode: &str, excite: u32, tune: u32, x_a: f64, points: &[f64]) -> Value {
    json!({
        "absorber": {"passive_tuning_mode": 1, "position_m": x_a},
        "control": {"mode": mode, "tuning_mode": tune},
        "excitation": {"type": "harmonic", "resonance_of_mode": excite},
        "outputs": {"time_response": {"t_end_s": 10.0, "dt_s": 0.001, "points_m": points, "return_series": true}}
    })
}

/// max |w_tip| over `[t0, t1]` from the series.
fn window_max(a: &Value, t0: f64, t1: f64) -> f64 {
    let t = nums(&a["time_response"]["t_s"]);
    let w = nums(&a["time_response"]["points"][0]["w_m"]);
    t.iter()
        .zip(&w)
        .filter(|(t, _)| **t >= t0 - 1e-12 && **t <= t1 + 1e-12)
        .map(|(_, w)| w.abs())
        .fold(0.0, f64::max)
}

fn tip_max(a: &Value) -> f64 {
    num(&a["time_response"]["points"][0]["max_abs_m"])
}

#[test]
fn t1_t3_bare_beam_at_resonance_grows_linearly() {
    for (k, slope) in [(1, 38.83e-3), (2, 6.195e-3)] {
        let a = answer(scenario("none", k, 1, 1.0, &[1.0]));
        let got = (window_max(&a, 9.0, 10.0) - window_max(&a, 4.0, 5.0)) / 5.0;
        close_rel(&format!("envelope slope, mode {k}"), got, slope, 0.02);
    }
    let a = answer(scenario("none", 2, 1, 1.0, &[1.0]));
    close_rel(
        "T3 tip max in [9, 10] s",
        window_max(&a, 9.0, 10.0),
        62.1e-3,
        0.02,
    );
}

#[test]
fn t2_passive_and_active_alike_at_the_first_resonance() {
    let passive = tip_max(&answer(scenario("passive", 1, 1, 1.0, &[1.0])));
    let active = tip_max(&answer(scenario("active", 1, 1, 1.0, &[1.0])));
    let none = tip_max(&answer(scenario("none", 1, 1, 1.0, &[1.0])));
    assert!(
        passive < 15e-3 && active < 15e-3,
        "passive {passive}, active {active}"
    );
    assert!(passive / active < 2.0 && active / passive < 2.0);
    assert!(none > 350e-3, "none {none}");
}

#[test]
fn t4_t5_t6_second_resonance_needs_the_active_absorber() {
    let none = answer(scenario("none", 2, 2, 1.0, &[1.0]));
    let passive = answer(scenario("passive", 2, 2, 1.0, &[1.0]));
    assert!(
        window_max(&passive, 9.0, 10.0) > 40e-3,
        "T4: passive still grows"
    );
    let tip = tip_max(&answer(scenario("active", 2, 2, 1.0, &[1.0])));
    assert!(tip < 1e-3, "T5: {tip}");
    close_rel("T5 ≈ 0.67 mm", tip, 0.67e-3, 0.05);
    assert!(tip_max(&none) / tip > 50.0);
    // T6: position influence, the tip response for x_a = L/3, 2L/3 and the node of mode 2.
    let at = |x: f64| tip_max(&answer(scenario("active", 2, 2, x, &[1.0])));
    let (third, two_thirds, node) = (at(1.0 / 3.0), at(2.0 / 3.0), at(0.783_445));
    assert!(tip < third && third < two_thirds && two_thirds < node);
    // The spec gives these as "≈" (two digits): measured 0.95 and 1.51 mm, checked at 10 %.
    close_rel("x_a = L/3 ≈ 0.95 mm", third, 0.95e-3, 0.1);
    close_rel("x_a = 2L/3 ≈ 1.4 mm", two_thirds, 1.4e-3, 0.1);
    close_rel("x_a at the node ≈ none", node, tip_max(&none), 0.05);
}

#[test]
fn t7_impulse_response_is_the_sum_of_modes() {
    let a = answer(json!({
        "control": {"mode": "none"},
        "excitation": {"type": "impulse", "amplitude_n": 1.0},
        "outputs": {"time_response": {"t_end_s": 1.0, "dt_s": 0.001, "points_m": [1.0, 0.4], "return_series": true}}
    }));
    let b = answer(json!({"control": {"mode": "none"}}));
    let f = nums(&b["beam"]["natural_frequencies_hz"]);
    let m = num(&b["beam"]["modal_mass_kg"]);
    let t = nums(&a["time_response"]["t_s"]);
    for (j, x) in [1.0, 0.4].iter().enumerate() {
        let w = nums(&a["time_response"]["points"][j]["w_m"]);
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for (ti, wi) in t.iter().zip(&w) {
            let exact: f64 = (1..=3)
                .map(|k| {
                    let s = ModeShape::new(k);
                    let om = 2.0 * std::f64::consts::PI * f[k - 1];
                    s.phi(*x) * s.phi(1.0) / (m * om) * (om * ti).sin()
                })
                .sum();
            worst = worst.max((wi - exact).abs());
            scale = scale.max(exact.abs());
        }
        assert!(worst <= 1e-11 * scale, "x = {x}: {worst:e} vs {scale:e}");
    }
}

#[test]
fn bare_beam_at_exact_resonance_matches_the_secular_solution() {
    // p = sin(ω₂ t) at the tip, ζ = 0: q₂ = F/(2ω²)(sin ωt − ωt cos ωt), the others
    // F/(ω_k² − Ω²)(sin Ωt − Ω/ω_k sin ω_k t).
    let a = answer(json!({
        "control": {"mode": "none"},
        "excitation": {"type": "harmonic", "resonance_of_mode": 2},
        "outputs": {"time_response": {"t_end_s": 10.0, "dt_s": 0.001, "return_series": true}}
    }));
    let f = nums(&a["beam"]["natural_frequencies_hz"]);
    let m = num(&a["beam"]["modal_mass_kg"]);
    let big_w = 2.0 * std::f64::consts::PI * f[1];
    let t = nums(&a["time_response"]["t_s"]);
    let w = nums(&a["time_response"]["points"][0]["w_m"]);
    let mut worst: f64 = 0.0;
    for (ti, wi) in t.iter().zip(&w) {
        let exact: f64 = (1..=3)
            .map(|k| {
                let fk = 4.0 / m; // φ_k(L)² = 4
                let om = 2.0 * std::f64::consts::PI * f[k - 1];
                if k == 2 {
                    fk / (2.0 * om * om) * ((om * ti).sin() - om * ti * (om * ti).cos())
                } else {
                    fk / (om * om - big_w * big_w)
                        * ((big_w * ti).sin() - big_w / om * (om * ti).sin())
                }
            })
            .sum();
        worst = worst.max((wi - exact).abs());
    }
    let scale = w.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    assert!(worst <= 1e-9 * scale, "{worst:e} vs {scale:e}");
}

/// Fixed-step RK4 of `ṡ = A s + B p(t)`: the independent check of the exact response.
fn rk4(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    p: impl Fn(f64) -> f64,
    h: f64,
    steps: usize,
    every: usize,
) -> Vec<DVector<f64>> {
    let f = |t: f64, s: &DVector<f64>| a * s + b * p(t);
    let mut s = DVector::zeros(a.nrows());
    let mut out = vec![s.clone()];
    for k in 0..steps {
        let t = k as f64 * h;
        let k1 = f(t, &s);
        let k2 = f(t + h / 2.0, &(&s + &k1 * (h / 2.0)));
        let k3 = f(t + h / 2.0, &(&s + &k2 * (h / 2.0)));
        let k4 = f(t + h, &(&s + &k3 * h));
        s += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        if (k + 1) % every == 0 {
            out.push(s.clone());
        }
    }
    out
}

#[test]
fn exact_time_response_agrees_with_a_fine_rk4() {
    // Benchmark S2 of spec §8 (AVA at the tip tuned to the model's f₂, 1 N sin(2π f₂ t)), 2 s,
    // for each configuration. RK4 at h = 10 µs has an O(h⁴) error ≈ 1e-10 relative (spec §8:
    // 1.6e-6 at 0.1 ms), far below the tolerance 1e-8.
    for mode in ["none", "passive", "passive_shorted", "active"] {
        let req = json!({
            "absorber": {"passive_tuning_mode": 1},
            "control": {"mode": mode, "tuning_mode": 2},
            "excitation": {"type": "harmonic", "resonance_of_mode": 2, "phase_rad": 0.3},
            "outputs": {"time_response": {"t_end_s": 2.0, "dt_s": 0.001, "return_series": true}}
        });
        let a = answer(req.clone());
        let w = nums(&a["time_response"]["points"][0]["w_m"]);
        let input = VibrationAbsorberInput::try_from(request(req)).expect("valid");
        let (model, freqs, _) = build_model(&input);
        let om = 2.0 * std::f64::consts::PI * freqs[1];
        let states = rk4(
            &model.a_matrix(),
            &model.b_vector(),
            |t| (om * t + 0.3).sin(),
            1e-5,
            200_000,
            100,
        );
        let c = model.row_deflection(1.0);
        let scale = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let worst = states
            .iter()
            .zip(&w)
            .map(|(s, wi)| (c.dot(s) - wi).abs())
            .fold(0.0_f64, f64::max);
        assert_eq!(states.len(), w.len());
        assert!(worst <= 1e-8 * scale, "{mode}: {worst:e} vs max {scale:e}");
    }
}

#[test]
fn mode_shapes_on_request() {
    let mut req = paper_case();
    req["outputs"] = json!({"mode_shapes": {"n_points": 11}});
    let a = answer(req);
    let s = &a["mode_shapes"];
    assert_eq!(nums(&s["x_m"]).len(), 11);
    for (k, shape) in s["shapes"].as_array().expect("shapes").iter().enumerate() {
        let phi = nums(shape);
        close("φ(0)", phi[0], 0.0, 1e-12);
        close("φ(L)", phi[10], if k % 2 == 0 { 2.0 } else { -2.0 }, 1e-12);
    }
    assert!(
        answer(paper_case()).get("mode_shapes").is_none(),
        "omitted unless asked"
    );
}

#[test]
fn a_negative_dc_gain_keeps_the_settling_and_overshoot_convention() {
    // K_c < 0 flips the sign of G_ec: the DC gain changes sign, the settling time and overshoot
    // (measured with the sign of y∞ divided out) do not.
    let step = |kc: f64| {
        let mut req = paper_case();
        req["control"] = json!({"mode": "passive_shorted"});
        req["actuator"]["force_constant_n_a"] = json!(kc);
        // K_b = 0 keeps D(s) the same for both signs (K_b K_c would otherwise flip too).
        req["actuator"]["back_emf_v_s_m"] = json!(0.0);
        req["absorber"]["damping_n_s_m"] = json!(1.0);
        req["outputs"] = json!({"ava_step": true});
        answer(req)["ava_step"]["xa_over_ec"].clone()
    };
    let (pos, neg) = (step(3.5), step(-3.5));
    assert!(
        num(&pos["overshoot_pct"]) > 1.0,
        "an underdamped case, so the convention matters"
    );
    close(
        "DC sign",
        num(&neg["dc_gain"]),
        -num(&pos["dc_gain"]),
        1e-15,
    );
    close(
        "settling",
        num(&neg["settling_time_s"]),
        num(&pos["settling_time_s"]),
        1e-12,
    );
    close(
        "overshoot",
        num(&neg["overshoot_pct"]),
        num(&pos["overshoot_pct"]),
        1e-9,
    );
}

#[test]
fn absorber_closed_loop_frf_peaks_at_the_tuning() {
    // Paper Fig. 6: |G_cl| has its (infinite) peak at f_c; at DC G_cl = K_c K_p / (k_a R + K_c K_p).
    let mut req = paper_case();
    req["outputs"] =
        json!({"ava_frequency_response": {"f_min_hz": 25.0, "f_max_hz": 27.5, "n_points": 101}});
    let a = answer(req.clone());
    let g = &a["ava_frequency_response"];
    close(
        "peak frequency",
        num(&g["peak_frequency_hz"]),
        26.26,
        0.0125 + 1e-9,
    );
    req["outputs"] =
        json!({"ava_frequency_response": {"f_min_hz": 1e-6, "f_max_hz": 1e-6, "n_points": 1}});
    let a = answer(req);
    let (kp, ka) = (606.851_090_171_872_2, 33.832_214_318_582_22);
    let dc = 3.5 * kp / (ka * 1.6 + 3.5 * kp);
    close_rel(
        "|G_cl(0)|",
        num(&a["ava_frequency_response"]["magnitude"][0]),
        dc,
        1e-9,
    );
}

// ---------------------------------------------------------------------------------------------
// n = 1: the paper's per-mode receptances, Eq. (17)–(19), written out independently
// ---------------------------------------------------------------------------------------------

/// `β₁L` by Newton on `1 + cos x cosh x` from 1.875 (independent of `beam::beta_l`).
fn beta_1() -> f64 {
    let mut x: f64 = 1.875;
    for _ in 0..50 {
        let f = 1.0 + x.cos() * x.cosh();
        let df = -x.sin() * x.cosh() + x.cos() * x.sinh();
        x -= f / df;
    }
    x
}

/// The paper's mode shape Eq. (12) with the corrected coefficient of Eq. (13) (spec §4 item 5),
/// `C = 1`, and its second derivative; `l = 1`.
fn paper_shape(beta: f64, x: f64) -> (f64, f64) {
    let alpha = (beta.sin() + beta.sinh()) / (beta.cos() + beta.cosh());
    let (s, sh, c, ch) = (
        (beta * x).sin(),
        (beta * x).sinh(),
        (beta * x).cos(),
        (beta * x).cosh(),
    );
    (
        s - sh - alpha * (c - ch),
        beta * beta * (-s - sh + alpha * (c + ch)),
    )
}

/// Composite Simpson on [0, 1] with `n` (even) intervals.
fn simpson01(f: impl Fn(f64) -> f64, n: usize) -> f64 {
    let h = 1.0 / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(0.0) + f(1.0) + inner) * h / 3.0
}

/// The actuator force per unit stroke `U/r = C(s)` through the coil and the PD law.
type Coil = Box<dyn Fn(Complex<f64>) -> Complex<f64>>;

/// The paper's receptance `W(x_o)/P` for n = 1 (Eq. (17)–(19), with the actuator force closed
/// through the coil and the PD law). Eq. (18)–(19) are written for force, absorber and output all
/// at the tip; here `φ(l)²` is split into `φ(x_o)φ(x_p)`, `φ(x_a)²`, `φ(x_o)φ(x_a)` as the same
/// Lagrange derivation gives for other positions.
struct PaperN1 {
    m11: f64,
    k11: f64,
    c11: f64,
    phi: [f64; 3],
    ma: f64,
    ka: f64,
    ba: f64,
    /// `U = C(s)·r`: the actuator force per unit stroke through coil and PD law (`None`: no
    /// absorber at all).
    coil: Option<Coil>,
}

impl PaperN1 {
    fn receptance(&self, s: Complex<f64>) -> Complex<f64> {
        let [po, pp, pa] = self.phi;
        let beam = s * s * self.m11 + s * self.c11 + self.k11;
        let Some(coil) = &self.coil else {
            return po * pp / beam;
        };
        let da = s * s * self.ma + s * self.ba + self.ka;
        // Eq. (19): G = m s² + k + m_a s²(k_a + b_a s)/D_a · φ_a².
        let g = beam + s * s * self.ma * (s * self.ba + self.ka) / da * pa * pa;
        // Eq. (18): G_p = φ_o φ_p / G, G_u = −m_a s²/D_a · φ_o φ_a / G.
        let gu = |phi_o: f64| -s * s * self.ma / da * phi_o * pa / g;
        let gp = |phi_o: f64| phi_o * pp / g;
        // Closure: r = (U − m_a s² W_a)/D_a and U = C r, W_a = G_p(a) P + G_u(a) U.
        let c = coil(s);
        let u_per_wa = -c * s * s * self.ma / (da - c);
        let wa = gp(pa) / (1.0 - gu(pa) * u_per_wa);
        gp(po) + gu(po) * u_per_wa * wa
    }
}

#[test]
fn n1_coupled_frf_equals_the_paper_per_mode_eq_17_to_19() {
    use std::f64::consts::PI;
    let (e, rho) = (2.1e11, 7850.0);
    let (area, inertia) = (0.05 * 0.005, 0.05 * 0.005_f64.powi(3) / 12.0);
    let beta = beta_1();
    let m11 = rho * area * simpson01(|x| paper_shape(beta, x).0.powi(2), 20_000);
    let k11 = e * inertia * simpson01(|x| paper_shape(beta, x).1.powi(2), 20_000);
    let (ma, ba) = (0.05, 0.01);
    let ka = ma * (2.0 * PI * 4.14).powi(2);
    let (r, lc, kc, kb) = (1.6, 0.75e-3, 3.5, 3.5);
    // Eq. (7)(8) at f_c = 26.26 Hz, evaluated with complex arithmetic.
    let wc = 2.0 * PI * 26.26;
    let sc = Complex::new(0.0, wc);
    let minus_d = -((sc * lc + r) * (sc * sc * ma + sc * ba + ka) + sc * (kb * kc)) / kc;
    let (kp, kd) = (minus_d.re, minus_d.im / wc);
    let (mut worst, mut worst_scaled): (f64, f64) = (0.0, 0.0);
    // (x_o, x_p, x_a, ζ): the paper's all-at-the-tip case, then other positions with damping.
    for (xo, xp, xa, zeta) in [(1.0, 1.0, 1.0, 0.0), (0.9, 0.8, 0.6, 0.01)] {
        let phi = [xo, xp, xa].map(|x| paper_shape(beta, x).0);
        let c11 = 2.0 * zeta * (k11 * m11).sqrt();
        for mode in ["none", "passive", "passive_shorted", "active"] {
            let coil: Option<Coil> = match mode {
                "none" => None,
                "passive" => Some(Box::new(|_| Complex::new(0.0, 0.0))),
                // (L_c s + R) i = −K_b ṙ: U = −K_c K_b s / (L_c s + R) · r.
                "passive_shorted" => Some(Box::new(move |s| -(s * (kc * kb)) / (s * lc + r))),
                // (L_c s + R) i = −K_b ṙ − (K_p r + K_d ṙ).
                _ => Some(Box::new(move |s| {
                    -((s * (kb + kd) + kp) * kc) / (s * lc + r)
                })),
            };
            let paper = PaperN1 {
                m11,
                k11,
                c11,
                phi,
                ma,
                ka,
                ba,
                coil,
            };
            let a = answer(json!({
                "beam": {"n_modes": 1, "modal_damping_ratio": zeta},
                "absorber": {"passive_tuning_hz": 4.14, "damping_n_s_m": ba, "position_m": xa},
                "control": {"mode": mode, "tuning_hz": 26.26},
                "excitation": {"position_m": xp},
                "outputs": {"frequency_response": {"f_min_hz": 0.5, "f_max_hz": 100.0,
                    "n_points": 397, "log": true, "points_m": [xo]}}
            }));
            let fr = &a["frequency_response"];
            let f = nums(&fr["frequencies_hz"]);
            let mag = nums(&fr["points"][0]["magnitude_m_per_n"]);
            let ph = nums(&fr["points"][0]["phase_deg"]);
            let h0 = paper.receptance(Complex::new(0.0, 0.0)).norm();
            for i in 0..f.len() {
                let want = paper.receptance(Complex::new(0.0, 2.0 * PI * f[i]));
                let got = Complex::from_polar(mag[i], ph[i].to_radians());
                let rel = (got - want).norm() / want.norm();
                // 1e-12 relative; near a lightly damped pole round-off in both evaluations is
                // amplified by the dynamic magnification |H|/|H(0)| (measured: 6.6e-12 at
                // 3.9776 Hz, 0.003 Hz from the active n = 1 closed-loop pole, |H|/|H(0)| ≈ 860).
                // Near the antiresonance |H| falls far below |H(0)| while the state does not: the
                // FRF (read from the state in Schur coordinates) is exact there to round-off of
                // |H(0)|, so the bound is taken relative to max(|H|, |H(0)|).
                let magnification = (want.norm() / h0).max(1.0) * (h0 / want.norm()).max(1.0);
                worst = worst.max(rel);
                worst_scaled = worst_scaled.max(rel / magnification);
                assert!(
                    rel <= 1e-12 * magnification,
                    "{mode} at x_o={xo}, x_p={xp}, x_a={xa}, ζ={zeta}, f={} Hz: {got} vs paper {want} (rel {rel:e})",
                    f[i]
                );
            }
        }
    }
    eprintln!(
        "n = 1, coupled vs Eq. (17)–(19): worst relative difference {worst:.2e}, \
         {worst_scaled:.2e} divided by the magnification"
    );
}

// ---------------------------------------------------------------------------------------------
// Several harmonics (spec §3.D.4) and the optional series
// ---------------------------------------------------------------------------------------------

/// Every series of a time response, by name.
fn series(a: &Value) -> Vec<(String, Vec<f64>)> {
    let t = &a["time_response"];
    let mut out: Vec<(String, Vec<f64>)> = t["points"]
        .as_array()
        .expect("points")
        .iter()
        .enumerate()
        .map(|(j, p)| (format!("w_m[{j}]"), nums(&p["w_m"])))
        .collect();
    for k in ["stroke_m", "force_n", "current_a", "voltage_v"] {
        if let Some(v) = t.get(k) {
            out.push((k.to_owned(), nums(v)));
        }
    }
    out
}

#[test]
fn several_harmonics_superpose_to_round_off() {
    // Undamped beam, active absorber: one component at the model's f₁ (secular growth), one at
    // f₂ (the tuning), one off-resonance with a phase. The list answer is the sum of the three
    // single-harmonic answers for every channel.
    let comps = [
        json!({"amplitude_n": 1.0, "resonance_of_mode": 1}),
        json!({"amplitude_n": -0.7, "resonance_of_mode": 2, "phase_rad": 0.4}),
        json!({"amplitude_n": 2.5, "frequency_hz": 11.3, "phase_rad": -1.2}),
    ];
    let outputs = json!({"time_response": {"t_end_s": 3.0, "dt_s": 0.001,
        "points_m": [1.0, 0.45], "return_series": true}});
    for mode in ["none", "passive", "passive_shorted", "active"] {
        let base = json!({"absorber": {"passive_tuning_mode": 1},
            "control": {"mode": mode, "tuning_mode": 2}, "outputs": outputs});
        let mut multi = base.clone();
        multi["excitation"] = json!({"harmonics": comps});
        let multi = answer(multi);
        let mut sum: Option<Vec<(String, Vec<f64>)>> = None;
        for c in &comps {
            let mut single = base.clone();
            let mut e = c.clone();
            e["type"] = json!("harmonic");
            single["excitation"] = e;
            let s = series(&answer(single));
            sum = Some(match sum {
                None => s,
                Some(acc) => acc
                    .into_iter()
                    .zip(s)
                    .map(|((k, a), (_, b))| (k, a.iter().zip(&b).map(|(x, y)| x + y).collect()))
                    .collect(),
            });
        }
        let got = series(&multi);
        let want = sum.expect("three components");
        assert_eq!(got.len(), want.len(), "{mode}: same channels");
        for ((name, g), (_, w)) in got.iter().zip(&want) {
            let scale = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            let worst = g
                .iter()
                .zip(w)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0_f64, f64::max);
            assert!(
                worst <= 1e-11 * scale,
                "{mode} {name}: {worst:e} vs max {scale:e}"
            );
        }
        let f = nums(&multi["time_response"]["excitation_frequencies_hz"]);
        let fk = nums(&multi["beam"]["natural_frequencies_hz"]);
        assert_eq!(f, vec![fk[0], fk[1], 11.3]);
    }
}

#[test]
fn several_harmonics_settle_to_the_sum_of_frf_steady_states() {
    // Damped beam and absorber: after the transients, w(t) = Σ_j P_j |H(f_j)| sin(Ω_j t + φ_j +
    // arg H(f_j)) with H from the frequency-response output.
    let comps = [(1.0, 3.0, 0.2), (0.4, 17.0, -0.5), (0.25, 40.0, 1.0)];
    let list: Vec<Value> = comps
        .iter()
        .map(|(p, f, ph)| json!({"amplitude_n": p, "frequency_hz": f, "phase_rad": ph}))
        .collect();
    let a = answer(json!({
        "beam": {"modal_damping_ratio": 0.05},
        "absorber": {"passive_tuning_mode": 1, "damping_n_s_m": 0.5},
        "control": {"mode": "active", "tuning_mode": 2},
        "excitation": {"harmonics": list},
        "outputs": {"eigenvalues": true,
                    "time_response": {"t_end_s": 40.0, "dt_s": 0.001, "return_series": true},
                    "frequency_response": {"f_min_hz": 3.0, "f_max_hz": 40.0, "n_points": 38}}
    }));
    let fr = &a["frequency_response"];
    let grid = nums(&fr["frequencies_hz"]);
    let (mag, ph) = (
        nums(&fr["points"][0]["magnitude_m_per_n"]),
        nums(&fr["points"][0]["phase_deg"]),
    );
    let h = |f: f64| {
        let i = grid
            .iter()
            .position(|g| (g - f).abs() < 1e-9)
            .expect("on the grid");
        (mag[i], ph[i].to_radians())
    };
    let t = nums(&a["time_response"]["t_s"]);
    let w = nums(&a["time_response"]["points"][0]["w_m"]);
    let amp: f64 = comps.iter().map(|(p, f, _)| p * h(*f).0).sum();
    // The last 1/3 s: one full period of the slowest component.
    for (ti, wi) in t.iter().zip(&w).rev().take(334) {
        let ss: f64 = comps
            .iter()
            .map(|(p, f, phase)| {
                let (m, arg) = h(*f);
                p * m * (2.0 * std::f64::consts::PI * f * ti + phase + arg).sin()
            })
            .sum();
        assert!(
            (wi - ss).abs() <= 1e-6 * amp,
            "t = {ti}: {wi:e} vs {ss:e} (Σ|H|P {amp:e})"
        );
    }
    // The "last period" reduction spans the slowest component's period: the samples with
    // t ≥ 40 − 1/3 s, i.e. the last 334.
    let last = num(&a["time_response"]["points"][0]["max_abs_last_period_m"]);
    let peak = w
        .iter()
        .rev()
        .take(334)
        .fold(0.0_f64, |m, x| m.max(x.abs()));
    close("max |w| over the last period", last, peak, 0.0);
    // The transients have decayed by e^{-20} or more.
    let rate = -num(&a["closed_loop"]["max_real_part_1_s"]);
    assert!(rate * 40.0 > 20.0, "slowest decay rate {rate} 1/s");
}

#[test]
fn time_series_of_stroke_force_current_and_voltage_on_request() {
    let req = |mode: &str, series: bool| {
        json!({"beam": {"modal_damping_ratio": 0.01},
            "absorber": {"passive_tuning_mode": 1},
            "control": {"mode": mode, "tuning_mode": 2},
            "excitation": {"type": "harmonic", "frequency_hz": 20.0},
            "outputs": {"time_response": {"t_end_s": 1.0, "dt_s": 1e-5, "return_series": series}}})
    };
    let present = |t: &Value| {
        ["stroke_m", "force_n", "current_a", "voltage_v"]
            .map(|k| t.get(k).is_some())
            .to_vec()
    };
    // Only when asked, and only the channels the configuration has.
    for (mode, want) in [
        ("none", [false, false, false, false]),
        ("passive", [true, false, false, false]),
        ("passive_shorted", [true, true, true, false]),
        ("active", [true, true, true, true]),
    ] {
        let off = answer(req(mode, false));
        assert_eq!(present(&off["time_response"]), vec![false; 4], "{mode}");
        assert!(off["time_response"].get("t_s").is_none());
        let on = answer(req(mode, true));
        assert_eq!(present(&on["time_response"]), want.to_vec(), "{mode}");
        // The series' extremes are the reductions (no decimation).
        let t = &on["time_response"];
        for (s, m) in [
            ("stroke_m", "stroke_max_m"),
            ("force_n", "force_max_n"),
            ("current_a", "current_max_a"),
            ("voltage_v", "voltage_max_v"),
        ] {
            if let Some(v) = t.get(s) {
                let peak = nums(v).iter().fold(0.0_f64, |a, x| a.max(x.abs()));
                close(&format!("{mode} {m}"), num(&t[m]), peak, 0.0);
            }
        }
    }
    // Active: u = K_c i, and the series satisfy the coil and PD equations in integral form over
    // [0, t] (Simpson on the 10 µs samples): K_d (r(t) − r(0)) = −∫(e_c + K_p r) and
    // L_c (i(t) − i(0)) = ∫(e_c − R i) − K_b (r(t) − r(0)).
    let a = answer(req("active", true));
    let t = &a["time_response"];
    let (r, u, i, e) = (
        nums(&t["stroke_m"]),
        nums(&t["force_n"]),
        nums(&t["current_a"]),
        nums(&t["voltage_v"]),
    );
    for (uk, ik) in u.iter().zip(&i) {
        // Exact in the state; 1e-14 covers the JSON round trip.
        close("u = K_c i", *uk, 3.5 * ik, 1e-14 * uk.abs());
    }
    let (kp, kd) = (num(&a["gains"]["kp_v_m"]), num(&a["gains"]["kd_v_s_m"]));
    let h = 1e-5;
    let simpson = |y: &[f64]| {
        let n = y.len() - 1;
        assert_eq!(n % 2, 0);
        let inner: f64 = (1..n)
            .map(|k| y[k] * if k % 2 == 1 { 4.0 } else { 2.0 })
            .sum();
        (y[0] + y[n] + inner) * h / 3.0
    };
    let pd: Vec<f64> = e.iter().zip(&r).map(|(e, r)| e + kp * r).collect();
    let coil: Vec<f64> = e.iter().zip(&i).map(|(e, i)| e - 1.6 * i).collect();
    let dr = r[r.len() - 1] - r[0];
    let di = i[i.len() - 1] - i[0];
    let e_scale = e.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    // Simpson's error here is ~ (Ω h)⁴ ≈ 2e-10 of the integrand scale.
    close("PD law", kd * dr, -simpson(&pd), 1e-8 * e_scale);
    close(
        "coil equation",
        0.75e-3 * di,
        simpson(&coil) - 3.5 * dr,
        1e-8 * e_scale,
    );
}

// ---------------------------------------------------------------------------------------------
// The fast paths (issue 27) against the previous dense implementations, kept in
// `vibration_absorber::response` as the reference: fixed-size absorber step metrics, the FRF
// and the time response from one Schur decomposition, and the exactness of both near defective
// (repeated) eigenvalues.
// ---------------------------------------------------------------------------------------------

mod fast_paths {
    use super::*;
    use mechcalc::calc::vibration_absorber::compute::ava_step::step_pair;
    use mechcalc::calc::vibration_absorber::compute::schur_response;
    use mechcalc::calc::vibration_absorber::model::{Device, Gains, Model};
    use mechcalc::calc::vibration_absorber::response::{
        StepMetrics, Stepper, frequency_response, step_metrics,
    };
    use mechcalc::numerics::linalg::BalancedSchur;
    use std::f64::consts::PI;

    /// Settling times agree to this relative amount: both bisect the same exact response to the
    /// last bit; the states differ only by the rounding of a few dozen 4 × 4 products.
    const SETTLING_REL: f64 = 1e-12;
    /// Samples, DC gains and overshoots: rounding of 5000 repeated products of the same `Φ`.
    const SAMPLE_REL: f64 = 1e-11;
    /// FRF: both solve the same linear system backward-stably, so they differ by round-off
    /// amplified by the distance to the spectrum: `|ΔH| ≤ FRF_REL·κ·|H| + FRF_FLOOR·max|H|`
    /// with `κ = max(1, max|λ| / min|jω − λ|)`. The floor is the absolute round-off of the
    /// output functional at an antiresonance, where `|H|` is small but the state is not.
    const FRF_REL: f64 = 1e-12;
    /// See [`FRF_REL`].
    const FRF_FLOOR: f64 = 1e-13;
    /// Time responses relative to each channel's peak: round-off of 1e4–1e5 steps of either
    /// transition matrix (spec §8: 2e-12 at n = 3 and 10 s, 1.4e-10 at n = 30).
    const TIME_REL: f64 = 1e-9;

    fn model_of(v: Value) -> (Model, Option<Gains>) {
        let input = VibrationAbsorberInput::try_from(request(v)).expect("valid input");
        let (m, _, g) = build_model(&input);
        (m, g)
    }

    fn same_step(what: &str, got: &StepMetrics, want: &StepMetrics) {
        match (got.settling, want.settling) {
            (Some(a), Some(b)) => close_rel(&format!("{what} settling"), a, b, SETTLING_REL),
            (a, b) => assert_eq!(a.is_some(), b.is_some(), "{what}: settling {a:?} vs {b:?}"),
        }
        close(
            &format!("{what} overshoot"),
            got.overshoot_pct,
            want.overshoot_pct,
            1e-9,
        );
        assert_eq!(got.dc, want.dc, "{what}: DC gain");
        if let (Some((tg, yg)), Some((tw, yw))) = (&got.series, &want.series) {
            let peak = yw.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            for k in 0..yw.len() {
                close(&format!("{what} t[{k}]"), tg[k], tw[k], 1e-15 * tw[k].abs());
                close(&format!("{what} y[{k}]"), yg[k], yw[k], SAMPLE_REL * peak);
            }
        } else {
            assert_eq!(got.series.is_some(), want.series.is_some());
        }
    }

    /// The reference: two separate calls of the dense `step_metrics`, as compute made them.
    fn reference_pair(dev: &Device, gains: Option<&Gains>) -> (StepMetrics, Option<StepMetrics>) {
        let (a, b) = dev.fixed_base();
        let dc_ec = (dev.ka > 0.0).then(|| dev.kc / (dev.ka * dev.r));
        let ec = step_metrics(&a, &b, &DVector::from_vec(vec![1.0, 0.0, 0.0]), dc_ec, true);
        let err = gains.map(|g| {
            let c = DVector::from_vec(vec![g.kp, g.kd, 0.0]);
            step_metrics(&a, &b, &c, dc_ec.map(|d| d * g.kp), true)
        });
        (ec, err)
    }

    #[test]
    fn ava_step_matches_the_dense_reference() {
        let paper = paper_case();
        let mut cases = vec![("paper case (V7)", paper.clone())];
        let mut with = |name: &'static str, patch: Value| {
            let mut v = paper.clone();
            for (k, p) in patch.as_object().expect("object") {
                for (kk, pv) in p.as_object().expect("object") {
                    v[k][kk] = pv.clone();
                }
            }
            cases.push((name, v));
        };
        with("b_a = 0.1", json!({"absorber": {"damping_n_s_m": 0.1}}));
        with(
            "heavy absorber, fast coil",
            json!({"absorber": {"mass_kg": 0.5}, "actuator": {"inductance_h": 1e-5}}),
        );
        with("no back-EMF", json!({"actuator": {"back_emf_v_s_m": 0.0}}));
        with(
            "overshooting (light damping, weak coil)",
            json!({"actuator": {"back_emf_v_s_m": 0.05, "force_constant_n_a": 0.05}}),
        );
        with(
            "explicit gains",
            json!({"control": {"mode": "active", "kp_v_m": 50.0, "kd_v_s_m": 0.3}}),
        );
        with(
            "no spring (no DC gain)",
            json!({"absorber": {"stiffness_n_m": 0.0, "passive_tuning_hz": null}}),
        );
        with(
            "passive (no gains)",
            json!({"control": {"mode": "passive"}}),
        );
        for (name, v) in cases {
            let (m, g) = model_of(v);
            let (ec, err) = step_pair(&m.dev, g.as_ref(), true);
            let (ec_ref, err_ref) = reference_pair(&m.dev, g.as_ref());
            same_step(&format!("{name}: G_ec"), &ec, &ec_ref);
            assert_eq!(err.is_some(), err_ref.is_some(), "{name}: G_err presence");
            if let (Some(a), Some(b)) = (&err, &err_ref) {
                same_step(&format!("{name}: G_err"), a, b);
            }
            // The shared levels: never more exponentials than the reference's one per bisection step.
            let used = ec.expms + err.as_ref().map_or(0, |e| e.expms);
            let before = ec_ref.expms + err_ref.as_ref().map_or(0, |e| e.expms);
            assert!(used <= before, "{name}: {used} exponentials vs {before}");
        }
    }

    /// Grids of the FRF tests: a log grid over the modes and one landing near each pole.
    fn grids(values: &[Complex<f64>]) -> Vec<f64> {
        let mut w: Vec<f64> = (0..300)
            .map(|i| 2.0 * PI * 0.3 * (1e4_f64 / 0.3).powf(f64::from(i) / 299.0))
            .collect();
        for l in values.iter().filter(|l| l.im > 0.0) {
            w.extend([l.im * (1.0 - 1e-4), l.im * (1.0 + 1e-3), l.im]);
        }
        w
    }

    fn compare_frf(name: &str, a: &DMatrix<f64>, b: &DVector<f64>, rows: &[DVector<f64>]) {
        let schur = BalancedSchur::new(a).expect("Schur form of the coupled model");
        let eig = eigenvalues(a).expect("eigenvalues");
        assert_eq!(
            schur.values, eig,
            "{name}: the kept form gives the same eigenvalues"
        );
        let w = grids(&eig);
        let budget = Budget::unlimited();
        let got = schur_response::frequency_response(&schur, b, rows, &w, &budget).expect("FRF");
        let want = frequency_response(a, b, rows, &w, &eig, &budget).expect("reference FRF");
        let max_abs = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
        let peak: Vec<f64> = (0..rows.len())
            .map(|j| {
                want.iter()
                    .filter_map(|r| r[j])
                    .map(|h| h.norm())
                    .fold(0.0, f64::max)
            })
            .collect();
        for (i, (g, r)) in got.iter().zip(&want).enumerate() {
            let jw = Complex::new(0.0, w[i]);
            let dist = eig
                .iter()
                .map(|l| (jw - l).norm())
                .fold(f64::INFINITY, f64::min);
            let kappa = (max_abs / dist).max(1.0);
            for (j, (g, r)) in g.iter().zip(r).enumerate() {
                match (g, r) {
                    (Some(g), Some(r)) => {
                        let tol = FRF_REL * kappa * g.norm().max(r.norm()) + FRF_FLOOR * peak[j];
                        assert!(
                            (g - r).norm() <= tol,
                            "{name}: ω = {} row {j}: {g} vs {r} (|Δ| {:.2e}, tol {tol:.2e})",
                            w[i],
                            (g - r).norm()
                        );
                    }
                    (None, None) => {}
                    _ => panic!("{name}: ω = {} row {j}: {g:?} vs {r:?}", w[i]),
                }
            }
        }
    }

    fn configs() -> Vec<(String, Value)> {
        let mut v = Vec::new();
        for mode in ["none", "passive", "passive_shorted", "active"] {
            for (n, zeta, xa) in [(3, 0.0, 1.0), (5, 0.002, 0.4), (10, 0.01, 0.7834)] {
                v.push((
                    format!("{mode} n={n} ζ={zeta} x_a={xa}"),
                    json!({"beam": {"n_modes": n, "modal_damping_ratio": zeta},
                           "absorber": {"passive_tuning_mode": 1, "position_m": xa},
                           "control": {"mode": mode, "tuning_mode": 2},
                           "excitation": {"position_m": 1.0}}),
                ));
            }
        }
        v
    }

    #[test]
    fn frf_from_one_schur_form_matches_the_lu_per_frequency() {
        for (name, v) in configs() {
            let (m, _) = model_of(v);
            let rows = [m.row_deflection(1.0), m.row_deflection(0.5)];
            compare_frf(&name, &m.a_matrix(), &m.b_vector(), &rows);
        }
    }

    /// A defective matrix (each of `±jω` twice with one eigenvector: an undamped oscillator
    /// driving an identical one, the structure of an exosystem at the beam's own frequency) and a
    /// real Jordan block: the Schur solve equals the closed-form inverse, where a modal
    /// (eigenvector) expansion would divide by zero.
    #[test]
    fn shifted_solve_is_exact_at_defective_eigenvalues() {
        let w0 = 2.0 * PI * 26.18;
        let a = DMatrix::from_row_slice(
            4,
            4,
            &[
                0.0, w0, 1.0, 0.0, //
                -w0, 0.0, 0.0, 1.0, //
                0.0, 0.0, 0.0, w0, //
                0.0, 0.0, -w0, 0.0,
            ],
        );
        let schur = BalancedSchur::new(&a).expect("Schur form");
        let b = DVector::from_vec(vec![0.3, -0.2, 0.7, 1.1]);
        for w in [0.5 * w0, w0 * (1.0 - 1e-6), w0 * (1.0 + 1e-3), 3.0 * w0] {
            let z = Complex::new(0.0, w);
            // (zI − A)⁻¹ = [[X, X²], [0, X]], X = (zI − R)⁻¹ = [[z, w0], [−w0, z]] / (z² + w0²).
            let det = z * z + w0 * w0;
            let x = [[z / det, w0 / det], [-w0 / det, z / det]];
            let x2 = |i: usize, j: usize| x[i][0] * x[0][j] + x[i][1] * x[1][j];
            // Block form: top = X b_top + X² b_bottom, bottom = X b_bottom.
            let mut want = [Complex::new(0.0, 0.0); 4];
            for i in 0..2 {
                want[i] = (0..2).map(|j| x[i][j] * b[j] + x2(i, j) * b[2 + j]).sum();
                want[2 + i] = (0..2).map(|j| x[i][j] * b[2 + j]).sum();
            }
            let rows: Vec<DVector<f64>> = (0..4)
                .map(|i| DVector::from_fn(4, |r, _| if r == i { 1.0 } else { 0.0 }))
                .collect();
            let got =
                schur_response::frequency_response(&schur, &b, &rows, &[w], &Budget::unlimited())
                    .expect("FRF");
            let scale = want.iter().fold(0.0_f64, |s, z| s.max(z.norm()));
            for i in 0..4 {
                let g = got[0][i].expect("finite off the poles");
                assert!(
                    (g - want[i]).norm() <= 1e-9 * scale,
                    "ω/ω0 = {}: x[{i}] = {g} vs {} (rel {:.2e})",
                    w / w0,
                    want[i],
                    (g - want[i]).norm() / scale
                );
            }
        }
        // On the defective eigenvalue itself the point is screened as singular (null), not NaN.
        let got = schur_response::frequency_response(
            &schur,
            &b,
            &[DVector::from_vec(vec![1.0, 0.0, 0.0, 0.0])],
            &[w0],
            &Budget::unlimited(),
        )
        .expect("FRF");
        assert!(got[0][0].is_none());
        // Real Jordan block J = [[λ, 1], [0, λ]]: (z − J)⁻¹ = [[1/(z−λ), 1/(z−λ)²], [0, 1/(z−λ)]].
        let lam = -3.0;
        let j = DMatrix::from_row_slice(2, 2, &[lam, 1.0, 0.0, lam]);
        let schur = BalancedSchur::new(&j).expect("Schur form");
        let b = DVector::from_vec(vec![0.0, 1.0]);
        for w in [0.1, 1.0, 10.0] {
            let z = Complex::new(0.0, w);
            let want = Complex::new(1.0, 0.0) / ((z - lam) * (z - lam));
            let got = schur_response::frequency_response(
                &schur,
                &b,
                &[DVector::from_vec(vec![1.0, 0.0])],
                &[w],
                &Budget::unlimited(),
            )
            .expect("FRF")[0][0]
                .expect("finite");
            assert!(
                (got - want).norm() <= 1e-14 * want.norm(),
                "{got} vs {want}"
            );
        }
    }

    /// `A_aug`, `s(0)` and the output rows of a harmonic (tip, `f`), step or impulse forcing.
    fn augmented(
        m: &Model,
        forcing: &str,
        f: f64,
    ) -> (DMatrix<f64>, DVector<f64>, Vec<DVector<f64>>) {
        let (a, b) = (m.a_matrix(), m.b_vector());
        let n = a.nrows();
        let extra = match forcing {
            "harmonic" => 2,
            "step" => 1,
            _ => 0,
        };
        let na = n + extra;
        let mut aug = DMatrix::zeros(na, na);
        aug.view_mut((0, 0), (n, n)).copy_from(&a);
        let mut s0 = DVector::zeros(na);
        match forcing {
            "harmonic" => {
                aug.view_mut((0, n), (n, 1)).copy_from(&b);
                aug[(n, n + 1)] = 2.0 * PI * f;
                aug[(n + 1, n)] = -2.0 * PI * f;
                s0[n] = 0.3_f64.sin();
                s0[n + 1] = 0.3_f64.cos();
            }
            "step" => {
                aug.view_mut((0, n), (n, 1)).copy_from(&b);
                s0[n] = 1.0;
            }
            _ => s0.rows_mut(0, n).copy_from(&b),
        }
        let pad = |c: DVector<f64>| {
            let mut r = DVector::zeros(na);
            r.rows_mut(0, n).copy_from(&c);
            r
        };
        let mut rows = vec![pad(m.row_deflection(1.0)), pad(m.row_deflection(0.4))];
        rows.extend(
            [
                m.row_stroke(false),
                m.row_current(m.dev.kc),
                m.row_voltage(),
            ]
            .into_iter()
            .flatten()
            .map(pad),
        );
        (aug, s0, rows)
    }

    fn compare_time(
        name: &str,
        aug: &DMatrix<f64>,
        s0: &DVector<f64>,
        rows: &[DVector<f64>],
        steps: usize,
        dt: f64,
    ) {
        let st = Stepper {
            a: aug,
            s0,
            rows,
            steps,
            dt,
            last_from: steps / 2,
            decimate: Some(1),
        };
        let budget = Budget::unlimited();
        let got = schur_response::time_response(&st, &budget).expect("Schur stepping");
        let want = st.run(&budget).expect("dense stepping");
        let (gs, ws) = (
            got.series.as_ref().expect("series"),
            want.series.as_ref().expect("series"),
        );
        for j in 0..rows.len() {
            let peak = want.max_abs[j];
            let worst = gs[j]
                .iter()
                .zip(&ws[j])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0_f64, f64::max);
            assert!(
                worst <= TIME_REL * peak,
                "{name}: row {j}: max |Δy| = {worst:.3e} vs peak {peak:.3e} (rel {:.2e})",
                worst / peak
            );
            close_rel(
                &format!("{name} row {j} max"),
                got.max_abs[j],
                peak,
                TIME_REL,
            );
            close(
                &format!("{name} row {j} last"),
                got.max_last[j],
                want.max_last[j],
                TIME_REL * peak,
            );
            close(
                &format!("{name} row {j} rms"),
                got.rms[j],
                want.rms[j],
                TIME_REL * peak,
            );
        }
        assert_eq!(got.t, want.t, "{name}: sample times");
    }

    #[test]
    fn time_response_in_schur_coordinates_matches_dense_stepping() {
        for (name, v) in configs() {
            let (m, _) = model_of(v);
            let scale = (m.omega[1] / (2.0 * PI)).max(1.0);
            for (forcing, f) in [
                ("harmonic", scale),
                ("harmonic", 7.3),
                ("step", 0.0),
                ("impulse", 0.0),
            ] {
                let (aug, s0, rows) = augmented(&m, forcing, f);
                compare_time(
                    &format!("{name} {forcing} {f:.2} Hz"),
                    &aug,
                    &s0,
                    &rows,
                    5000,
                    1e-3,
                );
            }
        }
    }

    /// Undamped bare beam forced at its own second frequency: `A_aug` has `±jω₂` twice with one
    /// eigenvector each (defective; the response grows like `t`). The Schur stepping equals the
    /// dense stepping and the direct exponential `expm(A_aug t) s(0)` at the end.
    #[test]
    fn time_response_is_exact_at_a_defective_resonance() {
        let (m, _) = model_of(json!({"beam": {"n_modes": 3}, "control": {"mode": "none"}}));
        let (aug, s0, rows) = augmented(&m, "harmonic", m.omega[1] / (2.0 * PI));
        let steps = 20_000;
        let dt = 5e-4;
        compare_time("none at f₂ (defective)", &aug, &s0, &rows, steps, dt);
        let st = Stepper {
            a: &aug,
            s0: &s0,
            rows: &rows,
            steps,
            dt,
            last_from: steps,
            decimate: Some(steps),
        };
        let got = schur_response::time_response(&st, &Budget::unlimited()).expect("stepping");
        let end =
            mechcalc::numerics::linalg::expm(&(&aug * (steps as f64 * dt))).expect("finite") * &s0;
        let peak = got.max_abs[0];
        let y_end = rows[0].dot(&end);
        close(
            "tip at the end vs direct expm",
            got.series.expect("series")[0][1],
            y_end,
            1e-10 * peak,
        );
    }

    /// Re-anchored horizon (more than 1e5 steps): Schur stepping and dense stepping agree.
    #[test]
    fn reanchored_time_response_matches_dense_stepping() {
        let (m, _) = model_of(json!({"beam": {"n_modes": 3, "modal_damping_ratio": 0.001},
                                     "absorber": {"passive_tuning_mode": 1},
                                     "control": {"mode": "active", "tuning_mode": 2}}));
        let (aug, s0, rows) = augmented(&m, "harmonic", m.omega[1] / (2.0 * PI));
        compare_time(
            "re-anchored 1.2e5 steps",
            &aug,
            &s0,
            &rows[..1],
            120_000,
            1e-3,
        );
    }

    /// The whole answer through `run`: what the Schur paths return equals the dense paths on the
    /// paper case (FRF magnitudes, time reductions), and the warnings keep their wire form.
    #[test]
    fn paper_case_answer_keeps_its_warnings() {
        let mut v = paper_case();
        v["excitation"] = json!({"type": "harmonic", "resonance_of_mode": 2});
        v["outputs"] = json!({"eigenvalues": true, "ava_step": true,
            "frequency_response": {"f_min_hz": 0.5, "f_max_hz": 100.0, "n_points": 50, "log": true}});
        let a = answer(v);
        let codes: Vec<&str> = a["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .map(|w| w["code"].as_str().expect("code"))
            .collect();
        assert_eq!(codes, ["MARGINAL_STABILITY", "EXCITATION_OFF_TUNING"]);
        let w = &a["warnings"][0];
        assert_eq!(w["pointer"], "/beam/modal_damping_ratio");
        let msg = w["message"].as_str().expect("message");
        assert!(
            msg.starts_with("modal_damping_ratio = 0 with active control: the closed loop is marginal (max Re λ = +3.7"),
            "{msg}"
        );
    }
}
