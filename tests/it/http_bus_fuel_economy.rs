//! `POST /v1/bus-fuel-economy` and `/v1/bus-fuel-economy/motor-map` over HTTP: results come back,
//! optional outputs only on request, and every kind of bad request gets the right problem+json
//! answer with a pointer to the offending field.

use crate::common;

use common::{post_json, post_json_to};
use mechcalc::AppState;
use mechcalc::config::ServiceConfig;
use serde_json::{Value, json};

use crate::support::bus_demo_motor::demo_ipmsm_json as demo;

const PATH: &str = "/v1/bus-fuel-economy";
const MAP_PATH: &str = "/v1/bus-fuel-economy/motor-map";

fn example() -> Value {
    json!({"cycles": ["manhattan", "hwfet", "hdudds"], "motors": [demo("initial", 0.0035), demo("low_kac", 0.0032)]})
}

fn constant() -> Value {
    json!({"id": "c", "model": "constant", "efficiency": 0.93})
}

#[tokio::test]
async fn two_motor_comparison_runs() {
    let r = post_json(PATH, &example()).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    let results = b["results"].as_array().expect("results");
    assert_eq!(results.len(), 6);
    assert_eq!(results[0]["n_over_envelope"], 66);
    assert!(
        results[0]["fe_km_per_kwh"]
            .as_f64()
            .is_some_and(|fe| (fe - 1.2502).abs() < 5e-5)
    );
    assert!(results[0]["warnings"].to_string().contains("envelope"));
    assert!(
        b["comparison"]["fe_change_pct"]["low_kac"]["hwfet"]
            .as_f64()
            .is_some_and(|x| x > 0.0)
    );
    assert_eq!(b["echo"]["cycle_data_version"], "advisor-2003");
    assert_eq!(b["echo"]["motor_eval"], "loss_map");
    // Costly outputs are absent unless requested.
    for key in ["loss_breakdown", "op_histogram", "traces"] {
        assert!(results[0].get(key).is_none(), "{key} not requested");
    }
    assert!(b.get("motor_maps").is_none());
}

#[tokio::test]
async fn requested_outputs_are_present() {
    let body = json!({"cycles": ["manhattan"], "motors": [demo("d", 0.0035)],
                      "options": {"outputs": ["loss_breakdown", "op_histogram", "traces", "efficiency_map"]}});
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    let res = &b["results"][0];
    assert!(
        res["loss_breakdown"]["motor_cu_ac_extra_kwh"]
            .as_f64()
            .is_some_and(|x| x > 0.0)
    );
    assert_eq!(
        res["op_histogram"]["modal_bin"]["rpm"],
        json!([1000.0, 1500.0])
    );
    assert_eq!(res["traces"]["t_s"].as_array().map(Vec::len), Some(1089));
    assert!(b["motor_maps"][0]["efficiency"].is_array());
}

