//! Stress tests near every hazard of spec `bus_fuel_economy.md` §8: random admissible vehicles
//! and motors (500 cases; 10⁴ with `MECHCALC_STRESS_FULL=1`), degenerate maps, stop-only cycles,
//! huge masses, tiny steps, steep grades, weak motors, oversized requests. The result must be a
//! typed failure or finite numbers: never NaN, never a panic.

use mechcalc::calc::ProblemClass;
use mechcalc::calc::bus_fuel_economy::{
    BusFuelEconomyRequest, BusFuelEconomyResponse, MotorMapRequest, run, run_motor_map,
};
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};
use std::time::Duration;

use crate::support::finite::first_null_or_non_finite_where;

/// JSON keys whose value may legitimately be null (undefined FE, map points outside the
/// envelope, the modal bin of a bus that never moves, ipmsm-only breakdown parts).
const NULLABLE: [&str; 9] = [
    "fe_km_per_kwh",
    "efficiency",
    "loss_w",
    "modal_bin",
    "mean_motor_efficiency",
    "motor_cu_dc_kwh",
    "motor_cu_ac_extra_kwh",
    "motor_iron_kwh",
    "motor_mech_kwh",
];

/// Every number in the response is finite (serde_json writes NaN/∞ as null, so nulls are only
/// allowed under the nullable keys, and in fe_change_pct where either FE is undefined).
fn assert_finite(v: &Value) {
    let bad = first_null_or_non_finite_where(v, |key, path| {
        NULLABLE.contains(&key) || path.starts_with("/comparison/fe_change_pct/")
    });
    assert!(bad.is_none(), "null (NaN?) or non-finite at {bad:?}");
}

fn check_response(r: &BusFuelEconomyResponse) {
    let v = serde_json::to_value(r).expect("response serialises");
    assert_finite(&v);
    for x in &r.results {
        assert!(
            x.energy_in_kwh.is_finite() && x.distance_km >= 0.0 && x.friction_brake_kwh >= -1e-12
        );
        if let Some(fe) = x.fe_km_per_kwh {
            assert!(fe.is_finite() && fe >= 0.0, "FE {fe}");
        }
        assert!((0.0..=1.0).contains(&x.frac_over_envelope));
    }
}

/// Run a request: Ok responses must be finite; errors must be typed and carry a code.
/// Returns whether the run succeeded.
fn exercise(v: Value) -> bool {
    exercise_code(v).is_none()
}

/// As [`exercise`], returning the failure code (None on success).
fn exercise_code(v: Value) -> Option<&'static str> {
    let req: BusFuelEconomyRequest = match serde_json::from_value(v) {
        Ok(r) => r,
        Err(e) => panic!("generator produced an undecodable request: {e}"),
    };
    match run(req, &Budget::new(Duration::from_secs(20))) {
        Ok(r) => {
            check_response(&r);
            None
        }
        Err(f) => {
            assert!(!f.code.is_empty());
            if f.class == ProblemClass::InvalidInput {
                assert!(
                    !f.errors.is_empty(),
                    "invalid input without field issues: {f}"
                );
            }
            Some(f.code)
        }
    }
}

fn expect_failure(v: Value, code: &str, pointer_prefix: &str) {
    let req: BusFuelEconomyRequest = serde_json::from_value(v).expect("decodes");
    let f = run(req, &Budget::unlimited()).expect_err("must fail");
    assert_eq!(f.code, code, "{f}");
    assert!(
        f.errors
            .iter()
            .any(|e| e.pointer.starts_with(pointer_prefix)),
        "no issue at {pointer_prefix}: {f}"
    );
}

/// Max trace speed [m/s] of the built-in cycles.
fn builtin_vmax(name: &str) -> f64 {
    match name {
        "manhattan" => 40.716 / 3.6,
        "hwfet" => 96.400 / 3.6,
        _ => 93.342 / 3.6,
    }
}

