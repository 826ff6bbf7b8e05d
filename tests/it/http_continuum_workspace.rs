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

/// Every broken per-field rule is listed in one 422 from the door; a rule between fields (the
/// guide direction's norm) is checked after the door passes, with its own code.
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
    ]);
    let mut b = fk_example();
    b["design"]["actuators"][1]["direction"] = json!([0.0, 0.0]);
    b["design"]["actuators"][0]["stroke_m"] = json!([0.2, 0.2]);
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input", "{p}");
    let ptrs = r.pointers();
    for want in [
        "/design/actuators/1/direction",
        "/design/actuators/0/stroke_m",
    ] {
        assert!(
            ptrs.iter().any(|q| q == want),
            "{want} missing from {ptrs:?}"
        );
    }
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

/// `(code, request, pointer)`: a request the schema accepts that breaks one rule between fields.
#[expect(clippy::too_many_lines, reason = "one table of cases, one rule each")]
fn cross_rule_cases() -> Vec<(&'static str, Value, &'static str)> {
    let fk = fk_example;
    let with = |mut b: Value, pointer: &str, x: Value| {
        let (parent, key) = pointer.rsplit_once('/').expect("a pointer");
        match b.pointer_mut(parent).expect("parent exists") {
            Value::Object(o) => {
                o.insert(key.to_owned(), x);
            }
            Value::Array(a) => a[key.parse::<usize>().expect("index")] = x,
            _ => panic!("{parent} holds no members"),
        }
        b
    };
    let without = |mut b: Value, parent: &str, key: &str| {
        b.pointer_mut(parent)
            .and_then(Value::as_object_mut)
            .map(|o| o.remove(key));
        b
    };
    let sweep = |workspace: Value| json!({"mode": "workspace", "design": {"preset": "keops_d1"}, "workspace": workspace});
    let mut three_actuators = fk();
    three_actuators["design"]["actuators"]
        .as_array_mut()
        .expect("actuators")
        .push(json!({"origin_m": [0, 0.1], "direction": [1, 0], "stroke_m": [-1, 1]}));
    let mut stiffness_only = without(fk(), "/design/rods/0", "diameter_m");
    stiffness_only["design"]["rods"][0]["ei_nm2"] = json!(2.6);
    stiffness_only["solver"]["axial_extensibility"] = json!(true);
    let mut sharded_fk = fk();
    sharded_fk["shard"] = json!({"index": 0, "count": 1});
    let mut coincident = fk();
    for i in 0..3 {
        coincident["design"]["rods"][i]["attach_m"] = json!([0.01, 0.0]);
    }
    let one_guide = json!({"mode": "workspace", "design": {
        "actuators": [{"origin_m": [0,0], "direction": [1,0], "stroke_m": [-1, 1]}],
        "rods": [{"actuator": 0, "clamp_angle_deg": -60, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [-0.02,0]},
                 {"actuator": 0, "clamp_angle_deg": -120, "length_m": 0.5, "diameter_m": 0.004, "attach_m": [0.02,0]}]}});
    vec![
        (
            "DESIGN_SOURCE",
            with(fk(), "/design/preset", json!("keops_d1")),
            "/design/actuators",
        ),
        (
            "DESIGN_SOURCE",
            without(fk(), "/design", "rods"),
            "/design/rods",
        ),
        (
            "DIRECTION_NORM",
            with(fk(), "/design/actuators/1/direction", json!([1e-13, 0])),
            "/design/actuators/1/direction",
        ),
        (
            "STROKE_ORDER",
            with(fk(), "/design/actuators/0/stroke_m", json!([0.2, -0.7])),
            "/design/actuators/0/stroke_m",
        ),
        (
            "UNKNOWN_ACTUATOR",
            with(fk(), "/design/rods/2/actuator", json!(2)),
            "/design/rods/2/actuator",
        ),
        (
            "ACTUATOR_WITHOUT_ROD",
            three_actuators,
            "/design/actuators/2",
        ),
        (
            "ROD_STIFFNESS",
            without(fk(), "/design/rods/0", "diameter_m"),
            "/design/rods/0/diameter_m",
        ),
        (
            "SLENDERNESS",
            with(fk(), "/design/rods/1/diameter_m", json!(0.2)),
            "/design/rods/1/diameter_m",
        ),
        ("COINCIDENT_ATTACHMENTS", coincident, "/design/rods"),
        (
            "HOME_INPUTS_COUNT",
            with(fk(), "/design/home_inputs_m", json!([-0.25])),
            "/design/home_inputs_m",
        ),
        (
            "HOME_NOT_STRESS_FREE",
            with(fk(), "/design/home_inputs_m", json!([-0.25, 0.3])),
            "/design/home_inputs_m",
        ),
        (
            "EXTENSIBILITY_NEEDS_DIAMETER",
            stiffness_only,
            "/solver/axial_extensibility",
        ),
        (
            "LOAD_LIMIT",
            with(fk(), "/load/force_n", json!([0.0, -1.1e5])),
            "/load/force_n",
        ),
        (
            "LOAD_LIMIT",
            with(fk(), "/load/moment_nm", json!(1e5)),
            "/load/moment_nm",
        ),
        (
            "INPUTS_REQUIRED",
            without(fk(), "", "inputs_m"),
            "/inputs_m",
        ),
        (
            "INPUTS_COUNT",
            with(fk(), "/inputs_m", json!([-0.15])),
            "/inputs_m",
        ),
        (
            "INPUT_OUTSIDE_STROKE",
            with(fk(), "/inputs_m/1", json!(0.75)),
            "/inputs_m/1",
        ),
        (
            "STATE_REQUIRED",
            with(fk(), "/start", json!({"kind": "guess"})),
            "/start/state",
        ),
        (
            "STATE_LENGTH",
            with(
                fk(),
                "/start",
                json!({"kind": "guess", "state": {"v": [0.0, 1.0]}}),
            ),
            "/start/state/v",
        ),
        (
            "STATE_REQUIRED",
            sweep(json!({"grid": [5, 5], "seed": {"kind": "guess"}})),
            "/workspace/seed/state",
        ),
        ("WORKSPACE_ACTUATORS", one_guide, "/design/actuators"),
        (
            "RANGE_ORDER",
            sweep(json!({"grid": [5, 5], "ranges_m": [[-0.7, 0.2], [0.5, 0.5]]})),
            "/workspace/ranges_m/1",
        ),
        (
            "GRID_TOO_LARGE",
            sweep(json!({"grid": [300, 300]})),
            "/workspace/grid",
        ),
        (
            "SEARCH_TOO_LARGE",
            json!({"mode": "assembly_modes", "design": {"preset": "symmetric"},
            "inputs_m": [-0.2, 0.25], "assembly_modes": {"n_grid": 6}}),
            "/assembly_modes/n_grid",
        ),
        (
            "SHARD_INDEX_BELOW_COUNT",
            json!({"mode": "workspace", "design": {"preset": "keops_d1"},
            "workspace": {"grid": [5, 5]}, "shard": {"index": 3, "count": 2}}),
            "/shard/index",
        ),
        ("SHARD_NOT_APPLICABLE", sharded_fk, "/shard"),
        (
            "ASSEMBLY_MODE_NOT_FOUND",
            json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": [-0.22, 0.2425],
            "start": {"kind": "assembly_mode", "index": 50}, "assembly_modes": {"n_grid": 3}}),
            "/start/index",
        ),
        (
            "ASSEMBLY_MODE_NOT_FOUND",
            json!({"mode": "workspace", "design": {"preset": "keops_d1"},
            "workspace": {"grid": [5, 5], "seed": {"kind": "assembly_mode", "index": 50, "inputs_m": [-0.22, 0.2425]}},
            "assembly_modes": {"n_grid": 3}}),
            "/workspace/seed/index",
        ),
    ]
}

