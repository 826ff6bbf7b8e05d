//! `POST /v1/cognates` over HTTP: the spec example comes back, and every kind of bad request gets
//! the right problem+json answer (400/415/422) with a pointer to the offending field and the
//! spec's `code`.

use crate::common;

use common::post_json;
use serde_json::{Value, json};

const PATH: &str = "/v1/cognates";

fn table1() -> Value {
    json!({
        "ground": {"A": [0, 0], "B": [3.10, 0]},
        "crank": 1.13, "coupler": 1.23, "rocker": 1.04,
        "coupler_point": {"d": 0.92, "e": 1.56, "side": 1},
        "input_angle_deg": 30.0, "branch": 1
    })
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

#[tokio::test]
async fn constructs_the_spec_example() {
    let mut body = table1();
    body["options"] =
        json!({"curves": true, "points_per_circuit": 360, "verify": ["sync", "implicit"]});
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    assert!((num(&b["C"][0]) + 0.076122).abs() < 5e-7);
    assert!((num(&b["C"][1]) - 2.317449).abs() < 5e-7);
    let m = b["mechanisms"].as_array().expect("mechanisms");
    assert_eq!(m.len(), 3);
    assert_eq!(m[1]["id"], "cognate1");
    assert_eq!(m[2]["snapshot"]["branch"], -1);
    assert_eq!(m[0]["curves"].as_array().map(Vec::len), Some(1));
    assert_eq!(b["verification"]["sync"]["passed"], true);
    assert_eq!(b["meta"]["points_total"], 1080);
    assert!(
        m[0]["grashof"].get("special").is_none(),
        "absent optionals are omitted"
    );
}

#[tokio::test]
async fn optional_outputs_are_omitted_unless_asked() {
    let r = post_json(PATH, &table1()).await;
    assert_eq!(r.status, 200);
    let b = r.json();
    assert!(b.get("verification").is_none() && b.get("geared_fivebars").is_none());
    for m in b["mechanisms"].as_array().expect("mechanisms") {
        assert!(m.get("curves").is_none() && m.get("metrics").is_none());
    }
}

/// Shape errors are decode errors (the service answers data errors with 422 and serde's path).
#[tokio::test]
async fn shape_errors_point_at_the_field() {
    let cases = [
        ("/branch", json!({"branch": 2})),
        (
            "/options/spacing",
            json!({"options": {"spacing": "cosine"}}),
        ),
        (
            "/coupler_point",
            json!({"coupler_point": {"d": 0.92, "e": 1.56, "u": 0.3}}),
        ),
        ("/crank", json!({"crank": "long"})),
        ("/rockr", json!({"rockr": 1.0})),
    ];
    for (pointer, patch) in cases {
        let mut b = table1();
        for (k, v) in patch.as_object().expect("object") {
            b[k] = v.clone();
        }
        let r = post_json(PATH, &b).await;
        r.problem(422);
        assert_eq!(r.pointers(), vec![pointer.to_string()], "{patch}");
    }
}

#[tokio::test]
async fn invalid_lengths_are_all_listed_with_the_spec_code() {
    let mut b = table1();
    b["crank"] = json!(-1.0);
    b["rocker"] = json!(0.0);
    b["coupler_point"] = json!({"d": -0.5, "e": 1.56});
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    assert_eq!(p["code"], "NON_POSITIVE_LENGTH");
    assert_eq!(r.pointers(), vec!["/crank", "/rocker", "/coupler_point/d"]);
}

#[tokio::test]
async fn geometric_rejections_have_their_codes() {
    let cases = [
        (
            "COINCIDENT_PIVOTS",
            "/problems/invalid-input",
            json!({"ground": {"B": [0, 0]}}),
        ),
        (
            "COUPLER_TRIANGLE_INVALID",
            "/problems/invalid-input",
            json!({"coupler_point": {"d": 0.1, "e": 1.56}}),
        ),
        (
            "COUPLER_POINT_AT_JOINT",
            "/problems/invalid-input",
            json!({"coupler_point": {"u": 0.0, "v": 0.0}}),
        ),
        (
            "NOT_ASSEMBLABLE",
            "/problems/infeasible",
            json!({"ground": {"B": [10, 0]}}),
        ),
        (
            "TOO_MANY_POINTS",
            "/problems/too-large",
            json!({"options": {"curves": true, "curve_mode": "fixed_branch", "points_per_circuit": 100000, "verify": ["sync"], "metrics": true},
                   "ground": {"B": [4, 0]}, "crank": 3.0, "coupler": 1.0, "rocker": 3.5,
                   "coupler_point": {"d": 0.8, "e": 0.6}}),
        ),
    ];
    for (code, type_uri, patch) in cases {
        let mut b = table1();
        for (k, v) in patch.as_object().expect("object") {
            b[k] = v.clone();
        }
        let r = post_json(PATH, &b).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{p}");
        assert_eq!(p["type"], type_uri, "{p}");
    }
}

#[tokio::test]
async fn input_angle_outside_the_range_is_not_an_error() {
    let mut b = table1();
    b["input_angle_deg"] = json!(120.0);
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200);
    let v = r.json();
    assert_eq!(v["mechanisms"][0]["snapshot"]["status"], "not_assemblable");
    assert!(v["mechanisms"][0]["snapshot"].get("joints").is_none());
}

