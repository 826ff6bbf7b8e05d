//! `POST /v1/continuum-workspace` over HTTP: the spec examples come back, optional outputs are
//! omitted unless asked, and every kind of bad request gets the right problem+json answer
//! (400/415/422) with pointers to the offending fields and the module's `code`.

use crate::common;

use common::post_json;
use serde_json::{Value, json};

const PATH: &str = "/v1/continuum-workspace";

fn fk_example() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/api/continuum_workspace/fk.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json")
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

#[tokio::test]
async fn solves_the_spec_fk_example() {
    let r = post_json(PATH, &fk_example()).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    assert_eq!(b["mode"], "fk");
    assert_eq!(b["status"], "ok");
    assert!((num(&b["platform"]["position_m"][0]) - 0.024_909_2).abs() < 1e-7);
    assert!((num(&b["platform"]["position_m"][1]) + 0.467_061_3).abs() < 1e-7);
    assert!((num(&b["platform"]["parasitic_angle_deg"]) - 0.145_897).abs() < 1e-5);
    assert!((num(&b["rods"][0]["tip_force_n"][1]) + 24.9925).abs() < 1e-4);
    assert_eq!(b["stability"]["stable"], true);
    assert_eq!(b["solver_state"]["v"].as_array().map(Vec::len), Some(12));
    assert!(
        b["rods"][0].get("shape").is_none(),
        "shapes only on request"
    );
    assert!(
        b.get("preset").is_none(),
        "explicit design: no preset statement"
    );
}

#[tokio::test]
async fn optional_outputs_only_when_asked() {
    let mut body = fk_example();
    body["outputs"] = json!({"stability": false, "rod_shape_points": 5});
    let b = post_json(PATH, &body).await.json();
    assert!(b.get("stability").is_none());
    assert_eq!(b["rods"][2]["shape"].as_array().map(Vec::len), Some(5));
    let sweep = json!({"mode": "workspace", "design": {"preset": "keops_d1"},
                       "workspace": {"grid": [5, 5], "stability_check": "none"}});
    let b = post_json(PATH, &sweep).await.json();
    assert_eq!(b["mode"], "workspace");
    assert!(
        b.get("nodes").is_none(),
        "node arrays only with return_nodes"
    );
    assert!(
        b["preset"]["assumed_geometry"] == true
            && b["preset"]["description"]
                .as_str()
                .is_some_and(|d| d.contains("ASSUMED"))
    );
    assert_eq!(b["grid"]["lambda1_m"].as_array().map(Vec::len), Some(5));
}

#[tokio::test]
async fn assembly_modes_are_marked_non_certified() {
    let body = json!({"mode": "assembly_modes", "design": {"preset": "keops_d1"}, "inputs_m": [-0.22, 0.2425],
                      "assembly_modes": {"n_grid": 4}});
    let b = post_json(PATH, &body).await.json();
    assert_eq!(b["complete"], false);
    assert!(
        b["note"]
            .as_str()
            .is_some_and(|n| n.contains("Non-certified"))
    );
    // The settings used are echoed: the given N_grid, the defaults for the rest.
    assert_eq!(
        b["search"],
        json!({"n_grid": 4, "tol": 0.5, "cell": 2, "max_refine": 4000})
    );
    // N_grid 4 / Tol 0.5 finds the spec's two stable modes (theta -0.00483 and -118.658 deg) and
    // one more (-136.64 deg, spec 6.2 N_grid 9 list).
    let stable: Vec<f64> = b["solutions"]
        .as_array()
        .expect("solutions")
        .iter()
        .filter(|x| x["stable"] == true)
        .filter_map(|x| x["pose"]["parasitic_angle_deg"].as_f64())
        .collect();
    assert_eq!(stable.len(), 3, "stable modes {stable:?}");
    for want in [-0.00483, -118.658, -136.64] {
        assert!(
            stable.iter().any(|t| (t - want).abs() < 5e-3),
            "{want} deg not in {stable:?}"
        );
    }
}