fn random_cycle(rng: &mut ChaCha8Rng) -> (Value, f64) {
    if rng.random_bool(0.6) {
        let name = ["manhattan", "hwfet", "hdudds"][rng.random_range(0..3)];
        return (json!(name), builtin_vmax(name));
    }
    let n = rng.random_range(2..300usize);
    let mut t = 0.0;
    let mut ts = Vec::with_capacity(n);
    let mut vs = Vec::with_capacity(n);
    let mut gs = Vec::with_capacity(n);
    let vmax_lim = rng.random_range(0.1..60.0);
    for _ in 0..n {
        ts.push(t);
        t += if rng.random_bool(0.1) {
            rng.random_range(1e-3..2e-3)
        } else {
            rng.random_range(0.1..60.0)
        };
        vs.push(if rng.random_bool(0.2) {
            0.0
        } else {
            rng.random_range(0.0..vmax_lim)
        });
        gs.push(rng.random_range(-0.3..0.3));
    }
    if vs.iter().all(|&v| v <= 0.0) {
        vs[n - 1] = 1.0;
    }
    let vmax = vs.iter().copied().fold(0.0, f64::max);
    let mut c = json!({"name": "custom", "time_s": ts, "speed_mps": vs});
    if rng.random_bool(0.5) {
        c["grade"] = json!(gs);
    }
    (c, vmax)
}

fn random_motor(rng: &mut ChaCha8Rng, id: usize, n_need: f64) -> Value {
    let n_max = (n_need * rng.random_range(1.0..3.0)).clamp(1.0, 1e5);
    match rng.random_range(0..4) {
        0 => {
            json!({"id": format!("m{id}"), "model": "constant", "efficiency": rng.random_range(0.01..=1.0),
                    "t_peak_nm": 10f64.powf(rng.random_range(0.0..5.0)), "p_peak_w": 10f64.powf(rng.random_range(2.0..7.0)),
                    "n_max_rpm": n_max})
        }
        1 => {
            let ns = rng.random_range(2..8usize);
            let nt = rng.random_range(2..8usize);
            let speeds: Vec<f64> = (0..ns)
                .map(|i| i as f64 * n_max / (ns - 1) as f64)
                .collect();
            let t0 = if rng.random_bool(0.5) { 0.0 } else { 1.0 };
            let step = rng.random_range(1.0..500.0);
            let torques: Vec<f64> = (0..nt).map(|j| (j as f64).mul_add(step, t0)).collect();
            let eff: Vec<Vec<f64>> = (0..ns)
                .map(|_| (0..nt).map(|_| rng.random_range(1e-3..=1.0)).collect())
                .collect();
            json!({"id": format!("m{id}"), "model": "efficiency_map", "speed_rpm": speeds, "torque_nm": torques,
                   "efficiency": eff, "n_max_rpm": n_max})
        }
        2 => {
            let ns = rng.random_range(2..8usize);
            let speeds: Vec<f64> = (0..ns)
                .map(|i| i as f64 * n_max / (ns - 1) as f64)
                .collect();
            let k = rng.random_range(1..5usize);
            let step = rng.random_range(1.0..500.0);
            let torques: Vec<f64> = (0..2 * k + 1)
                .map(|j| (j as f64 - k as f64) * step)
                .collect();
            let loss: Vec<Vec<f64>> = (0..ns)
                .map(|_| {
                    (0..2 * k + 1)
                        .map(|_| {
                            if rng.random_bool(0.2) {
                                0.0
                            } else {
                                rng.random_range(0.0..1e5)
                            }
                        })
                        .collect()
                })
                .collect();
            json!({"id": format!("m{id}"), "model": "loss_map", "speed_rpm": speeds, "torque_nm": torques, "loss_w": loss,
                   "t_peak_nm": rng.random_range(1.0..2000.0), "n_max_rpm": n_max})
        }
        _ => {
            let ld = 10f64.powf(rng.random_range(-6.0..-1.0));
            let mut m = json!({"id": format!("m{id}"), "model": "ipmsm", "pole_pairs": rng.random_range(1..=32u32),
                "psi_m_wb": 10f64.powf(rng.random_range(-3.0..0.5)), "ld_h": ld, "lq_h": ld * rng.random_range(1.0..4.0),
                "r_phase_20c_ohm": 10f64.powf(rng.random_range(-4.0..1.0)), "winding_temp_c": rng.random_range(-40.0..=250.0),
                "i_max_arms": 10f64.powf(rng.random_range(0.0..4.0)), "v_dc": 10f64.powf(rng.random_range(1.0..4.0)),
                "voltage_utilization": rng.random_range(0.5..=1.155), "n_max_rpm": n_max,
                "iron": {"k_h": rng.random_range(0.0..10.0), "k_e": rng.random_range(0.0..0.1)},
                "mech": {"c_fric_nm": rng.random_range(0.0..2.0), "c_wind": rng.random_range(0.0..1e-6)}});
            if rng.random_bool(0.5) {
                m["t_cap_nm"] = json!(10f64.powf(rng.random_range(1.0..4.0)));
                m["p_cap_w"] = json!(10f64.powf(rng.random_range(3.0..6.0)));
            }
            m["ac_factor"] = match rng.random_range(0..3) {
                0 => json!({"model": "none"}),
                1 => {
                    json!({"model": "table", "freq_hz": [0.0, 100.0, 1000.0], "k_ac": [1.0, 1.2, rng.random_range(1.2..5.0)]})
                }
                _ => {
                    json!({"model": "dowell", "conductor_height_m": rng.random_range(1e-4..0.02), "layers": rng.random_range(1..=100u32),
                            "porosity": rng.random_range(0.1..=1.0), "stack_length_m": rng.random_range(0.01..1.0),
                            "end_length_m": rng.random_range(0.0..0.5)})
                }
            };
            m
        }
    }
}

