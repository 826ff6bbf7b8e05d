//! `POST /v1/cam-law/evaluate` over HTTP: the law comes back, and every kind of bad request gets
//! the right problem+json answer with a pointer to the offending field.

use crate::common;

use std::time::Duration;

use common::{post_json, post_json_to};
use mechcalc::AppState;
use mechcalc::config::ServiceConfig;
use serde_json::{Value, json};

const PATH: &str = "/v1/cam-law/evaluate";

fn table1() -> Value {
    json!({
        "coefficients": [0.0645, 0.129, 0.1935, 0.0968, 0.2581, 0.2258, 0.0323],
        "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0, "v_a": 0.2, "v_b": 0.5, "a_a": 1.4, "a_b": 1.2},
        "abscissa": {"values": [0.0, 0.25, 0.5, 0.75, 1.0]},
        "quantities": ["s", "v", "a", "j"],
        "normalize": false
    })
}

#[tokio::test]
async fn evaluates_the_spec_example() {
    let r = post_json(PATH, &table1()).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    let s = b["curves"]["s"].as_array().expect("s curve");
    assert_eq!(s.len(), 5);
    assert!((s[0].as_f64().expect("number") - 0.0).abs() < 1e-12);
    assert!((s[4].as_f64().expect("number") - 1.0).abs() < 1e-12);
    assert_eq!(b["knots"].as_array().map(Vec::len), Some(8));
    assert!(b["peaks"]["a_max_abs"].as_f64().is_some_and(f64::is_finite));
}

#[tokio::test]
async fn named_law_is_evaluated() {
    let body = json!({
        "law": "cycloidal",
        "constraints": {"t_a": 0.0, "t_b": 2.0, "s_a": 1.0, "s_b": 3.0},
        "abscissa": {"grid": {"start": 0.0, "end": 2.0, "count": 11}},
        "quantities": ["s", "a"]
    });
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    let s = b["curves"]["s"].as_array().expect("s");
    assert_eq!(s.len(), 11);
    assert!((s[10].as_f64().expect("n") - 3.0).abs() < 1e-12);
    assert!(
        b["curves"].get("v").is_none(),
        "only the requested quantities are returned"
    );
}

#[tokio::test]
async fn wrong_type_and_unknown_field_are_422_with_pointers() {
    let mut b = table1();
    b["constraints"]["t_b"] = json!("one");
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/constraints/t_b"]);

    let mut b = table1();
    b["constraints"]["tb"] = json!(1.0);
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/constraints/tb"]);
}

#[tokio::test]
async fn every_bad_field_is_listed() {
    let mut b = table1();
    b["constraints"]["t_a"] = json!(2.0);
    b["abscissa"] = json!({"values": [0.0, 0.5, 0.25]});
    b["coefficients"] = json!([0.5, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0]);
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    let ptrs = r.pointers();
    assert!(ptrs.len() >= 2, "several problems reported: {p}");
    assert!(ptrs.iter().any(|q| q.starts_with("/constraints")), "{p}");
}

#[tokio::test]
async fn empty_pulse_is_422_on_coefficients() {
    let mut b = table1();
    b["coefficients"] = json!([0.5, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0]);
    let r = post_json(PATH, &b).await;
    r.problem(422);
    assert!(
        r.pointers().iter().any(|p| p.starts_with("/coefficients")),
        "{:?}",
        r.pointers()
    );
}

#[tokio::test]
async fn sample_outside_the_interval_is_422_on_abscissa() {
    let mut b = table1();
    b["abscissa"] = json!({"values": [0.0, 0.5, 1.5]});
    let r = post_json(PATH, &b).await;
    r.problem(422);
    assert!(
        r.pointers().iter().any(|p| p.starts_with("/abscissa")),
        "{:?}",
        r.pointers()
    );
}

#[tokio::test]
async fn coefficients_off_unit_sum_need_normalize() {
    let mut b = table1();
    b["coefficients"] = json!([0.1, 0.2, 0.2, 0.1, 0.2, 0.2, 0.05]);
    let r = post_json(PATH, &b).await;
    r.problem(422);
    assert!(r.pointers().iter().any(|p| p.starts_with("/coefficients")));
    b["normalize"] = json!(true);
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200);
    let w = r.json()["warnings"].to_string();
    assert!(w.contains("coefficients_renormalized"), "{w}");
}

#[tokio::test]
async fn both_or_neither_law_source_is_422() {
    let mut b = table1();
    b["law"] = json!("cycloidal");
    post_json(PATH, &b).await.problem(422);
    let mut b = table1();
    b.as_object_mut().expect("object").remove("coefficients");
    post_json(PATH, &b).await.problem(422);
}

#[tokio::test]
async fn named_law_outside_the_class_with_end_rates_is_422() {
    let body = json!({
        "law": "polynomial_345",
        "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0, "v_a": 0.3},
        "abscissa": {"values": [0.0, 0.5, 1.0]}
    });
    post_json(PATH, &body).await.problem(422);
}

#[tokio::test]
async fn oversized_body_is_413() {
    let config = ServiceConfig {
        max_body_bytes: 1024,
        ..common::config()
    };
    let mut b = table1();
    b["abscissa"] = json!({"values": (0..2000).map(|i| f64::from(i) / 1999.0).collect::<Vec<_>>()});
    let r = post_json_to(AppState::new(config), PATH, &b).await;
    assert_eq!(r.problem(413)["type"], "/problems/body-too-large");
}

#[tokio::test]
async fn saturated_pool_is_503_with_retry_after() {
    let config = ServiceConfig {
        compute_slots: 1,
        queue_depth: 0,
        ..common::config()
    };
    let state = AppState::new(config);
    let _held = state
        .pool
        .acquire(Duration::from_millis(10))
        .await
        .expect("the only slot is free");
    let r = post_json_to(state, PATH, &table1()).await;
    let p = r.problem(503);
    assert_eq!(p["type"], "/problems/overloaded");
    assert!(r.headers.get("retry-after").is_some());
}