/// Shape errors are decode errors with serde's path as the pointer.
#[tokio::test]
async fn shape_errors_point_at_the_field() {
    let cases = [
        ("/mode", json!({"mode": "inverse"})),
        ("/inputs_mm", json!({"inputs_mm": [0.0, 0.1]})),
        (
            "/solver/rk4_steps",
            json!({"solver": {"rk4_steps": "many"}}),
        ),
        (
            "/design/rods/0/actuator",
            json!({"design": {"rods": [{"actuator": -1}]}}),
        ),
    ];
    for (pointer, patch) in cases {
        let mut b = fk_example();
        for (k, v) in patch.as_object().expect("object") {
            b[k] = v.clone();
        }
        let r = post_json(PATH, &b).await;
        r.problem(422);
        let ptrs = r.pointers();
        assert!(
            ptrs.iter().any(|p| p.starts_with(pointer)),
            "{patch}: {ptrs:?}"
        );
    }
}

#[tokio::test]
async fn invalid_fields_are_all_listed() {
    let mut b = fk_example();
    b["design"]["rods"][0]["length_m"] = json!(0.0);
    b["design"]["rods"][1]["youngs_modulus_pa"] = json!(-2.0);
    b["design"]["actuators"][1]["direction"] = json!([0.0, 0.0]);
    let r = post_json(PATH, &b).await;
    r.invalid_input_at(&[
        "/design/rods/0/length_m",
        "/design/rods/1/youngs_modulus_pa",
        "/design/actuators/1/direction",
    ]);
    let mut b = fk_example();
    b["inputs_m"] = json!([0.25, 0.2225]);
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/inputs_m/0"]);
}

#[tokio::test]
async fn oversized_work_is_too_large_and_missing_modes_not_converged() {
    let cases = [
        (
            "GRID_TOO_LARGE",
            "/problems/too-large",
            json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "workspace": {"grid": [300, 300]}}),
            "/workspace/grid",
        ),
        (
            "SEARCH_TOO_LARGE",
            "/problems/too-large",
            json!({"mode": "assembly_modes", "design": {"preset": "symmetric"}, "inputs_m": [-0.2, 0.25],
                   "assembly_modes": {"n_grid": 6}}),
            "/assembly_modes/n_grid",
        ),
        (
            "ASSEMBLY_MODE_NOT_FOUND",
            "/problems/not-converged",
            json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.22, 0.2425],
                   "start": {"kind": "assembly_mode", "index": 50}, "assembly_modes": {"n_grid": 3}}),
            "/start/index",
        ),
    ];
    for (code, type_uri, body, pointer) in cases {
        let r = post_json(PATH, &body).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{p}");
        assert_eq!(p["type"], type_uri, "{p}");
        assert_eq!(r.pointers(), vec![pointer.to_string()]);
    }
}

#[tokio::test]
async fn non_convergence_is_a_200_with_status_and_the_time_limit_is_honoured() {
    let body = json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.7, 0.7225]});
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200);
    let b = r.json();
    assert_eq!(b["status"], "no_convergence");
    assert!(b.get("platform").is_none());
    let sweep = json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "time_limit_ms": 50,
                       "workspace": {"grid": [101, 101], "return_nodes": true}});
    let t0 = std::time::Instant::now();
    let r = post_json(PATH, &sweep).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.json()["report"]["stop_reason"], "deadline");
    assert!(t0.elapsed().as_secs() < 30);
    let r = post_json(PATH, &json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [0, 0.3], "time_limit_ms": 0})).await;
    r.assert_422_at(&["/time_limit_ms"]);
}

/// A workspace sweep ignores `inputs_m` (an FK field), but the document bounds it: a value out
/// of its documented range is a 422 naming the element, never a 200 (the module accepted the
/// rest of the request, the service checks the bounds the module did not).
#[tokio::test]
async fn ignored_fields_are_still_held_to_their_documented_bounds() {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("api/continuum_workspace/sweep_symmetric.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p).expect("example")).expect("json");
    v["inputs_m"] = serde_json::json!([0.0, -1_000_001.0]);
    let r = crate::common::post_json("/v1/continuum-workspace", &v).await;
    r.assert_422_at(&["/inputs_m/1"]);
    v["inputs_m"] = serde_json::json!([0.0, -0.5]);
    let r = crate::common::post_json("/v1/continuum-workspace", &v).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
}
