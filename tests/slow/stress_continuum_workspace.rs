//! Inputs near every hazard of spec 7: stroke limits, taut rods, straight over-constrained rods,
//! loads near buckling and at the load limit, grids at the size limit, tiny budgets, degenerate
//! designs, non-finite numbers, extreme scales. The result must be a typed error or finite numbers:
//! never NaN (which serde would silently turn into null), never a panic.

// Test arithmetic stays in textbook form.
#![allow(clippy::suboptimal_flops)]

use std::time::Duration;

use mechcalc::calc::continuum_workspace::wire::ContinuumWorkspaceRequest;
use mechcalc::calc::continuum_workspace::{run, time_limit};
use mechcalc::calc::{CalcFailure, ProblemClass};
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

/// Keys whose value may legitimately be null: none (absent optionals are omitted, never null).
const NULLABLE: &[&str] = &[];
/// Node arrays: null exactly where the node is not accepted.
const NODE_ARRAYS: &[&str] = &[
    "px_m",
    "py_m",
    "parasitic_angle_deg",
    "max_stress_pa",
    "actuator_forces_n",
];

fn check_no_hidden_nan(v: &Value, key: &str, path: &str) {
    match v {
        Value::Null => assert!(
            NULLABLE.contains(&key),
            "null (NaN or missing value) at {path}"
        ),
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                check_no_hidden_nan(x, key, &format!("{path}/{i}"));
            }
        }
        Value::Object(o) => {
            for (k, x) in o {
                if k == "nodes" && x.is_object() {
                    // Node arrays hold null exactly where the node is not accepted.
                    check_nodes(x, path);
                } else {
                    check_no_hidden_nan(x, k, &format!("{path}/{k}"));
                }
            }
        }
        _ => {}
    }
}

fn check_nodes(nodes: &Value, path: &str) {
    let status = nodes["status"].as_array().expect("status array");
    for (i, (x, s)) in nodes["px_m"]
        .as_array()
        .expect("px")
        .iter()
        .zip(status)
        .enumerate()
    {
        if s == "ok" {
            assert!(x.is_number(), "{path}/nodes/px_m/{i}");
        }
    }
    for key in NODE_ARRAYS {
        let arr = nodes[*key].as_array().expect("node array");
        assert_eq!(arr.len(), status.len(), "{path}/nodes/{key} length");
        for (i, (x, s)) in arr.iter().zip(status).enumerate() {
            let ok = s == "ok";
            if *key == "max_stress_pa" && ok {
                continue; // None only without diameters; checked by type elsewhere
            }
            assert_eq!(
                !x.is_null(),
                ok,
                "{path}/nodes/{key}/{i} (status {s}) null-ness"
            );
        }
    }
}

fn call(req: Value) -> Result<Value, CalcFailure> {
    call_with(req, &Budget::new(Duration::from_secs(60)))
}

fn call_with(req: Value, budget: &Budget) -> Result<Value, CalcFailure> {
    let req: ContinuumWorkspaceRequest = serde_json::from_value(req).expect("request parses");
    let out = run(req, budget)?;
    let v = serde_json::to_value(out).expect("serialises");
    check_no_hidden_nan(&v, "", "");
    Ok(v)
}

fn expect_invalid(req: Value, pointer: &str) -> CalcFailure {
    let e = call(req).expect_err("must fail validation");
    assert!(
        e.errors.iter().any(|f| f.pointer == pointer),
        "expected an issue at {pointer}, got {:?}",
        e.errors
            .iter()
            .map(|f| (&f.pointer, &f.detail))
            .collect::<Vec<_>>()
    );
    e
}

fn d1() -> Value {
    json!({"actuators": [{"origin_m": [0,0], "direction": [1,0], "stroke_m": [-0.7, 0.2]},
                         {"origin_m": [0,0], "direction": [1,0], "stroke_m": [-0.1775, 0.7225]}],
           "rods": [{"actuator": 0, "offset_m": [-0.0225,0], "clamp_angle_deg": -60, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [-0.0225,0]},
                    {"actuator": 0, "offset_m": [0.0225,0],  "clamp_angle_deg": -60, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [0.0225,0]},
                    {"actuator": 1, "offset_m": [0,0],       "clamp_angle_deg": -120, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [0.0225,0]}]})
}

