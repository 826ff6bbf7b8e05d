//! Progress for long work (`Accept: text/event-stream`) on the heavy endpoints: the IREFC sweep,
//! the continuum workspace sweep, the cam-law fit and model training report progress events
//! before the final `result` event, and the final answer equals the non-streaming one (timing
//! fields aside).

use axum::body::Body;
use axum::http::Request;
use http_body_util::BodyExt;
use mechcalc::AppState;
use serde_json::Value;
use tower::ServiceExt;

use crate::common;

fn example(file: &str) -> Value {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("api")
        .join(file);
    serde_json::from_str(&std::fs::read_to_string(p).expect("example")).expect("json")
}

/// POST `body` with `Accept: text/event-stream`; the (event, data) pairs of the stream.
async fn stream(path: &str, body: &Value) -> Vec<(String, String)> {
    let req = Request::builder()
        .method("POST")
        .uri(path)
        .header("content-type", "application/json")
        .header("accept", "text/event-stream")
        .body(Body::from(serde_json::to_vec(body).expect("json")))
        .expect("request");
    let resp = mechcalc::app(AppState::new(common::config()))
        .oneshot(req)
        .await
        .expect("router is infallible");
    assert_eq!(resp.status(), 200);
    let ct = resp
        .headers()
        .get("content-type")
        .and_then(|v| v.to_str().ok())
        .unwrap_or_default()
        .to_owned();
    assert!(ct.starts_with("text/event-stream"), "{ct}");
    let bytes = resp.into_body().collect().await.expect("body").to_bytes();
    let text = String::from_utf8(bytes.to_vec()).expect("utf-8");
    text.split("\n\n")
        .filter(|block| !block.trim().is_empty())
        .map(|block| {
            let mut event = String::from("message");
            let mut data = Vec::new();
            for line in block.lines() {
                if let Some(e) = line.strip_prefix("event:") {
                    event = e.trim().to_owned();
                } else if let Some(d) = line.strip_prefix("data:") {
                    data.push(d.strip_prefix(' ').unwrap_or(d));
                }
            }
            (event, data.join("\n"))
        })
        .collect()
}

/// Drops timing fields (they differ between two runs) everywhere in `v`.
fn without_timing(v: &mut Value) {
    match v {
        Value::Object(m) => {
            m.retain(|k, _| {
                !k.contains("elapsed")
                    && !k.ends_with("_us")
                    && !["cpu_ms", "wall_ms", "timing_ms", "compute_ms"].contains(&k.as_str())
            });
            m.values_mut().for_each(without_timing);
        }
        Value::Array(a) => a.iter_mut().for_each(without_timing),
        _ => {}
    }
}

async fn check(path: &str, file: &str) {
    let body = example(file);
    let events = stream(path, &body).await;
    let (last, rest) = events.split_last().expect("at least the final event");
    assert_eq!(last.0, "result", "{file}: final event {last:?}");
    let progress: Vec<Value> = rest
        .iter()
        .filter(|(e, _)| e == "progress")
        .map(|(_, d)| serde_json::from_str(d).expect("progress JSON"))
        .collect();
    assert!(
        !progress.is_empty(),
        "{file}: no progress event before the answer"
    );
    for p in &progress {
        let f = p["fraction"].as_f64().expect("fraction");
        assert!((0.0..=1.0).contains(&f), "{file}: fraction {f}");
        assert!(p["elapsed_ms"].as_f64().is_some_and(|t| t >= 0.0), "{p}");
    }
    let mut streamed: Value = serde_json::from_str(&last.1).expect("final JSON");
    let plain = common::post_json(path, &body).await;
    assert_eq!(
        plain.status,
        200,
        "{}",
        String::from_utf8_lossy(&plain.bytes)
    );
    let mut plain = plain.json();
    without_timing(&mut streamed);
    without_timing(&mut plain);
    assert_eq!(
        streamed, plain,
        "{file}: streamed answer differs from the plain one"
    );
}

#[tokio::test]
async fn irefc_sweep_streams_progress_then_the_answer() {
    check("/v1/irefc-stress", "irefc/stress_sweep.json").await;
}

#[tokio::test]
async fn workspace_sweep_streams_progress_then_the_answer() {
    check(
        "/v1/continuum-workspace",
        "continuum_workspace/sweep_symmetric.json",
    )
    .await;
}

#[tokio::test]
async fn cam_law_fit_streams_progress_then_the_answer() {
    check("/v1/fit-cam-law", "cam_law_fit/table1.json").await;
}

#[tokio::test]
async fn model_training_streams_progress_then_the_answer() {
    check(
        "/v1/machining-size/train",
        "machining_size/train_synthetic.json",
    )
    .await;
}
