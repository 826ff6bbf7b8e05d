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
    let mut b = small();
    b["constraints"] = json!({"t_a": 1.0, "t_b": 0.5});
    b["objective"] = json!({"metric": "dtw", "dtw_window": 13});
    b["optimizer"] = json!({"method": "lsq", "max_evaluations": 0, "time_limit_ms": 700000,
                            "snap_tol": 0.1, "dtw_global_restarts": 10, "ga": {"p_crossover": 1.5}});
    b["initial_coefficients"] = json!([0.1, 0.1, -0.1, 0.1, 0.1, 0.1, 0.1]);
    b["outputs"] = json!({"curves": {"count": 100001}});
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    let ptrs = r.pointers();
    for want in [
        "/constraints/t_b",
        "/objective/dtw_window",
        "/optimizer/method",
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
