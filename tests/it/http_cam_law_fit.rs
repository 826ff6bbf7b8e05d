//! `POST /v1/fit-cam-law` over HTTP: the Table-1 example is identified, every kind of bad request
//! gets the right problem+json answer with pointers to the offending fields, and a spent budget
//! returns the best-so-far with an honest `stop_reason`.

use crate::common;

use common::post_json;
use serde_json::{Value, json};

const PATH: &str = "/v1/fit-cam-law";

/// The spec §8 request with the full 300 samples (api/cam_law_fit/table1.json).
fn table1() -> Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cam_law_fit/table1.json");
    serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json")
}

/// A small valid request: 3-4-5 displacement on 12 samples.
fn small() -> Value {
    let xs: Vec<f64> = (0..12).map(|k| f64::from(k) / 11.0).collect();
    let s: Vec<f64> = xs
        .iter()
        .map(|x| x * x * x * (10.0 - 15.0 * x + 6.0 * x * x))
        .collect();
    json!({
        "abscissa": {"values": xs},
        "channels": {"displacement": s},
        "fit_on": "displacement"
    })
}

async fn expect_422(body: &Value, pointer: &str) -> Value {
    let r = post_json(PATH, body).await;
    let p = r.problem(422);
    assert!(
        r.pointers().iter().any(|q| q == pointer),
        "expected pointer {pointer}, got {p}"
    );
    p
}

#[tokio::test]
async fn table1_example_is_identified() {
    let r = post_json(PATH, &table1()).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    let c: Vec<f64> = b["coefficients"]
        .as_array()
        .expect("coefficients")
        .iter()
        .map(|v| v.as_f64().expect("number"))
        .collect();
    let truth = [2.0, 4.0, 6.0, 3.0, 8.0, 7.0, 1.0].map(|v| v / 31.0);
    for (a, t) in c.iter().zip(truth) {
        assert!((a - t).abs() < 1e-8, "{c:?}");
    }
    assert_eq!(b["optimizer_report"]["stop_reason"], "converged");
    assert_eq!(b["knots"].as_array().map(Vec::len), Some(8));
    assert!(b["error_table"]["acceleration"]["dtw"].is_number());
    assert!(b.get("curves").is_none() && b.get("history").is_none());
    assert_eq!(b["objective"]["dtw_window"], Value::Null);
}

#[tokio::test]
async fn optional_outputs_only_when_requested() {
    let mut b = small();
    b["outputs"] = json!({"curves": {"count": 5, "quantities": ["a", "j"]}, "history": true,
                          "error_table": false, "classify": false});
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let j = r.json();
    assert_eq!(j["curves"]["x"].as_array().map(Vec::len), Some(5));
    assert!(j["curves"]["a"].is_array() && j["curves"]["j"].is_array());
    assert!(j["curves"].get("s").is_none());
    assert!(j["history"].is_array());
    assert!(j.get("error_table").is_none() && j.get("classification").is_none());
}

#[tokio::test]
async fn decode_errors_point_at_the_field() {
    let mut b = small();
    b["optimizer"] = json!({"method": "simplex"});
    expect_422(&b, "/optimizer/method").await;
    let mut b = small();
    b["objective"] = json!({"metric": "euclidean", "windw": 3});
    expect_422(&b, "/objective/windw").await;
}

#[tokio::test]
async fn sample_problems_are_422_with_pointers() {
    // Lengths differ.
    let mut b = small();
    b["channels"]["displacement"] = json!([0.0, 0.5, 1.0]);
    expect_422(&b, "/channels/displacement").await;
    // N < 8.
    let b = json!({"abscissa": {"values": [0.0, 0.5, 1.0]}, "channels": {"displacement": [0.0, 0.5, 1.0]},
                   "fit_on": "displacement"});
    expect_422(&b, "/abscissa/values").await;
    // Not strictly increasing: the offending index.
    let mut b = small();
    b["abscissa"]["values"][4] = json!(0.1);
    expect_422(&b, "/abscissa/values/4").await;
    // Unit label over 32 characters (shared check with /v1/cam-law/evaluate).
    let mut b = small();
    b["units"] = json!({"x": "s", "s": "r".repeat(33)});
    expect_422(&b, "/units/s").await;
    // Grid too small.
    let mut b = small();
    b["abscissa"] = json!({"grid": {"start": 0.0, "end": 1.0, "count": 5}});
    expect_422(&b, "/abscissa/grid/count").await;
    // Both abscissa forms.
    let mut b = small();
    b["abscissa"]["grid"] = json!({"start": 0.0, "end": 1.0, "count": 12});
    expect_422(&b, "/abscissa").await;
    // Sample outside [t_a, t_b].
    let mut b = small();
    b["constraints"] = json!({"t_a": 0.0, "t_b": 0.9});
    let p = expect_422(&b, "/abscissa/values/10").await;
    assert!(p.to_string().contains("outside"), "{p}");
    // Magnitude beyond 1e12.
    let mut b = small();
    b["channels"]["displacement"][3] = json!(1e13);
    expect_422(&b, "/channels/displacement/3").await;
}