#[test]
fn inputs_at_the_stroke_limits() {
    for l in [
        [-0.7, -0.1775],
        [-0.7, 0.7225],
        [0.2, -0.1775],
        [0.2, 0.7225],
        [-0.7, 0.2725],
        [0.2, 0.2725],
    ] {
        let r = call(json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": l}))
            .expect("typed response");
        let st = r["status"].as_str().expect("status");
        assert!(
            ["ok", "no_convergence", "singular"].contains(&st),
            "{l:?}: {st}"
        );
        if st == "no_convergence" {
            assert!(r.get("platform").is_none(), "no pose without convergence");
        }
    }
    let e = expect_invalid(
        json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [0.2000001, 0.3]}),
        "/inputs_m/0",
    );
    assert_eq!(e.class, ProblemClass::InvalidInput);
}

#[test]
fn unreachable_inputs_report_no_convergence_with_a_reason() {
    // Carriages far apart: the branch from home ends at a fold before the rods could reach.
    let mut design = d1();
    design["actuators"][0]["stroke_m"] = json!([-3.0, 0.2]);
    design["actuators"][1]["stroke_m"] = json!([-0.2, 3.0]);
    let r = call(json!({"mode": "fk", "design": design, "inputs_m": [-1.5, 1.5]}))
        .expect("typed response");
    assert_eq!(r["status"], "no_convergence");
    assert!(
        r.get("platform").is_none() && r.get("solver_state").is_none(),
        "no pose without convergence"
    );
    let warnings = r["diagnostics"]["warnings"].as_array().expect("warnings");
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .is_some_and(|s| s.starts_with("continuation_stalled") || s.starts_with("taut_rod"))),
        "{warnings:?}"
    );
}

#[test]
fn straight_over_constrained_rods_are_singular_without_forces() {
    // Pure translation of the symmetric design: all rods straight, forces indeterminate.
    let r = call(
        json!({"mode": "fk", "design": {"preset": "symmetric"}, "inputs_m": [-0.2, 0.3],
                        "load": {"force_n": [0.0, -50.0]}}),
    )
    .expect("typed response");
    assert_eq!(r["status"], "singular");
    assert!(
        r["rods"][0].get("tip_force_n").is_none(),
        "no arbitrary forces"
    );
    assert!(r.get("actuator_forces_n").is_none());
    assert!(
        r["diagnostics"]["jacobian_condition"]
            .as_f64()
            .expect("cond")
            > 1e12
    );
    // Extensible rods make the forces physical.
    let r = call(json!({"mode": "fk", "design": {"preset": "symmetric"}, "inputs_m": [-0.2, 0.3],
                        "load": {"force_n": [0.0, -50.0]}, "solver": {"axial_extensibility": true}}))
    .expect("typed response");
    assert_eq!(r["status"], "ok");
    let fy: f64 = (0..4)
        .map(|i| r["rods"][i]["tip_force_n"][1].as_f64().expect("force"))
        .sum();
    assert!((fy + 50.0).abs() < 1e-6, "sum n_y = {fy}");
    // Nearly straight: a 1e-9 m departure from the translation path.
    for d in [1e-9, 1e-6, 1e-4] {
        let r = call(
            json!({"mode": "fk", "design": {"preset": "symmetric"}, "inputs_m": [-0.2, 0.3 + d]}),
        )
        .expect("typed response");
        assert!(
            ["ok", "singular"].contains(&r["status"].as_str().expect("status")),
            "d = {d}"
        );
    }
}

#[test]
fn loads_up_to_buckling_and_the_load_limit() {
    // F_ref = EI/L^2 = 10.56 N; the limit is 1e4 F_ref.
    for f in [1.0, 30.0, 100.0, 300.0, 1e3, 1e4, 1.05e5] {
        for dir in [[0.0, -1.0], [0.0, 1.0], [1.0, 0.0], [-0.6, 0.8]] {
            let force = [f * dir[0], f * dir[1]];
            let r = call(
                json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.25, 0.2725],
                                "load": {"force_n": force}, "solver": {"max_iter": 20}}),
            )
            .expect("typed response");
            let st = r["status"].as_str().expect("status");
            assert!(
                ["ok", "no_convergence", "singular"].contains(&st),
                "F {force:?}: {st}"
            );
        }
    }
    expect_invalid(
        json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.25, 0.2725], "load": {"force_n": [0.0, -1.1e5]}}),
        "/load/force_n",
    );
}

