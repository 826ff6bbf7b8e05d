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
    let body = json!({
        "vehicle": {"curb_mass_kg": -1, "gear_efficiency": 1.5},
        "inverter": {"efficiency": 0},
        "cycles": ["nowhere", {"name": "c", "time_s": [0, 2, 1], "speed_kmh": [0, 10, 0]}],
        "motors": [{"id": "x", "model": "ipmsm", "pole_pairs": 4, "psi_m_wb": 0.2, "ld_h": 0.001, "lq_h": 0.0005,
                    "r_phase_20c_ohm": 0.01, "i_max_arms": 100, "v_dc": 400, "n_max_rpm": 6000}],
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
        "/cycles/0",
        "/cycles/1/time_s/2",
        "/motors/0/lq_h",
        "/options/substeps",
    ] {
        assert!(ptrs.iter().any(|q| q == want), "missing {want}: {p}");
    }
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