/// Every code the operation lists under `x-cross-field-rules` is reachable: a request the
/// schema accepts (the door passes it) that breaks the rule gets a 422 with that code, pointing
/// at the field the rule names.
#[tokio::test]
async fn every_listed_cross_field_rule_is_reachable() {
    let listed: std::collections::BTreeSet<String> = mechcalc::http::openapi::document()["paths"]
        [PATH]["post"]["x-cross-field-rules"]
        .as_array()
        .expect("the operation lists its cross-field rules")
        .iter()
        .filter_map(|r| r["code"].as_str().map(str::to_owned))
        .collect();
    let mut reached = std::collections::BTreeSet::new();
    for (code, body, pointer) in cross_rule_cases() {
        let r = post_json(PATH, &body).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{body}: {p}");
        assert!(listed.contains(code), "{code} is not listed: {listed:?}");
        assert!(
            r.pointers().iter().any(|q| q == pointer),
            "{code}: {pointer} missing from {:?}",
            r.pointers()
        );
        reached.insert(code.to_owned());
    }
    // The answer-size rule needs a service with a small --max-response-bytes.
    let small = mechcalc::AppState::new(mechcalc::config::ServiceConfig {
        max_response_bytes: 20_000,
        ..common::config()
    });
    let big = json!({"mode": "workspace", "design": {"preset": "keops_d1"},
                     "workspace": {"grid": [101, 101], "return_nodes": true}});
    let r = common::post_json_to(small, PATH, &big).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "RESPONSE_TOO_LARGE", "{p}");
    assert_eq!(r.pointers(), vec!["/workspace/grid".to_owned()]);
    reached.insert("RESPONSE_TOO_LARGE".to_owned());
    let unreached: Vec<&String> = listed.difference(&reached).collect();
    assert!(
        unreached.is_empty(),
        "listed but not reached: {unreached:?}"
    );
}

