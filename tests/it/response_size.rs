//! The size of an answer is checked before computing: a request whose estimated answer exceeds
//! `--max-response-bytes` is a 422 `RESPONSE_TOO_LARGE` naming the option to change, and the
//! calculation is never entered; the estimate is an upper bound of the real body on every
//! `api/` example of the endpoints that estimate.

use crate::common;
use crate::contract::examples;

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use mechcalc::AppState;
use mechcalc::calc::irefc::{IrefcStressRequest, run_stress};
use mechcalc::config::ServiceConfig;
use mechcalc::numerics::Budget;
use mechcalc::numerics::budget::ProgressSink;
use serde_json::{Value, json};

/// Endpoints whose answer size is driven by request options and estimated before computing.
const ESTIMATED: &[&str] = &[
    "/v1/irefc-stress",
    "/v1/bezier-motion-law",
    "/v1/vibration-absorber",
    "/v1/cam-law/evaluate",
    "/v1/continuum-workspace",
    "/v1/bus-fuel-economy",
    "/v1/bus-fuel-economy/motor-map",
    "/v1/machining-size/predict",
];

/// The paper's structured array: 31 × 43 = 1333 combinations (≈ 2 MB estimated).
fn big_sweep() -> Value {
    json!({"mode": "sweep", "r2_mm": 20, "rb_mm": 2, "torque_Nm": 119.366207,
           "sweep": {"Z2": {"from": 10, "to": 40}, "chi": {"from": 1.25, "to": 1.67, "step": 0.01}},
           "step_deg": 1, "refine": true})
}

/// A budget that counts the progress reports of the calculation (the sweep reports after every
/// combination, the first report always reaches the sink).
fn counting_budget() -> (Budget, Arc<AtomicUsize>) {
    let calls = Arc::new(AtomicUsize::new(0));
    let c = Arc::clone(&calls);
    let sink = ProgressSink::new(move |_| {
        c.fetch_add(1, Ordering::Relaxed);
    });
    (Budget::unlimited().with_progress(Arc::new(sink)), calls)
}

#[test]
fn an_oversized_sweep_is_refused_without_computing() {
    let req = || -> IrefcStressRequest { serde_json::from_value(big_sweep()).expect("valid") };
    // Control: the counter sees the calculation when it runs (one combination allowed).
    let (budget, calls) = counting_budget();
    let done = run_stress(req(), &budget.with_max_evaluations(1)).expect("runs");
    assert!(matches!(
        done,
        mechcalc::calc::irefc::IrefcStressResponse::Sweep(_)
    ));
    assert!(
        calls.load(Ordering::Relaxed) > 0,
        "the sweep reports progress"
    );
    // Over the limit: refused, and the sweep was never entered.
    let (budget, calls) = counting_budget();
    let err = run_stress(req(), &budget.with_max_response_bytes(100_000))
        .expect_err("the estimate exceeds the limit");
    assert_eq!(err.code, "RESPONSE_TOO_LARGE");
    assert_eq!(err.errors.len(), 1);
    assert_eq!(err.errors[0].pointer, "/sweep");
    assert!(
        err.detail.contains("100000") && err.detail.contains("max_response_bytes"),
        "{}",
        err.detail
    );
    assert_eq!(calls.load(Ordering::Relaxed), 0, "nothing was computed");
    // Within the limit the same request is computed.
    let (budget, calls) = counting_budget();
    run_stress(
        req(),
        &budget
            .with_max_response_bytes(64 << 20)
            .with_max_evaluations(1),
    )
    .expect("within the limit");
    assert!(calls.load(Ordering::Relaxed) > 0);
}

fn limited(max_response_bytes: usize) -> AppState {
    AppState::new(ServiceConfig {
        max_response_bytes,
        ..common::config()
    })
}

#[tokio::test]
async fn the_service_limit_reaches_the_modules_and_names_the_option() {
    let started = std::time::Instant::now();
    let r = common::post_json_to(limited(50_000), "/v1/irefc-stress", &big_sweep()).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/too-large");
    assert_eq!(p["code"], "RESPONSE_TOO_LARGE");
    assert_eq!(r.pointers(), vec!["/sweep"]);
    let detail = p["detail"].as_str().unwrap_or_default();
    assert!(
        detail.contains("50000") && detail.contains("estimated before computing"),
        "{p}"
    );
    // Computing the 1333 combinations takes seconds in the test profile; the refusal does not
    // wait for them (a loose bound: the proof that nothing runs is the test above).
    assert!(started.elapsed().as_secs_f64() < 30.0);

    // Another endpoint: the cam law's curves.
    let cam = json!({"law": "modified_sine",
                     "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0},
                     "abscissa": {"grid": {"start": 0.0, "end": 1.0, "count": 200000}},
                     "quantities": ["s", "v", "a", "j"]});
    let r = common::post_json_to(limited(1_000_000), "/v1/cam-law/evaluate", &cam).await;
    r.problem(422);
    assert_eq!(r.pointers(), vec!["/abscissa"]);
}

#[tokio::test]
async fn the_estimate_bounds_every_example_answer() {
    let mut checked = 0;
    for (file, endpoint, body) in examples() {
        if !ESTIMATED.contains(&endpoint.as_str()) {
            continue;
        }
        let r = common::post_json_to(AppState::new(common::config()), &endpoint, &body).await;
        if r.status != 200 {
            continue;
        }
        let actual = r.bytes.len();
        // One byte below the real size: an estimate ≥ the real size refuses before computing
        // (its message says so); an estimate below it would let the calculation run into the
        // service's check of the encoded answer ("the answer is N bytes").
        let r = common::post_json_to(limited(actual - 1), &endpoint, &body).await;
        let p = r.problem(422);
        let detail = p["detail"].as_str().unwrap_or_default();
        assert!(
            detail.contains("estimated before computing"),
            "{file}: the estimate is below the real answer of {actual} bytes: {detail}"
        );
        let estimate = detail
            .split("about ")
            .nth(1)
            .and_then(|t| t.split(' ').next())
            .and_then(|n| n.parse::<f64>().ok())
            .unwrap_or(f64::NAN);
        eprintln!(
            "{file}: answer {actual} bytes, estimate {estimate} bytes ({:.1}x)",
            estimate / actual as f64
        );
        checked += 1;
    }
    assert!(checked >= 12, "only {checked} examples checked");
}
