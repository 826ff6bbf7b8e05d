//! Helpers shared by the HTTP tests: drive the router in process, no socket.

use axum::body::Body;
use axum::http::{HeaderMap, Request, StatusCode};
use http_body_util::BodyExt;
use mechcalc::config::ServiceConfig;
use mechcalc::{AppState, app};
use serde_json::Value;
use tower::ServiceExt;

/// A response as the tests see it.
pub struct Reply {
    pub status: StatusCode,
    pub headers: HeaderMap,
    pub bytes: Vec<u8>,
}

impl Reply {
    /// The body as JSON (panics with the raw body when it is not JSON).
    pub fn json(&self) -> Value {
        serde_json::from_slice(&self.bytes).unwrap_or_else(|e| {
            panic!(
                "body is not JSON ({e}): {}",
                String::from_utf8_lossy(&self.bytes)
            )
        })
    }

    /// The Content-Type header.
    pub fn content_type(&self) -> &str {
        self.headers
            .get("content-type")
            .and_then(|v| v.to_str().ok())
            .unwrap_or("")
    }

    /// Assert this is a problem+json answer with `status` and return the body.
    pub fn problem(&self, status: u16) -> Value {
        assert_eq!(
            self.status.as_u16(),
            status,
            "body: {}",
            String::from_utf8_lossy(&self.bytes)
        );
        assert_eq!(self.content_type(), "application/problem+json");
        let p = self.json();
        assert_eq!(p["status"], status);
        assert!(
            p["type"]
                .as_str()
                .is_some_and(|t| t.starts_with("/problems/")),
            "{p}"
        );
        assert!(
            p["title"].is_string() && p["detail"].is_string() && p["code"].is_string(),
            "{p}"
        );
        assert!(p["errors"].is_array(), "{p}");
        p
    }

    /// A 422 problem whose `errors[]` name exactly `want`, in order.
    #[track_caller]
    pub fn assert_422_at(&self, want: &[&str]) {
        self.problem(422);
        assert_eq!(self.pointers(), want);
    }

    /// A 422 invalid-input problem whose `errors[]` name (at least) every one of `want`; the
    /// problem body.
    #[track_caller]
    pub fn invalid_input_at(&self, want: &[&str]) -> Value {
        let p = self.problem(422);
        assert_eq!(p["type"], "/problems/invalid-input");
        assert_eq!(p["code"], "INVALID_INPUT");
        let ptrs = self.pointers();
        for w in want {
            assert!(
                ptrs.iter().any(|q| q == w),
                "{w} missing from {ptrs:?}: {p}"
            );
        }
        p
    }

    /// The JSON pointers of a problem's `errors[]`.
    pub fn pointers(&self) -> Vec<String> {
        self.json()["errors"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|e| e["pointer"].as_str().map(str::to_owned))
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// The `code`s of an answer's `warnings[]`, in order.
pub fn warning_codes(answer: &Value) -> Vec<&str> {
    answer["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .filter_map(|w| w["code"].as_str())
        .collect()
}

/// The default configuration used by tests.
pub fn config() -> ServiceConfig {
    ServiceConfig {
        compute_slots: 2,
        queue_depth: 4,
        ..ServiceConfig::default()
    }
}

/// Send one request to a fresh app built from `state`.
pub async fn send_to(
    state: AppState,
    method: &str,
    path: &str,
    content_type: Option<&str>,
    body: Vec<u8>,
) -> Reply {
    send_via(app(state), method, path, content_type, body).await
}

/// POST a JSON value through an app already built (a test that sends thousands of requests
/// builds its app once).
pub async fn post_json_via(router: axum::Router, path: &str, body: &Value) -> Reply {
    send_via(
        router,
        "POST",
        path,
        Some("application/json"),
        serde_json::to_vec(body).expect("serializable"),
    )
    .await
}

/// Send one request through `router`.
pub async fn send_via(
    router: axum::Router,
    method: &str,
    path: &str,
    content_type: Option<&str>,
    body: Vec<u8>,
) -> Reply {
    let mut req = Request::builder().method(method).uri(path);
    if let Some(ct) = content_type {
        req = req.header("content-type", ct);
    }
    let req = req.body(Body::from(body)).expect("valid request");
    let resp = router.oneshot(req).await.expect("router is infallible");
    let status = resp.status();
    let headers = resp.headers().clone();
    let bytes = resp
        .into_body()
        .collect()
        .await
        .expect("body")
        .to_bytes()
        .to_vec();
    Reply {
        status,
        headers,
        bytes,
    }
}

/// Send one request to a fresh app with the test configuration.
pub async fn send(method: &str, path: &str, content_type: Option<&str>, body: Vec<u8>) -> Reply {
    send_to(AppState::new(config()), method, path, content_type, body).await
}

/// POST a JSON value to a fresh app built from `state`.
pub async fn post_json_to(state: AppState, path: &str, body: &Value) -> Reply {
    send_to(
        state,
        "POST",
        path,
        Some("application/json"),
        serde_json::to_vec(body).expect("serializable"),
    )
    .await
}

/// POST a JSON value to a fresh app with the test configuration.
pub async fn post_json(path: &str, body: &Value) -> Reply {
    post_json_to(AppState::new(config()), path, body).await
}

/// GET a path.
pub async fn get(path: &str) -> Reply {
    send("GET", path, None, Vec::new()).await
}

/// Compare `expected` against `actual`: every leaf of `expected` must be present in `actual` at
/// the same path; numbers within `rel` relative or `abs` absolute. Returns the mismatches.
pub fn leaves_match(
    expected: &Value,
    actual: &Value,
    path: &str,
    rel: f64,
    abs: f64,
    out: &mut Vec<String>,
) {
    match (expected, actual) {
        (Value::Object(e), Value::Object(a)) => {
            for (k, ev) in e {
                match a.get(k) {
                    Some(av) => leaves_match(ev, av, &format!("{path}/{k}"), rel, abs, out),
                    None => out.push(format!("{path}/{k}: missing")),
                }
            }
        }
        (Value::Array(e), Value::Array(a)) => {
            if e.len() != a.len() {
                out.push(format!(
                    "{path}: length {} expected, got {}",
                    e.len(),
                    a.len()
                ));
                return;
            }
            for (i, (ev, av)) in e.iter().zip(a).enumerate() {
                leaves_match(ev, av, &format!("{path}/{i}"), rel, abs, out);
            }
        }
        (Value::Number(e), Value::Number(a)) => {
            let (e, a) = (
                e.as_f64().unwrap_or(f64::NAN),
                a.as_f64().unwrap_or(f64::NAN),
            );
            let ok = (e - a).abs() <= abs.max(rel * e.abs());
            if !ok {
                out.push(format!("{path}: expected {e}, got {a}"));
            }
        }
        (e, a) => {
            if e != a {
                out.push(format!("{path}: expected {e}, got {a}"));
            }
        }
    }
}