#[test]
fn compressed_straight_rods_turn_unstable_at_the_euler_load() {
    // Two rods clamped pointing straight down, pinned to the platform, pushed up: straight under
    // compression. The platform sways freely and the pins carry no moment, so each rod is a
    // clamped-free column: critical total load 2 * pi^2 EI / (4 L^2), margin (1 - f) pi^2/4.
    let design = json!({"actuators": [{"origin_m": [0,0], "direction": [1,0], "stroke_m": [-1, 1]}],
        "rods": [{"actuator": 0, "offset_m": [-0.05,0], "clamp_angle_deg": -90, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [-0.05,0]},
                 {"actuator": 0, "offset_m": [0.05,0],  "clamp_angle_deg": -90, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [0.05,0]}]});
    let ei = 2.1e11 * std::f64::consts::PI * 0.004f64.powi(4) / 64.0;
    let pcr = 2.0 * std::f64::consts::PI.powi(2) * ei / (4.0 * 0.25);
    for frac in [0.5, 0.9, 0.999, 1.001, 1.1, 2.0] {
        let r = call(json!({"mode": "fk", "design": design.clone(), "inputs_m": [0.0],
                            "load": {"force_n": [0.0, frac * pcr]}, "solver": {"axial_extensibility": true},
                            "outputs": {"stability_segments": 80}}))
        .expect("typed response");
        assert_eq!(r["status"], "ok", "f = {frac}");
        let margin = r["stability"]["margin"].as_f64().expect("margin");
        let want = (1.0 - frac) * std::f64::consts::PI.powi(2) / 4.0;
        assert!(
            (margin - want).abs() < 0.005 * std::f64::consts::PI.powi(2) / 4.0,
            "f = {frac}: margin {margin} vs {want}"
        );
        assert_eq!(r["stability"]["stable"], frac < 1.0, "f = {frac}");
    }
}

#[test]
fn grids_at_the_size_limit_and_beyond() {
    // 201 x 201 = 40 401 nodes is allowed; with a 200 ms budget it returns a partial sweep.
    let t0 = std::time::Instant::now();
    let r = call(json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "time_limit_ms": 200,
                        "workspace": {"grid": [201, 201], "stability_check": "none", "return_nodes": true}}))
    .expect("typed response");
    assert!(
        t0.elapsed() < Duration::from_secs(20),
        "budget honoured ({:?})",
        t0.elapsed()
    );
    assert_eq!(r["report"]["stop_reason"], "deadline");
    assert_eq!(r["nodes"]["status"].as_array().map(Vec::len), Some(40_401));
    let e = call(json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "workspace": {"grid": [202, 201]}}))
        .expect_err("too large");
    assert_eq!(e.class, ProblemClass::TooLarge);
    assert_eq!(e.code, "GRID_TOO_LARGE");
    assert_eq!(e.errors[0].pointer, "/workspace/grid");
    expect_invalid(
        json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "workspace": {"grid": [402, 2]}}),
        "/workspace/grid/0",
    );
    expect_invalid(
        json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "workspace": {"grid": [1, 31]}}),
        "/workspace/grid/0",
    );
}

#[test]
fn tiny_budgets_return_typed_partial_results() {
    let budget = Budget::new(Duration::from_micros(1));
    std::thread::sleep(Duration::from_millis(2));
    let fk = call_with(
        json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.1, 0.2]}),
        &budget,
    )
    .expect("typed response");
    assert_eq!(fk["status"], "no_convergence");
    assert_eq!(fk["report"]["stop_reason"], "deadline");
    let ws = call_with(
        json!({"mode": "workspace", "design": {"preset": "keops_d1"}}),
        &budget,
    )
    .expect("typed response");
    assert_eq!(ws["report"]["stop_reason"], "deadline");
    let am = call_with(json!({"mode": "assembly_modes", "design": {"preset": "keops_d1"}, "inputs_m": [-0.22, 0.2425]}), &budget)
        .expect("typed response");
    assert_eq!(am["report"]["stop_reason"], "deadline");
    assert_eq!(am["complete"], false);
    // Evaluation caps behave like deadlines.
    let capped = Budget::unlimited().with_max_evaluations(5);
    let ws = call_with(json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "workspace": {"grid": [11, 11]}}), &capped)
        .expect("typed response");
    assert_ne!(ws["report"]["stop_reason"], "completed");
    // The request's own limit.
    let req: ContinuumWorkspaceRequest =
        serde_json::from_value(json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [0, 0.3], "time_limit_ms": 1}))
            .expect("parses");
    assert_eq!(time_limit(&req), Some(Duration::from_millis(1)));
    expect_invalid(
        json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [0, 0.3], "time_limit_ms": 0}),
        "/time_limit_ms",
    );
}