/// The answer without the fields that measure time.
fn untimed(mut v: Value) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(o) => {
                o.remove("timing_ms");
                o.remove("elapsed_ms");
                o.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

/// `null` for an optional field means absent, at every depth: the fk example and a small sweep
/// with every optional field they omit sent as `null` give exactly the answers of the plain
/// requests.
#[tokio::test]
async fn null_optional_fields_read_as_absent() {
    let plain = fk_example();
    let mut nulls = plain.clone();
    for (parent, keys) in [
        (
            "",
            &["workspace", "assembly_modes", "time_limit_ms", "shard"][..],
        ),
        ("/design", &["preset", "sigma_allow_pa"][..]),
        ("/design/rods/0", &["ei_nm2"][..]),
        ("/design/rods/1", &["ei_nm2"][..]),
        ("/design/rods/2", &["ei_nm2"][..]),
        ("/solver", &["max_iter", "axial_extensibility"][..]),
        (
            "/start",
            &["state", "index", "continuation_steps", "continuation"][..],
        ),
    ] {
        let o = nulls
            .pointer_mut(parent)
            .and_then(Value::as_object_mut)
            .expect("object");
        for k in keys {
            assert!(!o.contains_key(*k), "{parent}/{k} is in the example");
            o.insert((*k).to_owned(), Value::Null);
        }
    }
    let (a, b) = (post_json(PATH, &plain).await, post_json(PATH, &nulls).await);
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
    assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
    assert_eq!(untimed(a.json()), untimed(b.json()));
    // The optional fields of a sweep and of its nested settings.
    let plain = json!({"mode": "workspace", "design": {"preset": "keops_d1"},
                       "workspace": {"grid": [6, 5], "seed": {"kind": "home"}, "jump_limits": {},
                                     "limits": {}, "return_nodes": true}});
    let nulls = json!({"mode": "workspace", "design": {"preset": "keops_d1", "actuators": null,
                       "rods": null, "home_inputs_m": null, "sigma_allow_pa": null},
                       "inputs_m": null, "load": null, "solver": null, "start": null, "outputs": null,
                       "assembly_modes": null, "time_limit_ms": null, "shard": null,
                       "workspace": {"grid": [6, 5], "ranges_m": null,
                                     "seed": {"kind": "home", "inputs_m": null, "state": null, "index": null},
                                     "neighbours": null, "predictor": null, "max_substeps": null,
                                     "max_tries": null, "substep_max_iter": null,
                                     "jump_limits": {"angle_deg": null, "position_factor": null},
                                     "cond_max": null, "stability_check": null, "stability_segments": null,
                                     "limits": {"min_actuator_gap_m": null, "sigma_allow_pa": null, "rod_crossing": null},
                                     "quasi_translational_deg": null, "area_method": null, "return_nodes": true}});
    let (a, b) = (post_json(PATH, &plain).await, post_json(PATH, &nulls).await);
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
    assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
    assert_eq!(untimed(a.json()), untimed(b.json()));
    // A required field stays required: null is a 422 naming it.
    let mut b = fk_example();
    b["design"] = Value::Null;
    post_json(PATH, &b).await.assert_422_at(&["/design"]);
}