#[tokio::test]
async fn constraint_and_option_problems_are_all_listed() {
    // The per-field rules are checked at the door and all listed together, before any rule
    // between fields runs.
    let mut b = small();
    b["optimizer"] = json!({"max_evaluations": 0, "time_limit_ms": 700000,
                            "snap_tol": 0.1, "dtw_global_restarts": 10, "ga": {"p_crossover": 1.5}});
    b["initial_coefficients"] = json!([0.1, 0.1, -0.1, 0.1, 0.1, 0.1, 0.1]);
    b["outputs"] = json!({"curves": {"count": 100001}});
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    let ptrs = r.pointers();
    for want in [
        "/optimizer/max_evaluations",
        "/optimizer/time_limit_ms",
        "/optimizer/snap_tol",
        "/optimizer/dtw_global_restarts",
        "/optimizer/ga/p_crossover",
        "/initial_coefficients/2",
        "/outputs/curves/count",
    ] {
        assert!(ptrs.iter().any(|q| q == want), "{want} missing in {p}");
    }
    // A schema-valid request breaking three rules between fields gets all three listed.
    let mut b = small();
    b["constraints"] = json!({"t_a": 1.0, "t_b": 0.5});
    b["objective"] = json!({"metric": "dtw", "dtw_window": 13});
    b["optimizer"] = json!({"method": "lsq"});
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    let ptrs = r.pointers();
    for want in [
        "/constraints/t_b",
        "/objective/dtw_window",
        "/optimizer/method",
    ] {
        assert!(ptrs.iter().any(|q| q == want), "{want} missing in {p}");
    }
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
    let with = |f: &dyn Fn(&mut Value)| {
        let mut b = small();
        f(&mut b);
        b
    };
    let xs = small()["abscissa"]["values"].clone();
    let s = small()["channels"]["displacement"].clone();
    let cases: Vec<(&str, &str, Value)> = vec![
        (
            "ABSCISSA_ORDER",
            "/abscissa/values/4",
            with(&|b| b["abscissa"]["values"][4] = json!(0.1)),
        ),
        (
            "ABSCISSA_ORDER",
            "/abscissa/grid/end",
            with(&|b| b["abscissa"] = json!({"grid": {"start": 1.0, "end": 0.0, "count": 12}})),
        ),
        (
            "NO_CHANNEL",
            "/channels",
            with(&|b| b["channels"] = json!({})),
        ),
        (
            "CHANNEL_LENGTH",
            "/channels/displacement",
            with(&|b| b["channels"]["displacement"] = json!([0.0, 0.5, 1.0])),
        ),
        (
            "FIT_CHANNEL_MISSING",
            "/fit_on",
            with(&|b| b["fit_on"] = json!("velocity")),
        ),
        (
            "END_DISPLACEMENT_REQUIRED",
            "/constraints/s_a",
            json!({"abscissa": {"values": xs}, "channels": {"velocity": s}, "fit_on": "velocity"}),
        ),
        (
            "SEGMENT_INTERVAL",
            "/constraints/t_b",
            with(&|b| b["constraints"] = json!({"t_a": 1.0, "t_b": 0.5})),
        ),
        (
            "ABSCISSA_OUTSIDE",
            "/abscissa/values/10",
            with(&|b| b["constraints"] = json!({"t_a": 0.0, "t_b": 0.9})),
        ),
        (
            "DTW_WINDOW_SAMPLES",
            "/objective/dtw_window",
            with(&|b| b["objective"] = json!({"metric": "dtw", "dtw_window": 13})),
        ),
        (
            "METHOD_METRIC",
            "/optimizer/method",
            with(&|b| {
                b["objective"] = json!({"metric": "dtw"});
                b["optimizer"] = json!({"method": "lsq"});
            }),
        ),
        (
            "INITIAL_EXCLUSIVE",
            "/initial_law",
            with(&|b| {
                b["initial_law"] = json!("cycloidal");
                b["initial_coefficients"] = json!([1, 1, 1, 1, 1, 1, 1]);
            }),
        ),
        (
            "INITIAL_LAW_CLASS",
            "/initial_law",
            with(&|b| b["initial_law"] = json!("polynomial_345")),
        ),
        (
            "EMPTY_PULSE",
            "/fixed_zero",
            with(&|b| b["fixed_zero"] = json!([true, true, true, false, false, false, false])),
        ),
        ("FIT_TOO_EXPENSIVE", "/optimizer/max_evaluations", {
            let mut b = table1();
            b["objective"] = json!({"metric": "dtw", "dtw_window": 300});
            b["optimizer"]["max_evaluations"] = json!(10_000_000);
            b
        }),
        (
            "INFEASIBLE_CONSTRAINTS",
            "/constraints",
            json!({
                "abscissa": {"values": (0..8).map(|k| f64::from(k) * 1e-300 / 7.0).collect::<Vec<_>>()},
                "channels": {"velocity": [0.0, 1.0, 2.0, 3.0, 3.0, 2.0, 1.0, 0.0]},
                "fit_on": "velocity",
                "constraints": {"s_a": 0.0, "s_b": 1e12}
            }),
        ),
    ];
    for (code, pointer, body) in cases {
        assert!(
            codes.iter().any(|c| c == code),
            "{code} is not listed: {codes:?}"
        );
        let r = post_json(PATH, &body).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{p}");
        assert!(
            r.pointers().iter().any(|q| q == pointer),
            "{code}: expected pointer {pointer}, got {p}"
        );
    }
}

