//! `POST /v1/spatial-coupling` over HTTP: the spec example comes back, optional groups are
//! omitted unless asked, and every kind of bad request gets its problem+json answer (422) with a
//! pointer to each offending field and the right `code`; the support-plane rule of spec §2/§7.2
//! (422 for sweeps, per-point error objects for points-only requests).

use crate::common;

use common::post_json;
use serde_json::{Value, json};

const PATH: &str = "/v1/spatial-coupling";

fn spec_example() -> Value {
    json!({"alpha_deg": 15, "a_m": 1.0, "beta_deg": 15, "omega1_rad_s": 1.0, "branch": 1,
           "theta1_deg": [30],
           "sweep": {"start_deg": 0, "end_deg": 360, "n_points": 721},
           "outputs": {"contact": true, "relative_1": true, "relative_2": true, "frames": false,
                       "summary": true, "series": false, "check": true},
           "body3_points_m": []})
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[tokio::test]
async fn answers_the_spec_example() {
    let r = post_json(PATH, &spec_example()).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    let p = &b["points"][0];
    assert!((num(&p["theta2_deg"]) - 56.309_932).abs() < 5e-7);
    assert!((num(&p["contact"]["vB_m_s"][0]) - 1.732_050_81).abs() < 5e-9);
    assert!((num(&p["relative_2"]["vx2B_m_s"]) - 1.681_345_61).abs() < 5e-9);
    assert!(num(&p["check"]["max_residual"]) < 1e-12);
    assert!(p.get("frames").is_none() && p.get("body3_points").is_none());
    assert_eq!(b["summary"]["n_points"], 721);
    assert!((num(&b["summary"]["fluctuation"]) - 0.288_675_13).abs() < 5e-9);
    assert!(b.get("series").is_none(), "series only when asked");
    assert_eq!(b["warnings"], json!([]));
    assert_eq!(b["report"]["stop_reason"], "completed");
}

#[tokio::test]
async fn optional_groups_are_omitted_unless_asked() {
    let r = post_json(PATH, &json!({"theta1_deg": [10, 20]})).await;
    assert_eq!(r.status, 200);
    let b = r.json();
    assert!(b.get("summary").is_none() && b.get("series").is_none());
    for p in b["points"].as_array().expect("points") {
        for k in [
            "contact",
            "relative_1",
            "relative_2",
            "frames",
            "body3_points",
            "check",
        ] {
            assert!(p.get(k).is_none(), "{k} present without being asked");
        }
    }
    // A series carries only the groups asked for, though the summary needs B and both motions.
    let b = post_json(
        PATH,
        &json!({"sweep": {"n_points": 5}, "outputs": {"series": true, "relative_2": true}}),
    )
    .await
    .json();
    for p in b["series"].as_array().expect("series") {
        assert!(
            p.get("contact").is_none() && p.get("relative_1").is_none(),
            "{p}"
        );
        assert!(p["relative_2"]["x2B_m"].is_number());
    }
    // Neither points nor a sweep: the default sweep's summary.
    let b = post_json(PATH, &json!({})).await.json();
    assert_eq!(b["summary"]["n_points"], 721);
    assert!(b.get("points").is_none());
}

/// Each bad field alone: 422, its pointer, and its code.
#[tokio::test]
async fn invalid_fields_point_at_themselves() {
    let cases = [
        (
            json!({"alpha_deg": 45}),
            "/alpha_deg",
            "PERPENDICULAR_SHAFTS",
        ),
        (
            json!({"alpha_deg": -45}),
            "/alpha_deg",
            "PERPENDICULAR_SHAFTS",
        ),
        (
            json!({"alpha_deg": 45.000_000_01}),
            "/alpha_deg",
            "PERPENDICULAR_SHAFTS",
        ),
        (json!({"alpha_deg": 90}), "/alpha_deg", "INVALID_INPUT"),
        (json!({"alpha_deg": -90.5}), "/alpha_deg", "INVALID_INPUT"),
        (json!({"a_m": 0}), "/a_m", "INVALID_INPUT"),
        (json!({"a_m": -1.0}), "/a_m", "INVALID_INPUT"),
        (json!({"a_m": 2e6}), "/a_m", "INVALID_INPUT"),
        (json!({"beta_deg": -90}), "/beta_deg", "INVALID_INPUT"),
        (json!({"beta_deg": 90.001}), "/beta_deg", "INVALID_INPUT"),
        (
            json!({"omega1_rad_s": 1e7}),
            "/omega1_rad_s",
            "INVALID_INPUT",
        ),
        (
            json!({"sweep": {"n_points": 1}}),
            "/sweep/n_points",
            "INVALID_INPUT",
        ),
        (
            json!({"sweep": {"n_points": 1_000_001}}),
            "/sweep/n_points",
            "INVALID_INPUT",
        ),
        (
            json!({"outputs": {"decimate": 0}}),
            "/outputs/decimate",
            "INVALID_INPUT",
        ),
        (
            json!({"body3_points_m": [[0, 0, 0], [0, 2e6, 0]]}),
            "/body3_points_m/1/1",
            "INVALID_INPUT",
        ),
        (
            json!({"time_limit_ms": 0}),
            "/time_limit_ms",
            "INVALID_INPUT",
        ),
    ];
    for (body, pointer, code) in cases {
        let r = post_json(PATH, &body).await;
        let p = r.problem(422);
        assert_eq!(p["type"], "/problems/invalid-input", "{body}: {p}");
        assert_eq!(p["code"], code, "{body}: {p}");
        assert_eq!(r.pointers(), vec![pointer.to_owned()], "{body}");
    }
}

/// Several bad fields at once: one 422 listing each.
#[tokio::test]
async fn every_bad_field_is_listed() {
    // The per-field rules are checked at the door, all listed together; |cos 2α| ≥ 1e-9 is a
    // rule of the operation (a hole in α's range), checked once the fields are valid.
    let r = post_json(
        PATH,
        &json!({"alpha_deg": 44, "a_m": -1, "beta_deg": 100, "sweep": {"n_points": 0}}),
    )
    .await;
    r.problem(422);
    let mut got = r.pointers();
    got.sort();
    assert_eq!(got, ["/a_m", "/beta_deg", "/sweep/n_points"]);
    let r = post_json(PATH, &json!({"alpha_deg": 45, "sweep": {"n_points": 5}})).await;
    r.problem(422);
    assert_eq!(r.pointers(), ["/alpha_deg"]);
}

/// Decode errors: wrong branch, wrong types, unknown members.
#[tokio::test]
async fn shape_errors_point_at_the_field() {
    for (body, pointer) in [
        (json!({"branch": 2}), "/branch"),
        (json!({"branch": 0}), "/branch"),
        (json!({"theta1_deg": 30}), "/theta1_deg"),
        (json!({"sweep": {"n_points": -3}}), "/sweep/n_points"),
        (json!({"outputs": {"contacts": true}}), "/outputs/contacts"),
        (json!({"alpha": 15}), "/alpha"),
        (json!({"body3_points_m": [[0, 0]]}), "/body3_points_m/0"),
    ] {
        let r = post_json(PATH, &body).await;
        r.problem(422);
        assert!(
            r.pointers().iter().any(|p| p.starts_with(pointer)),
            "{body}: pointers {:?}",
            r.pointers()
        );
    }
}

/// Spec §2 / §7.2: with cos(α−β)·cos 2α·cos(α+β) ≤ 0 a sweep is refused (422, the roots of D
/// named), a points-only request answers 200 with an error object where D = 0 and numbers
/// elsewhere. α = 0, β = 60: D(0) = cos 60°, D(90°) = cos 60°: valid; α = 15, β = 80: D(0) =
/// cos(−65°)·cos 30° > 0, D(90°) = cos 95° < 0: invalid, root at θ1 = atan(√(D0/|D90|)).
#[tokio::test]
async fn invalid_support_plane_sweep_is_refused_points_answer_per_point() {
    let r = post_json(PATH, &json!({"alpha_deg": 15, "beta_deg": 80, "sweep": {}})).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/infeasible", "{p}");
    assert_eq!(p["code"], "SUPPORT_PLANE_INVALID");
    assert_eq!(r.pointers(), ["/beta_deg"]);
    let (d0, d90) = (
        65f64.to_radians().cos() * 30f64.to_radians().cos(),
        95f64.to_radians().cos(),
    );
    let root = (d0 / d90.abs()).sqrt().atan().to_degrees();
    let detail = p["detail"].as_str().expect("detail");
    assert!(detail.contains(&format!("[{}.", root.trunc())), "{detail}");
    // Points only: the exact root gives an error object, its neighbours numbers.
    let b = post_json(
        PATH,
        &json!({"alpha_deg": 15, "beta_deg": 80, "theta1_deg": [root, 10.0, 180.0 - root],
                "outputs": {"contact": true}}),
    )
    .await;
    assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
    let v = b.json();
    assert!(
        !v["configuration"]["support_plane"]["valid"]
            .as_bool()
            .expect("bool")
    );
    let roots = v["configuration"]["support_plane"]["d_roots_theta1_deg"]
        .as_array()
        .expect("roots");
    assert_eq!(roots.len(), 4);
    assert!((num(&roots[0]) - root).abs() < 1e-12);
    let pts = v["points"].as_array().expect("points");
    assert_eq!(pts[0]["error"]["code"], "CONTACT_AT_INFINITY", "{}", pts[0]);
    assert!(pts[1]["contact"]["rB_m"][0].is_number(), "{}", pts[1]);
    assert_eq!(pts[2]["error"]["code"], "CONTACT_AT_INFINITY", "{}", pts[2]);
    assert!(
        v["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .any(|w| w["code"] == "SUPPORT_PLANE_INVALID")
    );
    // A request with both points and a sweep follows the sweep rule (422).
    let r = post_json(
        PATH,
        &json!({"alpha_deg": 15, "beta_deg": 80, "theta1_deg": [10], "sweep": {}}),
    )
    .await;
    assert_eq!(r.problem(422)["code"], "SUPPORT_PLANE_INVALID");
}

#[tokio::test]
async fn warnings_name_the_hazard() {
    let b = post_json(
        PATH,
        &json!({"alpha_deg": 44, "beta_deg": 0, "theta1_deg": [0]}),
    )
    .await
    .json();
    let codes = common::warning_codes(&b);
    assert!(codes.contains(&"NEAR_PERPENDICULAR_SHAFTS"), "{codes:?}");
    // β close to α − 90°: D(0) = cos(α−β)·cos 2α nearly 0, valid but ill-conditioned.
    let b = post_json(
        PATH,
        &json!({"alpha_deg": 15, "beta_deg": -74.99, "sweep": {"n_points": 33}}),
    )
    .await;
    assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
    let codes: Vec<String> = b.json()["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .filter_map(|w| w["code"].as_str().map(str::to_owned))
        .collect();
    assert!(
        codes.iter().any(|c| c == "CONTACT_ILL_CONDITIONED"),
        "{codes:?}"
    );
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
    let cases = [
        (
            "PERPENDICULAR_SHAFTS",
            "/alpha_deg",
            json!({"alpha_deg": 45}),
        ),
        (
            "SUPPORT_PLANE_INVALID",
            "/beta_deg",
            json!({"alpha_deg": 15, "beta_deg": 80, "sweep": {"n_points": 5}}),
        ),
    ];
    for (code, pointer, body) in cases {
        assert!(
            codes.iter().any(|c| c == code),
            "{code} is not listed: {codes:?}"
        );
        let r = post_json(PATH, &body).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{body}: {p}");
        assert!(
            r.pointers().iter().any(|q| q == pointer),
            "{code}: expected pointer {pointer}, got {p}"
        );
    }
    for code in ["DEADLINE_EXCEEDED", "RESPONSE_TOO_LARGE"] {
        assert!(codes.iter().any(|c| c == code), "{code}: {codes:?}");
    }
}

/// An answer without its timing fields (the report's `elapsed_ms`).
fn untimed(mut v: Value) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                m.retain(|k, _| k != "elapsed_ms");
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
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("api/spatial_coupling/paper_case.json");
    let plain: Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json");
    let mut nulls = plain.clone();
    nulls["time_limit_ms"] = Value::Null;
    nulls["outputs"]["decimate"] = Value::Null;
    // Every optional field null at every depth, against the same fields absent.
    let every = json!({"alpha_deg": null, "a_m": null, "beta_deg": null, "omega1_rad_s": null,
        "branch": null, "theta1_deg": null, "body3_points_m": null, "time_limit_ms": null,
        "sweep": {"start_deg": null, "end_deg": null, "n_points": null},
        "outputs": {"contact": null, "relative_1": null, "relative_2": null, "frames": null,
                    "summary": null, "series": null, "decimate": null, "check": null}});
    let absent = json!({"sweep": {}, "outputs": {}});
    let top = json!({"outputs": null, "sweep": null, "theta1_deg": [30, 60]});
    let top_absent = json!({"theta1_deg": [30, 60]});
    for (a, b) in [(plain, nulls), (absent, every), (top_absent, top)] {
        let ra = post_json(PATH, &a).await;
        assert_eq!(ra.status, 200, "{}", String::from_utf8_lossy(&ra.bytes));
        let rb = post_json(PATH, &b).await;
        assert_eq!(
            rb.status,
            200,
            "{b}: {}",
            String::from_utf8_lossy(&rb.bytes)
        );
        assert_eq!(untimed(ra.json()), untimed(rb.json()), "{b}");
    }
}
