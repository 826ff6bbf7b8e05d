//! The service contract shared by every endpoint: discovery, docs, and problem+json for
//! malformed, mistyped, oversized and misrouted requests.

use crate::common;

use common::{config, get, send, send_to};
use mechcalc::AppState;
use mechcalc::config::ServiceConfig;

#[tokio::test]
async fn healthz_answers_ok() {
    let r = get("/healthz").await;
    assert_eq!(r.status, 200);
    assert_eq!(r.json()["status"], "ok");
}

/// Every answer announces the idle keep-alive limit (the request-head timeout, 10 s by default),
/// so pooled client connections are replaced before the server closes them.
#[tokio::test]
async fn answers_announce_the_keep_alive_limit() {
    for path in ["/healthz", "/v1", "/no-such-path"] {
        let r = get(path).await;
        assert_eq!(
            r.headers.get("keep-alive").and_then(|v| v.to_str().ok()),
            Some("timeout=10"),
            "{path}"
        );
    }
}

#[tokio::test]
async fn index_lists_every_documented_endpoint() {
    let r = get("/v1").await;
    assert_eq!(r.status, 200);
    let body = r.json();
    let lines = body["endpoints"].as_array().expect("endpoints array");
    let api = mechcalc::http::openapi();
    assert_eq!(
        lines.len(),
        api.paths
            .paths
            .values()
            .map(|p| usize::from(p.get.is_some()) + usize::from(p.post.is_some()))
            .sum::<usize>()
    );
    for l in lines {
        assert!(
            !l["summary"].as_str().unwrap_or("").is_empty(),
            "every endpoint has a summary: {l}"
        );
    }
    assert!(lines.iter().any(|l| l["path"] == "/healthz"));
}

#[tokio::test]
async fn openapi_json_and_docs_are_served() {
    let r = get("/openapi.json").await;
    assert_eq!(r.status, 200);
    assert!(
        r.json()["openapi"]
            .as_str()
            .is_some_and(|v| v.starts_with("3."))
    );
    let d = get("/docs").await;
    assert_eq!(d.status, 200);
    assert!(String::from_utf8_lossy(&d.bytes).contains("/docs/swagger-ui-bundle.js"));
    let js = get("/docs/swagger-ui-bundle.js").await;
    assert_eq!(js.status, 200);
    assert!(
        js.bytes.len() > 100_000,
        "the vendored bundle is served whole"
    );
    assert_eq!(get("/docs/swagger-ui.css").await.status, 200);
}

#[tokio::test]
async fn unknown_path_is_problem_404() {
    let r = get("/v1/no-such-thing").await;
    let p = r.problem(404);
    assert_eq!(p["type"], "/problems/not-found");
}

#[tokio::test]
async fn wrong_method_is_problem_405() {
    let r = send("DELETE", "/healthz", None, Vec::new()).await;
    let p = r.problem(405);
    assert_eq!(p["type"], "/problems/method-not-allowed");
}

#[tokio::test]
async fn config_defaults_match_the_readme() {
    let c = ServiceConfig::default();
    assert_eq!(c.bind.to_string(), "127.0.0.1:8080");
    assert!(c.max_body_bytes >= 1 << 20);
    let state = AppState::new(config());
    assert_eq!(state.pool.available_slots(), 2);
    let r = send_to(state, "GET", "/healthz", None, Vec::new()).await;
    assert_eq!(r.json()["compute_slots_free"], 2);
}