#[test]
fn degenerate_designs_are_rejected_with_pointers() {
    let fk = |design: Value| json!({"mode": "fk", "design": design, "inputs_m": [-0.15, 0.2225]});
    let mut d = d1();
    d["rods"][0]["attach_m"] = json!([0.01, 0.0]);
    d["rods"][1]["attach_m"] = json!([0.01, 0.0]);
    d["rods"][2]["attach_m"] = json!([0.01, 0.0]);
    expect_invalid(fk(d), "/design/rods");
    let mut d = d1();
    d["rods"] = json!([d["rods"][0].clone()]);
    expect_invalid(fk(d), "/design/rods");
    let mut d = d1();
    let r = d["rods"][0].clone();
    d["rods"] = json!([
        r.clone(),
        r.clone(),
        r.clone(),
        r.clone(),
        r.clone(),
        r.clone(),
        r.clone(),
        r.clone(),
        r
    ]);
    expect_invalid(fk(d), "/design/rods");
    let mut d = d1();
    d["actuators"][1]["direction"] = json!([1e-13, 0.0]);
    expect_invalid(fk(d), "/design/actuators/1/direction");
    let mut d = d1();
    d["rods"][2]["actuator"] = json!(2);
    let e = expect_invalid(fk(d), "/design/rods/2/actuator");
    assert!(
        e.errors.iter().any(|f| f.pointer == "/design/actuators/1"),
        "actuator 1 left without rods"
    );
    let mut d = d1();
    d["rods"][1]["diameter_m"] = json!(0.2);
    expect_invalid(fk(d), "/design/rods/1/diameter_m");
    let mut d = d1();
    d["rods"][1]["length_m"] = json!(0.0);
    expect_invalid(fk(d), "/design/rods/1/length_m");
    let mut d = d1();
    d["actuators"][0]["stroke_m"] = json!([0.2, 0.2]);
    expect_invalid(fk(d), "/design/actuators/0/stroke_m");
    let mut d = d1();
    d["home_inputs_m"] = json!([-0.25, 0.3]);
    expect_invalid(fk(d), "/design/home_inputs_m");
    // A slender-rod warning, not an error, for 5 <= L/d < 20.
    let mut d = d1();
    for i in 0..3 {
        d["rods"][i]["diameter_m"] = json!(0.05);
    }
    let r = call(fk(d)).expect("accepted with a warning");
    let w = r["diagnostics"]["warnings"].as_array().expect("warnings");
    assert!(
        w.iter()
            .any(|x| x.as_str().is_some_and(|s| s.starts_with("slender_rod")))
    );
    // Every issue at once: the per-field rules in one failure, then the rules between fields
    // in one failure.
    let mut d = d1();
    d["rods"][0]["length_m"] = json!(-1.0);
    d["rods"][1]["youngs_modulus_pa"] = json!(0.0);
    d["rods"][2]["diameter_m"] = json!(-0.004);
    d["actuators"][0]["stroke_m"] = json!([1.0, 0.0]);
    let e = call(fk(d)).expect_err("invalid");
    assert!(e.errors.len() >= 3, "{:?}", e.errors);
    let mut d = d1();
    d["rods"][0]["diameter_m"] = json!(0.5);
    d["rods"][2]["actuator"] = json!(3);
    d["actuators"][0]["stroke_m"] = json!([1.0, 0.0]);
    let e = call(fk(d)).expect_err("invalid");
    assert!(e.errors.len() >= 3, "{:?}", e.errors);
    expect_invalid(
        json!({"mode": "fk", "design": {"preset": "keops_d1", "rods": []}, "inputs_m": [0, 0.3]}),
        "/design/rods",
    );
    expect_invalid(
        json!({"mode": "workspace", "design": {"actuators": [{"origin_m": [0,0], "direction": [1,0], "stroke_m": [-1, 1]}],
        "rods": [{"actuator": 0, "clamp_angle_deg": -60, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [-0.02,0]},
                 {"actuator": 0, "clamp_angle_deg": -120, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [0.02,0]}]}}),
        "/design/actuators",
    );
}