fn random_request(rng: &mut ChaCha8Rng) -> Value {
    let r = rng.random_range(0.11..=2.0);
    let ig = rng.random_range(0.5..=50.0);
    let n_cycles = rng.random_range(1..=3usize);
    let mut cycles = Vec::new();
    let mut vmax: f64 = 0.0;
    for k in 0..n_cycles {
        let (mut c, v) = random_cycle(rng);
        if c.is_object() {
            c["name"] = json!(format!("custom{k}"));
        } else if cycles.contains(&c) {
            continue;
        }
        vmax = vmax.max(v);
        cycles.push(c);
    }
    let n_need = vmax * ig / r * 30.0 / std::f64::consts::PI;
    let n_motors = rng.random_range(1..=3usize);
    let motors: Vec<Value> = (0..n_motors)
        .map(|i| random_motor(rng, i, n_need))
        .collect();
    let battery = if rng.random_bool(0.2) {
        json!({"model": "ecm_2rc", "ocv_soc": [0.0, 0.5, 1.0], "ocv_v": [300.0, 350.0, 400.0],
               "r0_ohm": rng.random_range(1e-4..1.0), "r1_ohm": rng.random_range(0.0..0.1), "c1_f": rng.random_range(1.0..1e5),
               "r2_ohm": rng.random_range(0.0..0.1), "c2_f": rng.random_range(1.0..1e5), "soc_initial": rng.random_range(0.01..=1.0),
               "capacity_kwh": rng.random_range(0.01..500.0)})
    } else {
        json!({"efficiency": rng.random_range(0.01..=1.0)})
    };
    let mode = ["backward", "clip", "forward"][rng.random_range(0..3)];
    let mut outputs = vec![];
    for (p, name) in [
        (0.3, "loss_breakdown"),
        (0.2, "op_histogram"),
        (0.05, "traces"),
        (0.05, "efficiency_map"),
    ] {
        if rng.random_bool(p) {
            outputs.push(name);
        }
    }
    json!({
        "vehicle": {"curb_mass_kg": 10f64.powf(rng.random_range(2.0..5.0)), "passengers": rng.random_range(0..=500u32),
                    "mass_per_passenger_kg": rng.random_range(0.0..=200.0), "frontal_area_m2": rng.random_range(0.1..=30.0),
                    "drag_coeff": rng.random_range(0.01..=3.0), "rolling_coeff": rng.random_range(0.0..=0.1),
                    "air_density": rng.random_range(0.1..=2.0), "gravity": rng.random_range(9.01..=10.5),
                    "wheel_radius_m": r, "gear_ratio": ig, "gear_efficiency": rng.random_range(0.05..=1.0),
                    "rotational_inertia_factor": rng.random_range(0.0..=1.0), "grade": rng.random_range(-0.3..=0.3),
                    "aux_power_w": rng.random_range(0.0..=1e5)},
        "inverter": {"efficiency": rng.random_range(0.05..=1.0)},
        "battery": battery,
        "cycles": cycles,
        "motors": motors,
        "options": {"mode": mode, "power_convention": if rng.random_bool(0.5) { "paper" } else { "loss" },
                    "substeps": rng.random_range(1..=4u32), "regen": rng.random_bool(0.8), "regen_limit": rng.random_bool(0.8),
                    "motor_eval": if rng.random_bool(0.5) { "direct" } else { "loss_map" },
                    "loss_map_grid": {"speed_step_rpm": rng.random_range(50.0..1000.0), "torque_step_nm": rng.random_range(5.0..200.0)},
                    "outputs": outputs}
    })
}