/// The codes the document lists under the operation's `x-cross-field-rules`.
async fn documented_cross_codes() -> Vec<String> {
    let doc = common::get("/openapi.json").await.json();
    doc["paths"][PATH]["post"]["x-cross-field-rules"]
        .as_array()
        .expect("x-cross-field-rules listed")
        .iter()
        .map(|r| r["code"].as_str().expect("code").to_owned())
        .collect()
}

#[tokio::test]
async fn every_rule_between_fields_is_listed_and_reachable() {
    let codes = documented_cross_codes().await;
    let joints =
        json!({"A": [0, 0], "B": [3.1, 0], "D": [1.0, 0.5], "E": [2.5, 1.0], "P": [1.5, 1.5]});
    let cases = [
        ("JOINTS_EXCLUSIVE", "/ground", json!({"joints": joints})),
        ("DIMENSIONS_REQUIRED", "/crank", json!({"crank": null})),
        (
            "GROUND_B_OR_LENGTH",
            "/ground/length",
            json!({"ground": {"B": [3.1, 0], "length": 3.1}}),
        ),
        (
            "GROUND_ANGLE_WITH_LENGTH",
            "/ground/angle_deg",
            json!({"ground": {"B": [3.1, 0], "angle_deg": 10.0}}),
        ),
        (
            "COINCIDENT_PIVOTS",
            "/ground/B",
            json!({"ground": {"B": [0, 0]}}),
        ),
        ("NON_POSITIVE_LENGTH", "/crank", json!({"crank": 1e-13})),
        (
            "COUPLER_TRIANGLE_INVALID",
            "/coupler_point",
            json!({"coupler_point": {"d": 0.1, "e": 1.56}}),
        ),
        (
            "COUPLER_POINT_AT_JOINT",
            "/coupler_point",
            json!({"coupler_point": {"u": 0.0, "v": 0.0}}),
        ),
    ];
    for (code, pointer, patch) in cases {
        assert!(
            codes.iter().any(|c| c == code),
            "{code} is not listed: {codes:?}"
        );
        let mut b = table1();
        for (k, v) in patch.as_object().expect("object") {
            b[k] = v.clone();
        }
        let r = post_json(PATH, &b).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{p}");
        assert!(
            r.pointers().iter().any(|q| q == pointer),
            "{code}: expected pointer {pointer}, got {p}"
        );
    }
    // The failures found while computing (geometric_rejections_have_their_codes reaches them).
    for code in [
        "NOT_ASSEMBLABLE",
        "TOO_MANY_POINTS",
        "DEADLINE_EXCEEDED",
        "RESPONSE_TOO_LARGE",
    ] {
        assert!(
            codes.iter().any(|c| c == code),
            "{code} is not listed: {codes:?}"
        );
    }
}

/// An answer without its timing fields (`meta.compute_us`).
fn untimed(mut v: Value) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                m.retain(|k, _| k != "compute_us" && k != "elapsed_ms");
                m.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

#[tokio::test]
async fn null_optional_fields_answer_as_absent() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cognates/table1.json");
    let plain: Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json");
    let mut nulls = plain.clone();
    for k in ["joints", "angle_reference", "time_limit_ms"] {
        nulls[k] = Value::Null;
    }
    nulls["ground"]["length"] = Value::Null;
    nulls["ground"]["angle_deg"] = Value::Null;
    for k in ["u", "v", "p", "alpha_deg"] {
        nulls["coupler_point"][k] = Value::Null;
    }
    nulls["options"]["metrics"] = Value::Null;
    nulls["options"]["grashof_rtol"] = Value::Null;
    let a = post_json(PATH, &plain).await;
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
    let b = post_json(PATH, &nulls).await;
    assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
    assert_eq!(untimed(a.json()), untimed(b.json()));
    // Every option null, the options object null, the ground's A and the coupler side null: the
    // defaults, as when absent.
    let mut every = table1();
    every["options"] = json!({"curves": null, "points_per_circuit": null, "spacing": null,
        "curve_mode": null, "verify": null, "geared_fivebars": null, "metrics": null,
        "grashof_rtol": null});
    let mut top = table1();
    top["options"] = Value::Null;
    top["branch"] = Value::Null;
    let mut no_branch = table1();
    no_branch.as_object_mut().map(|m| m.remove("branch"));
    let mut side = table1();
    side["ground"]["A"] = Value::Null;
    side["coupler_point"]["side"] = Value::Null;
    let mut no_side = table1();
    no_side["ground"].as_object_mut().map(|m| m.remove("A"));
    no_side["coupler_point"]
        .as_object_mut()
        .map(|m| m.remove("side"));
    for (plain, body) in [(table1(), every), (no_branch, top), (no_side, side)] {
        let a = post_json(PATH, &plain).await;
        assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
        let b = post_json(PATH, &body).await;
        assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
        assert_eq!(untimed(a.json()), untimed(b.json()));
    }
}