#[test]
fn non_finite_numbers_are_rejected() {
    let mut req: ContinuumWorkspaceRequest =
        serde_json::from_value(json!({"mode": "fk", "design": d1(), "inputs_m": [-0.15, 0.2225]}))
            .expect("parses");
    if let Some(rods) = req.design.rods.as_mut() {
        rods[0].clamp_angle_deg = f64::NAN;
        rods[1].length_m = f64::INFINITY;
    }
    req.inputs_m = Some(vec![f64::NAN, 0.2]);
    let e = run(req, &Budget::unlimited()).expect_err("rejected");
    let ptrs: Vec<&str> = e.errors.iter().map(|f| f.pointer.as_str()).collect();
    for p in ["/design/rods/0/clamp_angle_deg", "/design/rods/1/length_m"] {
        assert!(ptrs.contains(&p), "{p} missing from {ptrs:?}");
    }
    let mut req: ContinuumWorkspaceRequest = serde_json::from_value(
        json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.15, 0.2225]}),
    )
    .expect("parses");
    req.inputs_m = Some(vec![f64::NAN, 0.2]);
    let e = run(req, &Budget::unlimited()).expect_err("rejected");
    assert_eq!(e.errors[0].pointer, "/inputs_m/0");
}

#[test]
fn extreme_scales_keep_working() {
    // Lengths x s, loads x s^2 (spec 6.3 scaling) from micro- to kilometre scale.
    for s in [1e-6, 1e-3, 1e3, 1e6] {
        let mut d = d1();
        for a in 0..2 {
            for k in 0..2 {
                let v = d["actuators"][a]["stroke_m"][k].as_f64().expect("num");
                d["actuators"][a]["stroke_m"][k] = json!(v * s);
            }
        }
        for i in 0..3 {
            for key in ["offset_m", "attach_m"] {
                let x = d["rods"][i][key][0].as_f64().expect("num");
                d["rods"][i][key][0] = json!(x * s);
            }
            d["rods"][i]["length_m"] = json!(0.5 * s);
            d["rods"][i]["diameter_m"] = json!(0.004 * s);
        }
        let r = call(
            json!({"mode": "fk", "design": d, "inputs_m": [-0.15 * s, 0.2225 * s],
                            "load": {"force_n": [0.0, -50.0 * s * s]}}),
        )
        .expect("typed response");
        assert_eq!(r["status"], "ok", "scale {s}");
        let py = r["platform"]["position_m"][1].as_f64().expect("py");
        assert!(
            (py / s + 0.467_061_3).abs() < 1e-6,
            "scale {s}: py/s = {}",
            py / s
        );
    }
}

#[test]
fn search_limits_and_missing_modes() {
    let e = call(json!({"mode": "assembly_modes", "design": {"preset": "symmetric"}, "inputs_m": [-0.2, 0.25],
                        "assembly_modes": {"n_grid": 6}}))
        .expect_err("(2*6)^8 combinations exceed 1e8");
    assert_eq!(e.code, "SEARCH_TOO_LARGE");
    assert_eq!(e.class, ProblemClass::TooLarge);
    assert_eq!(e.errors[0].pointer, "/assembly_modes/n_grid");
    let r = call(json!({"mode": "assembly_modes", "design": {"preset": "symmetric"}, "inputs_m": [-0.2, 0.25],
                        "assembly_modes": {"n_grid": 3, "max_refine": 50}}))
    .expect("small search runs");
    assert_eq!(r["complete"], false);
    let e = call(json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.22, 0.2425],
                        "start": {"kind": "assembly_mode", "index": 99}, "assembly_modes": {"n_grid": 3}}))
    .expect_err("index beyond the list");
    assert_eq!(e.code, "ASSEMBLY_MODE_NOT_FOUND");
    assert_eq!(e.errors[0].pointer, "/start/index");
}