/// 500 random admissible requests (10⁴ with MECHCALC_STRESS_FULL=1): never a panic or NaN.
#[test]
fn random_admissible_requests() {
    let full = std::env::var("MECHCALC_STRESS_FULL").is_ok_and(|v| v == "1");
    let n = if full { 10_000 } else { 500 };
    let mut rng = ChaCha8Rng::seed_from_u64(0x00b5_fe01);
    let mut ok = 0usize;
    let mut codes = std::collections::BTreeMap::new();
    for _ in 0..n {
        match exercise_code(random_request(&mut rng)) {
            None => ok += 1,
            Some(code) => *codes.entry(code).or_insert(0usize) += 1,
        }
    }
    eprintln!("{ok} of {n} random requests ran; typed failures: {codes:?}");
    // The generator aims at runnable requests; most must actually run (not a vacuous test).
    assert!(ok * 3 >= n, "only {ok} of {n} random requests ran");
}

fn demo_ipmsm() -> Value {
    json!({"id": "demo", "model": "ipmsm", "pole_pairs": 4, "back_emf": {"v_peak_phase": 83.3, "at_rpm": 1000},
           "ld_h": 0.00035, "lq_h": 0.00055, "r_phase_20c_ohm": 0.006, "i_max_arms": 500, "v_dc": 360,
           "n_max_rpm": 5200, "t_cap_nm": 800, "p_cap_w": 130000,
           "ac_factor": {"model": "dowell", "conductor_height_m": 0.0035, "layers": 6, "porosity": 0.9,
                         "stack_length_m": 0.083, "end_length_m": 0.05},
           "iron": {"k_h": 3.0, "k_e": 0.03}})
}

#[test]
fn stop_only_cycle_is_rejected() {
    let c = json!({"name": "stops", "time_s": [0, 1, 2, 3], "speed_kmh": [0, 0, 0, 0]});
    expect_failure(
        json!({"cycles": [c], "motors": [demo_ipmsm()]}),
        "ZERO_DISTANCE",
        "/cycles/0",
    );
}

#[test]
fn huge_mass_and_extremes_stay_finite() {
    for mode in ["backward", "clip", "forward"] {
        for eval in ["direct", "loss_map"] {
            assert!(exercise(json!({
                "vehicle": {"curb_mass_kg": 1e5, "passengers": 500, "mass_per_passenger_kg": 200, "grade": 0.3,
                            "rotational_inertia_factor": 1.0, "aux_power_w": 1e5},
                "cycles": ["manhattan", "hwfet", "hdudds"], "motors": [demo_ipmsm()],
                "options": {"mode": mode, "motor_eval": eval, "outputs": ["loss_breakdown", "op_histogram"]}
            })));
        }
    }
}