/// An answer without its timing fields (`optimizer_report.cpu_ms`, `wall_ms`).
fn untimed(mut v: Value) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                m.retain(|k, _| !["cpu_ms", "wall_ms", "elapsed_ms"].contains(&k.as_str()));
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
    let plain = table1();
    let mut nulls = table1();
    for k in [
        "derive_missing",
        "initial_coefficients",
        "initial_law",
        "fixed_zero",
        "time_limit_ms",
    ] {
        nulls[k] = Value::Null;
    }
    nulls["abscissa"]["values"] = Value::Null;
    nulls["channels"]["displacement"] = Value::Null;
    nulls["channels"]["velocity"] = Value::Null;
    nulls["objective"]["dtw_window"] = Value::Null;
    for k in ["ga", "dtw_global_restarts", "polish", "snap_tol"] {
        nulls["optimizer"][k] = Value::Null;
    }
    nulls["outputs"]["curves"]["quantities"] = Value::Null;
    let a = post_json(PATH, &plain).await;
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
    let b = post_json(PATH, &nulls).await;
    assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
    assert_eq!(untimed(a.json()), untimed(b.json()));
    // Every optional field of a nested object null (GA settings, constraints, curves), and
    // every optional object itself null: the defaults, as when absent.
    let mut inner = small();
    inner["optimizer"] = json!({"method": null, "seed": null, "max_evaluations": null,
        "time_limit_ms": null, "dtw_global_restarts": null, "polish": null, "snap_tol": null,
        "ga": {"population": null, "generations": null, "p_crossover": null, "p_inversion": null,
               "p_range_mutation": null, "range0": null, "range_factor": null, "range_every": null,
               "p_mutation": null, "stall_generations": null}});
    inner["constraints"] = json!({"t_a": null, "t_b": null, "s_a": null, "s_b": null,
        "v_a": null, "v_b": null, "a_a": null, "a_b": null});
    inner["objective"] = json!({"metric": null, "dtw_window": null});
    inner["outputs"] = json!({"curves": {"count": null, "quantities": null}, "error_table": null,
        "history": null, "classify": null});
    inner["units"] = json!({"x": null, "s": null});
    let mut top = small();
    for k in ["constraints", "objective", "optimizer", "outputs", "units"] {
        top[k] = Value::Null;
    }
    // (Unit labels are echoed: the baseline of `units: {x: null, s: null}` is `units: {}`.)
    let mut with_units = small();
    with_units["units"] = json!({});
    for (plain, body) in [(with_units, inner), (small(), top)] {
        let a = post_json(PATH, &plain).await;
        assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
        let b = post_json(PATH, &body).await;
        assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
        assert_eq!(untimed(a.json()), untimed(b.json()));
    }
}

#[tokio::test]
async fn missing_channel_and_derivation_rules() {
    // fit_on channel absent, derive_missing false: says what to change.
    let mut b = small();
    b["fit_on"] = json!("acceleration");
    let p = expect_422(&b, "/fit_on").await;
    assert!(p.to_string().contains("derive_missing"), "{p}");
    // Derivation would need integration.
    let mut b = small();
    b["channels"] = json!({"acceleration": b["channels"]["displacement"].clone()});
    b["fit_on"] = json!("displacement");
    b["derive_missing"] = json!(true);
    let p = expect_422(&b, "/fit_on").await;
    assert!(p.to_string().contains("integration"), "{p}");
    // s_a/s_b required without displacement.
    let mut b = small();
    b["channels"] = json!({"velocity": b["channels"]["displacement"].clone()});
    b["fit_on"] = json!("velocity");
    expect_422(&b, "/constraints/s_a").await;
    // With derive_missing, a is derived from s and the fit succeeds with a warning.
    let mut b = small();
    b["fit_on"] = json!("acceleration");
    b["derive_missing"] = json!(true);
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert!(
        r.json()["warnings"]
            .to_string()
            .contains("derived_channel_noise_gain")
    );
}