#[test]
fn garbage_warm_starts_and_random_designs() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    // Random warm-start states: converge somewhere or report no_convergence.
    for _ in 0..20 {
        let v: Vec<f64> = (0..12).map(|_| rng.random_range(-50.0..50.0)).collect();
        let r = call(json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.15, 0.2225],
                            "start": {"kind": "guess", "state": {"v": v}}, "solver": {"max_iter": 30}}))
        .expect("typed response");
        assert!(
            ["ok", "no_convergence", "singular"].contains(&r["status"].as_str().expect("status"))
        );
    }
    expect_invalid(
        json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.15, 0.2225],
               "start": {"kind": "guess", "state": {"v": [0.0, 1.0]}}}),
        "/start/state/v",
    );
    // Random valid designs with 2..5 rods on 1..2 guides: FK from home or from the mode search.
    for _ in 0..12 {
        let n_act = rng.random_range(1..=2usize);
        let n = rng.random_range(2..=5usize).max(n_act);
        let acts: Vec<Value> = (0..n_act)
            .map(|_| json!({"origin_m": [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)],
                            "direction": [rng.random_range(-1.0..1.0), rng.random_range(0.1..1.0)], "stroke_m": [-1.0, 1.0]}))
            .collect();
        let rods: Vec<Value> = (0..n)
            .map(|i| json!({"actuator": i % n_act, "offset_m": [rng.random_range(-0.1..0.1), 0.0],
                            "clamp_angle_deg": rng.random_range(-180.0..180.0), "length_m": rng.random_range(0.2..0.8),
                            "diameter_m": 0.004, "attach_m": [rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1)]}))
            .collect();
        let inputs: Vec<f64> = (0..n_act).map(|_| rng.random_range(-0.2..0.2)).collect();
        let req = json!({"mode": "fk", "design": {"actuators": acts, "rods": rods}, "inputs_m": inputs,
                         "assembly_modes": {"n_grid": 2, "max_refine": 30}, "solver": {"max_iter": 20}});
        match call(req) {
            Ok(r) => assert!(
                ["ok", "no_convergence", "singular"]
                    .contains(&r["status"].as_str().expect("status"))
            ),
            Err(e) => assert!(
                matches!(
                    e.class,
                    ProblemClass::TooLarge
                        | ProblemClass::InvalidInput
                        | ProblemClass::NotConverged
                ),
                "{e}"
            ),
        }
    }
}

fn leaves(v: &Value, path: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                leaves(x, format!("{path}/{k}"), out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                leaves(x, format!("{path}/{i}"), out);
            }
        }
        Value::Number(_) => out.push(path),
        _ => {}
    }
}

/// Every numeric leaf of the api/ examples pushed to 0, +/-1e300, 1e-300 and -1: a typed error
/// or a response without hidden NaN, within a 300 ms budget per request.
#[test]
fn mutated_examples_never_produce_nan() {
    for name in ["fk", "sweep_symmetric"] {
        let path = format!(
            "{}/api/continuum_workspace/{name}.json",
            env!("CARGO_MANIFEST_DIR")
        );
        let original: Value =
            serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json");
        let mut ptrs = Vec::new();
        leaves(&original, String::new(), &mut ptrs);
        for p in ptrs {
            for x in [0.0, -1e300, 1e300, 1e-300, -1.0] {
                let mut v = original.clone();
                if let Some(slot) = v.pointer_mut(&p) {
                    *slot = json!(x);
                }
                let Ok(req) = serde_json::from_value::<ContinuumWorkspaceRequest>(v) else {
                    continue;
                };
                let budget = Budget::new(Duration::from_millis(300));
                if let Ok(out) = run(req, &budget) {
                    let body = serde_json::to_value(out).expect("serialises");
                    check_no_hidden_nan(&body, "", &format!("{name}{p}={x}"));
                }
            }
        }
    }
}

/// The rod-crossing limit (spec 4.7 limits) stops the wave where rod centre lines cross.
#[test]
fn rod_crossing_limit_cuts_the_workspace() {
    let sweep = |rc: &str| {
        call(json!({"mode": "workspace", "design": {"preset": "keops_d1"},
                    "workspace": {"grid": [21, 21], "stability_check": "det_sign", "limits": {"rod_crossing": rc}}}))
        .expect("typed response")
    };
    let (ignore, reject) = (sweep("ignore"), sweep("reject"));
    let n = |v: &Value| v["metrics"]["n_accepted"].as_u64().expect("count");
    assert!(n(&reject) < n(&ignore), "{} vs {}", n(&reject), n(&ignore));
    assert!(
        reject["failures"]["limit_rod_crossing"]
            .as_u64()
            .is_some_and(|c| c > 0),
        "{}",
        reject["failures"]
    );
    assert!(ignore["failures"].get("limit_rod_crossing").is_none());
}