#[test]
fn downhill_gives_null_fe_not_infinity() {
    let resp = {
        let req: BusFuelEconomyRequest = serde_json::from_value(json!({
            "vehicle": {"grade": -0.3}, "cycles": ["hwfet"],
            "motors": [{"id": "c", "model": "constant", "efficiency": 0.95, "t_peak_nm": 5000, "p_peak_w": 1e7}],
            "options": {"regen_limit": false}
        }))
        .expect("decodes");
        run(req, &Budget::unlimited()).expect("runs")
    };
    let r = &resp.results[0];
    assert!(r.energy_in_kwh < 0.0);
    assert!(r.fe_km_per_kwh.is_none());
    assert!(r.warnings.iter().any(|w| w.contains("undefined")));
    check_response(&resp);
}

#[test]
fn forward_mode_stuck_on_steep_grade() {
    let weak = json!({"id": "weak", "model": "constant", "efficiency": 0.9, "t_peak_nm": 1.0, "p_peak_w": 100});
    let req: BusFuelEconomyRequest = serde_json::from_value(json!({
        "vehicle": {"grade": 0.3}, "cycles": ["manhattan"], "motors": [weak], "options": {"mode": "forward"}
    }))
    .expect("decodes");
    let resp = run(req, &Budget::unlimited()).expect("runs");
    check_response(&resp);
    let r = &resp.results[0];
    assert!(
        r.distance_km < 0.01,
        "a 1 N·m motor cannot climb 30 %: {}",
        r.distance_km
    );
    assert!(r.trace_miss_km.expect("forward") > 3.0);
}

#[test]
fn tiny_steps_and_jumps_stay_finite() {
    let c = json!({"name": "jumpy", "time_s": [0.0, 1e-3, 2e-3, 10.0, 10.001, 20.0],
                   "speed_mps": [0.0, 20.0, 0.0, 20.0, 0.0, 0.0]});
    for mode in ["backward", "clip", "forward"] {
        assert!(exercise(
            json!({"cycles": [c.clone()], "motors": [demo_ipmsm()], "options": {"mode": mode}})
        ));
    }
    // The corner of every service limit at once: 200 m/s jumps over 1 ms, 2·10⁵ kg, the
    // smallest gear ratio and efficiencies, the largest wheel: still finite numbers.
    let c = json!({"name": "corner", "time_s": [0.0, 1e-3, 2e-3, 3e-3],
                   "speed_mps": [0.0, 200.0, 200.0, 0.0], "grade": [0.3, -0.3, 0.3, -0.3]});
    for mode in ["backward", "clip", "forward"] {
        for battery in [
            json!({"efficiency": 0.01}),
            json!({"model": "ecm_2rc", "ocv_soc": [0.0, 1.0], "ocv_v": [1.0, 2.0], "r0_ohm": 100.0,
                   "r1_ohm": 100.0, "c1_f": 1e-9, "r2_ohm": 0.0, "c2_f": 1e9, "soc_initial": 1.0,
                   "capacity_kwh": 1e-3, "nominal_voltage": 5000.0}),
        ] {
            let motors = json!([
                {"id": "c", "model": "constant", "efficiency": 0.01, "t_peak_nm": 1e6, "p_peak_w": 1e9, "n_max_rpm": 1e5},
                {"id": "e", "model": "efficiency_map", "speed_rpm": [0.0, 1e5], "torque_nm": [0.0, 1e6],
                 "efficiency": [[1e-6, 1e-6], [1e-6, 1e-6]], "n_max_rpm": 1e5}
            ]);
            assert!(exercise(json!({
                "vehicle": {"curb_mass_kg": 1e5, "passengers": 500, "mass_per_passenger_kg": 200,
                            "rotational_inertia_factor": 1.0, "wheel_radius_m": 2.0, "gear_ratio": 0.01,
                            "gear_efficiency": 0.01, "aux_power_w": 1e5},
                "inverter": {"efficiency": 0.01}, "battery": battery, "cycles": [c.clone()], "motors": motors,
                "options": {"mode": mode, "power_convention": "loss", "substeps": 32, "regen_limit": false,
                            "outputs": ["loss_breakdown", "traces"]}
            })));
        }
    }
    // Below the service limits: typed rejections, never overflow.
    let c = json!({"name": "c", "time_s": [0.0, 1e-300], "speed_mps": [0.0, 1.0]});
    expect_failure(
        json!({"cycles": [c], "motors": [demo_ipmsm()]}),
        "TIME_STEP",
        "/cycles/0/time_s/1",
    );
    expect_failure(
        json!({"vehicle": {"gear_ratio": 1e-300}, "cycles": ["manhattan"], "motors": [demo_ipmsm()]}),
        "INVALID_INPUT",
        "/vehicle/gear_ratio",
    );
}