#[tokio::test]
async fn empty_pulses_are_422() {
    let mut b = small();
    b["initial_coefficients"] = json!([0.0, 0.0, 0.0, 0.5, 0.2, 0.2, 0.1]);
    let p = expect_422(&b, "/initial_coefficients").await;
    assert!(p.to_string().contains("first acceleration pulse"), "{p}");
    let mut b = small();
    b["fixed_zero"] = json!([false, false, false, false, true, true, true]);
    let p = expect_422(&b, "/fixed_zero").await;
    assert!(p.to_string().contains("second acceleration pulse"), "{p}");
    let mut b = small();
    b["initial_law"] = json!("polynomial_345");
    expect_422(&b, "/initial_law").await;
}

#[tokio::test]
async fn too_expensive_request_is_422_too_large() {
    let mut b = table1();
    b["objective"] = json!({"metric": "dtw", "dtw_window": 300});
    b["optimizer"]["max_evaluations"] = json!(10_000_000);
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/too-large");
    assert_eq!(r.pointers(), vec!["/optimizer/max_evaluations"]);
    assert!(
        p["detail"]
            .as_str()
            .is_some_and(|d| d.contains("lower max_evaluations")),
        "{p}"
    );
}

#[tokio::test]
async fn end_conditions_no_law_can_meet_are_422_infeasible() {
    // A rise of 1e12 over Δt = 1e-300 (with a matching grid): every law's peaks overflow f64.
    let xs: Vec<f64> = (0..8).map(|k| f64::from(k) * 1e-300 / 7.0).collect();
    let b = json!({
        "abscissa": {"values": xs},
        "channels": {"velocity": [0.0, 1.0, 2.0, 3.0, 3.0, 2.0, 1.0, 0.0]},
        "fit_on": "velocity",
        "constraints": {"s_a": 0.0, "s_b": 1e12}
    });
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/infeasible");
    assert_eq!(r.pointers(), vec!["/constraints"]);
    assert!(p.to_string().contains("widen"), "{p}");
}

#[tokio::test]
async fn one_evaluation_budget_returns_the_initial_law_with_max_evaluations() {
    let mut b = table1();
    b["optimizer"]["max_evaluations"] = json!(1);
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let j = r.json();
    assert_eq!(j["optimizer_report"]["stop_reason"], "max_evaluations");
    assert_eq!(j["optimizer_report"]["evaluations"], 1);
    assert!(j["warnings"].to_string().contains("budget_exhausted"));
    // Only the initial law was evaluated: the answer is that law (to round-off of the
    // renormalization).
    let (fi, ff) = (
        j["objective"]["initial"].as_f64().expect("initial"),
        j["objective"]["final"].as_f64().expect("final"),
    );
    assert!(ff <= fi && fi - ff <= 1e-12 * fi, "{fi} vs {ff}");
}

#[tokio::test]
async fn one_millisecond_budget_returns_best_so_far_with_deadline() {
    let mut b = table1();
    b["optimizer"] = json!({"method": "ga", "time_limit_ms": 1, "seed": 3});
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let j = r.json();
    assert_eq!(j["optimizer_report"]["stop_reason"], "deadline");
    assert!(j["warnings"].to_string().contains("budget_exhausted"));
    assert!(j["objective"]["final"].as_f64() <= j["objective"]["initial"].as_f64());
    assert!(j["optimizer_report"]["evaluations"].as_u64() < Some(49_600));
}

#[tokio::test]
async fn missing_required_members_are_422() {
    let r = post_json(PATH, &json!({})).await;
    r.assert_422_at(&["/abscissa"]);
    let r = post_json(
        PATH,
        &json!({"abscissa": {"grid": {"start": 0.0, "end": 1.0, "count": 12}}}),
    )
    .await;
    r.assert_422_at(&["/channels"]);
    let r = post_json(
        PATH,
        &json!({"abscissa": {"grid": {"start": 0.0, "end": 1.0, "count": 12}},
                                    "channels": {}}),
    )
    .await;
    r.assert_422_at(&["/channels"]);
}