#[tokio::test]
async fn motor_map_runs() {
    let r = post_json(
        MAP_PATH,
        &json!({"motor": demo("d", 0.0035), "include_components": true}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    assert_eq!(b["t_max_nm"][0], 800.0);
    assert!(b["components"]["mode"].to_string().contains("fw"));
}

#[tokio::test]
async fn wrong_type_and_unknown_field_are_422_with_pointers() {
    let mut b = example();
    b["vehicle"] = json!({"curb_mass_kg": "heavy"});
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/vehicle/curb_mass_kg"]);

    let mut b = example();
    b["options"] = json!({"substep": 2});
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/options/substep"]);

    let mut b = example();
    b["motors"][0]["model"] = json!("diesel");
    let r = post_json(PATH, &b).await;
    r.problem(422);
    assert!(
        r.pointers().iter().all(|p| p.starts_with("/motors/0")),
        "{:?}",
        r.pointers()
    );
}

#[tokio::test]
async fn every_bad_field_is_listed() {
    // Per-field rules (the door): every offending field in one 422.
    let body = json!({
        "vehicle": {"curb_mass_kg": -1, "gear_efficiency": 1.5},
        "inverter": {"efficiency": 0},
        "cycles": ["hwfet"],
        "motors": [constant()],
        "options": {"substeps": 40}
    });
    let r = post_json(PATH, &body).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    assert_eq!(p["code"], "INVALID_INPUT");
    let ptrs = r.pointers();
    for want in [
        "/vehicle/curb_mass_kg",
        "/vehicle/gear_efficiency",
        "/inverter/efficiency",
        "/options/substeps",
    ] {
        assert!(ptrs.iter().any(|q| q == want), "missing {want}: {p}");
    }

    // Rules between fields (after the door): every offending field in one 422, each issue with
    // its rule's code.
    let body = json!({
        "cycles": ["nowhere", {"name": "c", "time_s": [0, 2, 1], "speed_kmh": [0, 10, 0]}],
        "motors": [{"id": "x", "model": "ipmsm", "pole_pairs": 4, "psi_m_wb": 0.2, "ld_h": 0.001, "lq_h": 0.0005,
                    "r_phase_20c_ohm": 0.01, "i_max_arms": 100, "v_dc": 400, "n_max_rpm": 6000}]
    });
    let r = post_json(PATH, &body).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    let issues: Vec<(String, String)> = p["errors"]
        .as_array()
        .expect("errors")
        .iter()
        .map(|e| {
            let d = e["detail"].as_str().unwrap_or_default();
            let code = d.split(':').next().unwrap_or_default().to_owned();
            (e["pointer"].as_str().unwrap_or_default().to_owned(), code)
        })
        .collect();
    for want in [
        ("/cycles/0", "UNKNOWN_CYCLE"),
        ("/cycles/1/time_s/2", "AXIS_ORDER"),
        ("/motors/0/lq_h", "LQ_BELOW_LD"),
    ] {
        assert!(
            issues.iter().any(|(q, c)| q == want.0 && c == want.1),
            "missing {want:?}: {p}"
        );
    }
}

/// The document's `x-cross-field-rules` of the operation at `path`: their codes, sorted.
fn documented_rule_codes(path: &str) -> Vec<String> {
    let doc = serde_json::to_value(mechcalc::http::openapi()).expect("openapi");
    let key = path.replace('/', "~1");
    let rules = doc
        .pointer(&format!("/paths/{key}/post/x-cross-field-rules"))
        .and_then(Value::as_array)
        .expect("x-cross-field-rules");
    let mut codes: Vec<String> = rules
        .iter()
        .map(|r| r["code"].as_str().expect("code").to_owned())
        .collect();
    codes.sort();
    codes
}

fn custom(time_s: &Value, speed_kmh: &Value) -> Value {
    json!({"name": "c", "time_s": time_s, "speed_kmh": speed_kmh})
}

/// Per rule between fields: its code, its pointer and a schema-valid request that breaks it.
fn cross_field_cases() -> Vec<(&'static str, &'static str, Value)> {
    let m = |extra: Value| {
        let mut c = constant();
        for (k, x) in extra.as_object().expect("object") {
            c[k] = x.clone();
        }
        c
    };
    let ipmsm = |extra: Value| {
        let mut d = demo("d", 0.0035);
        for (k, x) in extra.as_object().expect("object") {
            d[k] = x.clone();
        }
        d
    };
    let table = json!({"speed_rpm": [0, 3000, 6000], "t_max_nm": [800, 800, 400]});
    vec![
        (
            "BATTERY_MODEL_FIELDS",
            "/battery/r0_ohm",
            json!({"battery": {"r0_ohm": 0.03}, "cycles": ["hwfet"], "motors": [constant()]}),
        ),
        (
            "BATTERY_ECM_REQUIRED",
            "/battery/c2_f",
            json!({"battery": {"model": "ecm_2rc", "soc_initial": 0.9, "ocv_soc": [0, 1], "ocv_v": [300, 400],
                            "r0_ohm": 0.03, "r1_ohm": 0.01, "c1_f": 3000, "r2_ohm": 0.01},
                "cycles": ["hwfet"], "motors": [constant()]}),
        ),
        (
            "AXIS_ORDER",
            "/cycles/0/time_s/2",
            json!({"cycles": [custom(&json!([0, 2, 1]), &json!([0, 10, 0]))], "motors": [constant()]}),
        ),
        (
            "LENGTH_MISMATCH",
            "/cycles/0/speed_kmh",
            json!({"cycles": [custom(&json!([0, 1, 2]), &json!([0, 10]))], "motors": [constant()]}),
        ),
        (
            "TIME_STEP",
            "/cycles/0/time_s/1",
            json!({"cycles": [custom(&json!([0, 100, 101]), &json!([0, 10, 0]))], "motors": [constant()]}),
        ),
        (
            "UNKNOWN_CYCLE",
            "/cycles/0",
            json!({"cycles": ["nowhere"], "motors": [constant()]}),
        ),
        (
            "ZERO_DISTANCE",
            "/cycles/0",
            json!({"cycles": [custom(&json!([0, 10, 20]), &json!([0, 0, 0]))], "motors": [constant()]}),
        ),
        (
            "DUPLICATE_NAME",
            "/motors/1/id",
            json!({"cycles": ["hwfet"], "motors": [constant(), constant()]}),
        ),
        (
            "ENVELOPE_CONFLICT",
            "/motors/0/envelope",
            json!({"cycles": ["hwfet"], "motors": [m(json!({"envelope": table, "t_peak_nm": 700}))]}),
        ),
        (
            "BACK_EMF_PSI",
            "/motors/0/back_emf",
            json!({"cycles": ["hwfet"], "motors": [ipmsm(json!({"back_emf": {"v_peak_phase": 1e5, "at_rpm": 1}}))]}),
        ),
        (
            "LQ_BELOW_LD",
            "/motors/0/lq_h",
            json!({"cycles": ["hwfet"], "motors": [ipmsm(json!({"lq_h": 0.0003}))]}),
        ),
        (
            "STACK_SCALE_NEEDS_DOWELL",
            "/motors/0/stack_scale",
            json!({"cycles": ["hwfet"], "motors": [ipmsm(json!({"stack_scale": 1.1, "ac_factor": {"model": "none"}}))]}),
        ),
        (
            "LOSS_AXIS_ZERO",
            "/motors/0/torque_nm",
            json!({"cycles": ["hwfet"], "motors": [{"id": "l", "model": "loss_map", "speed_rpm": [0, 6000],
                "torque_nm": [10, 800], "loss_w": [[0, 0], [0, 0]]}]}),
        ),
        (
            "DESIRABILITY_ZERO",
            "/options/desirability_weights",
            json!({"cycles": ["hwfet"], "motors": [constant()], "options": {"desirability_weights": [0]}}),
        ),
        (
            "CYCLE_ABOVE_MOTOR_SPEED",
            "/motors/0/n_max_rpm",
            json!({"cycles": ["hwfet"], "motors": [m(json!({"n_max_rpm": 1000}))]}),
        ),
        (
            "TOO_MANY_SAMPLES",
            "/options/substeps",
            json!({"cycles": [custom(&json!((0..40_000).map(f64::from).collect::<Vec<_>>()),
                                  &json!(vec![10.0; 40_000]))],
                "motors": [constant()], "options": {"substeps": 32}}),
        ),
        (
            "SHARD_INDEX_BELOW_COUNT",
            "/shard/index",
            json!({"cycles": ["hwfet"], "motors": [constant()], "shard": {"index": 2, "count": 2}}),
        ),
    ]
}

/// Each rule between fields the operation lists is reachable: a request that passes every
/// per-field rule and breaks that one rule gets a 422 with the rule's code at the rule's pointer.
#[tokio::test]
async fn every_cross_field_rule_is_reachable() {
    let cases = cross_field_cases();
    for (code, pointer, body) in &cases {
        let r = post_json(PATH, body).await;
        let p = r.problem(422);
        assert_eq!(p["code"], *code, "{p}");
        assert_eq!(r.pointers(), [*pointer], "{code}: {p}");
    }
    // Every listed code is one of these, or a failure of the computation that the tests above
    // reach (deadline, unreachable speed, map size) or that guards the answer's size.
    let computed = [
        "DEADLINE_EXCEEDED",
        "MOTOR_SPEED_UNREACHABLE",
        "HISTOGRAM_TOO_LARGE",
        "MAP_TOO_LARGE",
        "RESPONSE_TOO_LARGE",
    ];
    let mut want: Vec<String> = cases
        .iter()
        .map(|c| c.0)
        .chain(computed)
        .map(str::to_owned)
        .collect();
    want.sort();
    assert_eq!(documented_rule_codes(PATH), want);
}

/// The motor map lists the motor's rules (reported under /motor) and its own computation's
/// failures.
#[tokio::test]
async fn motor_map_cross_field_rules() {
    let mut d = demo("d", 0.0035);
    d["lq_h"] = json!(0.0003);
    let r = post_json(MAP_PATH, &json!({"motor": d})).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "LQ_BELOW_LD", "{p}");
    assert_eq!(r.pointers(), ["/motor/lq_h"]);
    let mut want: Vec<String> = [
        "AXIS_ORDER",
        "LENGTH_MISMATCH",
        "ENVELOPE_CONFLICT",
        "BACK_EMF_PSI",
        "LQ_BELOW_LD",
        "STACK_SCALE_NEEDS_DOWELL",
        "LOSS_AXIS_ZERO",
        "DEADLINE_EXCEEDED",
        "MAP_TOO_LARGE",
        "RESPONSE_TOO_LARGE",
    ]
    .map(str::to_owned)
    .to_vec();
    want.sort();
    assert_eq!(documented_rule_codes(MAP_PATH), want);
}

fn example_file(name: &str) -> Value {
    let path = format!("{}/api/bus_fuel_economy/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json")
}

/// The answer without its timing fields.
fn untimed(r: &common::Reply) -> Value {
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let mut v = r.json();
    if let Some(rep) = v["report"].as_object_mut() {
        rep.remove("elapsed_ms");
    }
    v
}

/// `null` for an optional field is the same as leaving it out, at every depth: the api examples
/// with every optional field they omit set to `null` get the examples' answers.
#[tokio::test]
async fn null_means_absent() {
    let plain = example_file("two_motor_comparison.json");
    let mut b = plain.clone();
    for k in ["shard", "time_limit_ms"] {
        b[k] = Value::Null;
    }
    for k in ["rotational_inertia_factor", "grade", "aux_power_w"] {
        b["vehicle"][k] = Value::Null;
    }
    for k in [
        "nominal_voltage",
        "capacity_kwh",
        "soc_initial",
        "ocv_soc",
        "ocv_v",
        "r0_ohm",
        "r1_ohm",
        "c1_f",
        "r2_ohm",
        "c2_f",
    ] {
        b["battery"][k] = Value::Null;
    }
    for m in b["motors"].as_array_mut().expect("motors") {
        for k in ["psi_m_wb", "voltage_utilization", "mech", "stack_scale"] {
            m[k] = Value::Null;
        }
    }
    for k in [
        "regen",
        "regen_limit",
        "op_histogram",
        "desirability_weights",
    ] {
        b["options"][k] = Value::Null;
    }
    let want = untimed(&post_json(PATH, &plain).await);
    assert_eq!(untimed(&post_json(PATH, &b).await), want);

    // Every member of vehicle, inverter, battery and options as null = each absent = defaults;
    // and null for the optional top-level objects is the same as leaving them out.
    let mut nulls = json!({"cycles": ["hwfet"], "motors": [constant()],
                           "vehicle": {}, "inverter": {}, "battery": {}, "options": {}});
    for (obj, keys) in [
        (
            "vehicle",
            &[
                "curb_mass_kg",
                "passengers",
                "mass_per_passenger_kg",
                "frontal_area_m2",
                "drag_coeff",
                "rolling_coeff",
                "air_density",
                "gravity",
                "wheel_radius_m",
                "gear_ratio",
                "gear_efficiency",
                "rotational_inertia_factor",
                "grade",
                "aux_power_w",
            ][..],
        ),
        ("inverter", &["efficiency"][..]),
        ("battery", &["model", "efficiency"][..]),
        (
            "options",
            &[
                "mode",
                "power_convention",
                "substeps",
                "regen",
                "regen_limit",
                "motor_eval",
                "loss_map_grid",
                "outputs",
                "op_histogram",
                "desirability_weights",
            ][..],
        ),
    ] {
        for k in keys {
            nulls[obj][*k] = Value::Null;
        }
    }
    let top = json!({"cycles": ["hwfet"], "motors": [constant()],
                     "vehicle": null, "inverter": null, "battery": null, "options": null});
    let gone = json!({"cycles": ["hwfet"], "motors": [constant()]});
    let want = untimed(&post_json(PATH, &gone).await);
    assert_eq!(untimed(&post_json(PATH, &nulls).await), want);
    assert_eq!(untimed(&post_json(PATH, &top).await), want);

    // The motor map: the example with its omitted optional fields null.
    let plain = example_file("motor_map/demo_motor.json");
    let mut b = plain.clone();
    for k in ["grid", "include_components", "time_limit_ms"] {
        if b.get(k).is_none() {
            b[k] = Value::Null;
        }
    }
    for k in ["psi_m_wb", "voltage_utilization", "mech", "stack_scale"] {
        b["motor"][k] = Value::Null;
    }
    let want = untimed(&post_json(MAP_PATH, &plain).await);
    assert_eq!(untimed(&post_json(MAP_PATH, &b).await), want);
}

#[tokio::test]
async fn cycle_faster_than_the_motor_is_422_on_n_max() {
    let mut m = demo("slow", 0.0035);
    m["n_max_rpm"] = json!(4000);
    let r = post_json(PATH, &json!({"cycles": ["hwfet"], "motors": [m]})).await;
    let p = r.problem(422);
    assert_eq!(r.pointers(), vec!["/motors/0/n_max_rpm"]);
    let detail = p["errors"][0]["detail"].as_str().unwrap_or_default();
    assert!(
        detail.contains("hwfet") && detail.contains("rpm"),
        "{detail}"
    );
}

#[tokio::test]
async fn stop_only_cycle_is_422() {
    let c = json!({"name": "stops", "time_s": [0, 10, 20], "speed_kmh": [0, 0, 0]});
    let r = post_json(PATH, &json!({"cycles": [c], "motors": [constant()]})).await;
    r.assert_422_at(&["/cycles/0"]);
}

#[tokio::test]
async fn unreachable_speed_is_infeasible() {
    let m = json!({"id": "fw", "model": "ipmsm", "pole_pairs": 4, "psi_m_wb": 0.6, "ld_h": 0.00035, "lq_h": 0.00055,
                   "r_phase_20c_ohm": 0.006, "i_max_arms": 100, "v_dc": 360, "n_max_rpm": 6000});
    let r = post_json(PATH, &json!({"cycles": ["hwfet"], "motors": [m]})).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/infeasible");
    assert_eq!(p["code"], "MOTOR_SPEED_UNREACHABLE");
    assert_eq!(r.pointers(), vec!["/motors/0/n_max_rpm"]);
}

#[tokio::test]
async fn oversized_work_is_too_large() {
    let body = json!({"cycles": ["manhattan"], "motors": [demo("d", 0.0035)],
                      "options": {"loss_map_grid": {"speed_step_rpm": 1, "torque_step_nm": 0.1}}});
    let r = post_json(PATH, &body).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/too-large");
    assert_eq!(p["code"], "MAP_TOO_LARGE");
    assert_eq!(r.pointers(), vec!["/options/loss_map_grid"]);

    let nine: Vec<Value> = (0..9)
        .map(|i| json!({"id": format!("m{i}"), "model": "constant", "efficiency": 0.9}))
        .collect();
    let r = post_json(PATH, &json!({"cycles": ["manhattan"], "motors": nine})).await;
    r.assert_422_at(&["/motors"]);
}

#[tokio::test]
async fn exhausted_time_budget_is_422() {
    let config = ServiceConfig {
        max_time_budget_ms: 1,
        ..common::config()
    };
    let body = json!({"cycles": ["manhattan", "hwfet", "hdudds"], "motors": [demo("a", 0.0035), demo("b", 0.003)],
                      "options": {"motor_eval": "direct", "substeps": 32}});
    let r = post_json_to(AppState::new(config), PATH, &body).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "DEADLINE_EXCEEDED");
}

#[tokio::test]
async fn motor_map_bad_input_points_at_the_motor() {
    let mut m = demo("d", 0.0035);
    m["ld_h"] = json!(-1.0);
    let r = post_json(
        MAP_PATH,
        &json!({"motor": m, "grid": {"speed_step_rpm": 0, "torque_step_nm": 50}}),
    )
    .await;
    r.problem(422);
    let ptrs = r.pointers();
    assert!(ptrs.contains(&"/motor/ld_h".to_owned()), "{ptrs:?}");
    assert!(
        ptrs.contains(&"/grid/speed_step_rpm".to_owned()),
        "{ptrs:?}"
    );

    let r = post_json(
        MAP_PATH,
        &json!({"motor": demo("d", 0.0035), "grid": {"speed_step_rpm": 1, "torque_step_nm": 0.1}}),
    )
    .await;
    let p = r.problem(422);
    assert_eq!(p["code"], "MAP_TOO_LARGE");
    assert_eq!(r.pointers(), vec!["/grid"]);
}