#[test]
fn degenerate_maps() {
    let speeds = json!([0.0, 5200.0]);
    // All-zero loss map, torque axis far narrower than the envelope (warns, never extrapolates).
    let zero = json!({"id": "zero", "model": "loss_map", "speed_rpm": speeds, "torque_nm": [-1.0, 0.0, 1.0],
                      "loss_w": [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]});
    // Efficiency map with one positive torque column (constant T = 0 extrapolation), η = 1 and tiny η.
    let one_col = json!({"id": "onecol", "model": "efficiency_map", "speed_rpm": [0.0, 5200.0], "torque_nm": [0.0, 800.0],
                         "efficiency": [[0.5, 1.0], [0.5, 1e-6]]});
    let req: BusFuelEconomyRequest = serde_json::from_value(json!({
        "cycles": ["manhattan", "hwfet"], "motors": [zero, one_col],
        "options": {"outputs": ["loss_breakdown", "efficiency_map", "op_histogram"]}
    }))
    .expect("decodes");
    let resp = run(req, &Budget::unlimited()).expect("runs");
    check_response(&resp);
    assert!(
        resp.results[0]
            .warnings
            .iter()
            .any(|w| w.contains("exceeds the map torque axis"))
    );
    assert!(
        resp.results[2]
            .warnings
            .iter()
            .any(|w| w.contains("converted to a loss map"))
    );
    // Invalid maps: efficiency 0, negative loss, non-increasing axis, no zero column, bad shape.
    let bad = [
        (
            json!({"id": "a", "model": "efficiency_map", "speed_rpm": [0, 5200], "torque_nm": [0, 800], "efficiency": [[0.0, 0.9], [0.9, 0.9]]}),
            "/motors/0/efficiency/0/0",
        ),
        (
            json!({"id": "a", "model": "loss_map", "speed_rpm": [0, 5200], "torque_nm": [-1, 0, 1], "loss_w": [[0, -1, 0], [0, 0, 0]]}),
            "/motors/0/loss_w/0/1",
        ),
        (
            json!({"id": "a", "model": "loss_map", "speed_rpm": [0, 0], "torque_nm": [-1, 0, 1], "loss_w": [[0, 0, 0], [0, 0, 0]]}),
            "/motors/0/speed_rpm/1",
        ),
        (
            json!({"id": "a", "model": "loss_map", "speed_rpm": [0, 5200], "torque_nm": [1, 2], "loss_w": [[0, 0], [0, 0]]}),
            "/motors/0/torque_nm",
        ),
        (
            json!({"id": "a", "model": "loss_map", "speed_rpm": [0, 5200], "torque_nm": [-1, 0, 1], "loss_w": [[0, 0], [0, 0, 0]]}),
            "/motors/0/loss_w/0",
        ),
        (
            json!({"id": "a", "model": "loss_map", "speed_rpm": [0, 3000], "torque_nm": [-1, 0, 1], "loss_w": [[0, 0, 0], [0, 0, 0]]}),
            "/motors/0/n_max_rpm",
        ),
    ];
    // Values out of range are refused at the door; the rest are rules between fields.
    let codes = [
        "INVALID_INPUT",
        "INVALID_INPUT",
        "AXIS_ORDER",
        "LOSS_AXIS_ZERO",
        "LENGTH_MISMATCH",
        "CYCLE_ABOVE_MOTOR_SPEED",
    ];
    for ((m, ptr), code) in bad.into_iter().zip(codes) {
        expect_failure(json!({"cycles": ["hwfet"], "motors": [m]}), code, ptr);
    }
}

#[test]
fn every_invalid_field_is_reported() {
    // Per-field rules (the door): every offending field in one failure.
    let req: BusFuelEconomyRequest = serde_json::from_value(json!({
        "vehicle": {"curb_mass_kg": -1, "gear_efficiency": 0, "grade": 0.5},
        "inverter": {"efficiency": 1.5},
        "cycles": ["hwfet"],
        "motors": [{"id": "x", "model": "ipmsm", "pole_pairs": 0, "psi_m_wb": 0.2, "ld_h": 0.001, "lq_h": 0.0015,
                    "r_phase_20c_ohm": 0.01, "i_max_arms": 100, "v_dc": 400, "n_max_rpm": 6000}],
        "options": {"substeps": 33}
    }))
    .expect("decodes");
    let f = run(req, &Budget::unlimited()).expect_err("invalid");
    assert_eq!(f.code, "INVALID_INPUT", "{f}");
    let ptrs: Vec<&str> = f.errors.iter().map(|e| e.pointer.as_str()).collect();
    for p in [
        "/vehicle/curb_mass_kg",
        "/vehicle/gear_efficiency",
        "/vehicle/grade",
        "/inverter/efficiency",
        "/motors/0/pole_pairs",
        "/options/substeps",
    ] {
        assert!(ptrs.contains(&p), "missing {p} in {ptrs:?}");
    }
    // Rules between fields (after the door): every offending field in one failure.
    let req: BusFuelEconomyRequest = serde_json::from_value(json!({
        "cycles": ["nowhere", {"name": "c", "time_s": [0, 2, 1], "speed_kmh": [0, 10, 0]}],
        "motors": [{"id": "x", "model": "ipmsm", "pole_pairs": 4, "psi_m_wb": 0.2, "ld_h": 0.001, "lq_h": 0.0005,
                    "r_phase_20c_ohm": 0.01, "i_max_arms": 100, "v_dc": 400, "n_max_rpm": 6000}]
    }))
    .expect("decodes");
    let f = run(req, &Budget::unlimited()).expect_err("invalid");
    let ptrs: Vec<&str> = f.errors.iter().map(|e| e.pointer.as_str()).collect();
    for p in ["/cycles/0", "/cycles/1/time_s/2", "/motors/0/lq_h"] {
        assert!(ptrs.contains(&p), "missing {p} in {ptrs:?}");
    }
}

#[test]
fn unreachable_ipmsm_speed_is_a_typed_error() {
    // ψ_m/L_d far below I_pk: the voltage limit leaves no torque at HWFET speeds.
    let m = json!({"id": "fw", "model": "ipmsm", "pole_pairs": 4, "psi_m_wb": 0.6, "ld_h": 0.00035, "lq_h": 0.00055,
                   "r_phase_20c_ohm": 0.006, "i_max_arms": 100, "v_dc": 360, "n_max_rpm": 6000});
    expect_failure(
        json!({"cycles": ["hwfet"], "motors": [m]}),
        "MOTOR_SPEED_UNREACHABLE",
        "/motors/0/n_max_rpm",
    );
}

#[test]
fn oversized_requests_are_typed() {
    let n = 200_000usize;
    let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
    let v: Vec<f64> = (0..n)
        .map(|k| if k % 100 < 50 { 5.0 } else { 0.0 })
        .collect();
    let c = json!({"name": "long", "time_s": t, "speed_mps": v});
    let motor = json!({"id": "c", "model": "constant", "efficiency": 0.9});
    expect_failure(
        json!({"cycles": [c], "motors": [motor.clone()], "options": {"substeps": 8}}),
        "TOO_MANY_SAMPLES",
        "/options/substeps",
    );
    expect_failure(
        json!({"cycles": ["manhattan"], "motors": [demo_ipmsm()], "options": {"loss_map_grid": {"speed_step_rpm": 1, "torque_step_nm": 0.1}}}),
        "MAP_TOO_LARGE",
        "/options/loss_map_grid",
    );
    expect_failure(
        json!({"cycles": ["manhattan"], "motors": [motor], "options": {"outputs": ["op_histogram"], "op_histogram": {"speed_bin_rpm": 1, "torque_bin_nm": 0.1}}}),
        "HISTOGRAM_TOO_LARGE",
        "/options/op_histogram",
    );
    let nine: Vec<Value> = (0..9)
        .map(|i| json!({"id": format!("m{i}"), "model": "constant", "efficiency": 0.9}))
        .collect();
    expect_failure(
        json!({"cycles": ["manhattan"], "motors": nine}),
        "INVALID_INPUT",
        "/motors",
    );
}

#[test]
fn deadline_is_a_typed_error() {
    let req: BusFuelEconomyRequest = serde_json::from_value(json!({
        "cycles": ["manhattan", "hwfet", "hdudds"], "motors": [demo_ipmsm()],
        "options": {"motor_eval": "direct", "substeps": 32}
    }))
    .expect("decodes");
    let f = run(req, &Budget::new(Duration::ZERO)).expect_err("no time");
    assert_eq!(f.code, "DEADLINE_EXCEEDED");
}

#[test]
fn ecm_battery_hazards_are_flagged() {
    let bat = json!({"model": "ecm_2rc", "ocv_soc": [0.0, 1.0], "ocv_v": [330.0, 390.0], "r0_ohm": 2.0,
                     "r1_ohm": 0.0, "c1_f": 1e-9, "r2_ohm": 0.01, "c2_f": 30000.0, "soc_initial": 0.05, "capacity_kwh": 0.5});
    let req: BusFuelEconomyRequest = serde_json::from_value(json!({
        "battery": bat, "cycles": ["hdudds"], "motors": [{"id": "c", "model": "constant", "efficiency": 0.93}]
    }))
    .expect("decodes");
    let resp = run(req, &Budget::unlimited()).expect("runs");
    check_response(&resp);
    let flags = resp.results[0].battery_flags.clone().expect("ecm flags");
    assert!(flags.contains(&"battery_power_infeasible".to_owned()));
    assert!(flags.contains(&"soc_out_of_range".to_owned()));
}

#[test]
fn motor_map_endpoint_stays_finite() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for i in 0..100 {
        let need = rng.random_range(100.0..6000.0);
        let m = random_motor(&mut rng, i, need);
        let req: MotorMapRequest = serde_json::from_value(
            json!({"motor": m, "grid": {"speed_step_rpm": 500, "torque_step_nm": 50},
                                                                  "include_components": true}),
        )
        .expect("decodes");
        match run_motor_map(req, &Budget::new(Duration::from_secs(20))) {
            Ok(r) => {
                // Every number of the typed answer is finite (components and maps are absent
                // outside the envelope only, checked below).
                crate::support::finite::assert_finite(&r);
                for (row, tm) in r.loss_w.iter().zip(&r.t_max_nm) {
                    for (x, t) in row.iter().zip(&r.torque_nm) {
                        assert_eq!(x.is_some(), t.abs() <= tm + 1e-9);
                    }
                }
            }
            Err(f) => assert!(!f.code.is_empty()),
        }
    }
}
