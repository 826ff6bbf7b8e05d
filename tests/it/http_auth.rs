//! API keys at the door (in process): 401 with `WWW-Authenticate` for a missing or unknown
//! token, the public routes, per-key rates (429 + `Retry-After`, other keys unaffected), the key
//! id as a metrics label with no token anywhere, reload, a keys file that cannot be read, the
//! document's bearer scheme with 401 and 429 on every operation, and `--help` units.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use axum::body::Body;
use axum::http::Request;
use http_body_util::BodyExt;
use mechcalc::config::ServiceConfig;
use mechcalc::http::auth::token_hash_hex;
use mechcalc::{AppState, app};
use serde_json::Value;
use tower::ServiceExt;

use crate::common::{self, Reply};

const CAM: &str = "/v1/cam-law/evaluate";

/// A keys file with `lines` (`id token [rate]`, tokens are hashed here) in the temp directory.
fn keys_file(lines: &[(&str, &str, Option<u32>)]) -> PathBuf {
    static N: AtomicU32 = AtomicU32::new(0);
    let path = std::env::temp_dir().join(format!(
        "mechcalc-keys-{}-{}.txt",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    write_keys(&path, lines);
    path
}

fn write_keys(path: &Path, lines: &[(&str, &str, Option<u32>)]) {
    let mut text = String::from("# test keys\n");
    for (id, token, rate) in lines {
        text.push_str(&format!("{id} {}", token_hash_hex(token)));
        if let Some(r) = rate {
            text.push_str(&format!(" {r}"));
        }
        text.push('\n');
    }
    std::fs::write(path, text).expect("keys file written");
}

fn state_with(path: &Path) -> AppState {
    AppState::new(ServiceConfig {
        api_keys_file: Some(path.to_path_buf()),
        ..common::config()
    })
}

fn cam_body() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/api/cam_law/evaluate_table1.json"
    ))
    .expect("example")
}

/// Send `method path` with an optional `Authorization` header.
async fn call(state: &AppState, method: &str, path: &str, auth: Option<&str>) -> Reply {
    let mut req = Request::builder().method(method).uri(path);
    if let Some(a) = auth {
        req = req.header("authorization", a);
    }
    let body = if method == "POST" {
        req = req.header("content-type", "application/json");
        Body::from(cam_body())
    } else {
        Body::empty()
    };
    let resp = app(state.clone())
        .oneshot(req.body(body).expect("request"))
        .await
        .expect("infallible");
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

fn header<'a>(r: &'a Reply, name: &str) -> &'a str {
    r.headers
        .get(name)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("")
}

#[tokio::test]
async fn a_missing_or_unknown_token_is_401_with_a_bearer_challenge() {
    let path = keys_file(&[("plm", "s3cret-plm", None)]);
    let state = state_with(&path);
    for (method, route) in [
        ("GET", "/v1"),
        ("GET", "/v1/examples"),
        ("GET", "/metrics"),
        ("POST", CAM),
    ] {
        for (auth, invalid) in [
            (None, false),
            (Some("Bearer wrong-token"), true),
            (Some("Basic czNjcmV0LXBsbQ=="), false),
            (Some("Bearer "), false),
            (Some("s3cret-plm"), false),
        ] {
            let r = call(&state, method, route, auth).await;
            let p = r.problem(401);
            assert_eq!(
                p["type"], "/problems/unauthorized",
                "{method} {route} {auth:?}"
            );
            assert_eq!(p["code"], "UNAUTHORIZED");
            let challenge = header(&r, "www-authenticate");
            assert!(challenge.starts_with("Bearer"), "{challenge}");
            assert_eq!(
                challenge.contains("invalid_token"),
                invalid,
                "{method} {route} {auth:?}: {challenge}"
            );
        }
        let ok = call(&state, method, route, Some("Bearer s3cret-plm")).await;
        assert_eq!(ok.status, 200, "{method} {route} with the token");
        let lower = call(&state, method, route, Some("bearer  s3cret-plm ")).await;
        assert_eq!(lower.status, 200, "the scheme is case-insensitive");
    }
}

#[tokio::test]
async fn the_public_routes_answer_without_a_token() {
    let path = keys_file(&[("plm", "tok-public", None)]);
    let state = state_with(&path);
    for route in [
        "/healthz",
        "/",
        "/docs",
        "/openapi.json",
        "/docs/swagger-ui.css",
    ] {
        assert_eq!(
            call(&state, "GET", route, None).await.status,
            200,
            "{route}"
        );
    }
    // Unknown routes are still behind the door: no probing of the route table without a key.
    assert_eq!(call(&state, "GET", "/nope", None).await.status, 401);
    assert_eq!(
        call(&state, "GET", "/nope", Some("Bearer tok-public"))
            .await
            .status,
        404
    );
}

#[tokio::test]
async fn a_key_over_its_rate_gets_429_and_other_keys_are_served() {
    let path = keys_file(&[("slow", "tok-slow", Some(3)), ("free", "tok-free", None)]);
    let state = state_with(&path);
    for i in 0..3 {
        let r = call(&state, "POST", CAM, Some("Bearer tok-slow")).await;
        assert_eq!(
            r.status, 200,
            "request {i} within the burst of one minute's worth"
        );
    }
    let r = call(&state, "POST", CAM, Some("Bearer tok-slow")).await;
    let p = r.problem(429);
    assert_eq!(p["code"], "RATE_LIMITED");
    assert_eq!(p["type"], "/problems/too-many-requests");
    let retry: u64 = header(&r, "retry-after").parse().expect("Retry-After");
    // 3 a minute: the next token comes within 20 s.
    assert!((1..=20).contains(&retry), "Retry-After {retry}");
    assert!(!r.bytes.windows(8).any(|w| w == b"tok-slow"));
    for _ in 0..10 {
        let other = call(&state, "POST", CAM, Some("Bearer tok-free")).await;
        assert_eq!(other.status, 200, "another key is never refused for it");
    }
    // A reload that keeps the key and its rate keeps its bucket.
    state
        .keys
        .as_ref()
        .expect("keys")
        .reload()
        .expect("reloads");
    assert_eq!(
        call(&state, "POST", CAM, Some("Bearer tok-slow"))
            .await
            .status,
        429
    );
}

#[tokio::test]
async fn metrics_carry_the_key_id_and_never_a_token() {
    let token = "tok-metrics-9d1c";
    let path = keys_file(&[("metrics-key", token, None)]);
    let state = state_with(&path);
    assert_eq!(
        call(&state, "POST", CAM, Some(&format!("Bearer {token}")))
            .await
            .status,
        200
    );
    let m = call(&state, "GET", "/metrics", Some(&format!("Bearer {token}"))).await;
    let text = String::from_utf8_lossy(&m.bytes);
    assert!(
        text.lines()
            .any(|l| l.starts_with("mechcalc_requests_total")
                && l.contains("key=\"metrics-key\"")
                && l.contains("route=\"/v1/cam-law/evaluate\"")),
        "no request metric labelled with the key id"
    );
    assert!(!text.contains(token), "the token is in the metrics");
    assert!(
        !text.contains(&token_hash_hex(token)),
        "the hash is in the metrics"
    );
}

#[tokio::test]
async fn a_reload_takes_new_keys_and_a_broken_file_keeps_the_keys_in_force() {
    let path = keys_file(&[("old", "tok-old", None)]);
    let state = state_with(&path);
    let ring = state.keys.clone().expect("keys");
    assert_eq!(
        call(&state, "GET", "/v1", Some("Bearer tok-old"))
            .await
            .status,
        200
    );
    write_keys(&path, &[("new", "tok-new", None)]);
    assert_eq!(ring.reload().expect("reloads"), 1);
    assert_eq!(
        call(&state, "GET", "/v1", Some("Bearer tok-old"))
            .await
            .status,
        401
    );
    assert_eq!(
        call(&state, "GET", "/v1", Some("Bearer tok-new"))
            .await
            .status,
        200
    );
    std::fs::write(&path, "new not-a-hash\n").expect("written");
    let e = ring
        .reload()
        .expect_err("a bad line is refused")
        .to_string();
    assert!(e.contains("line 1"), "{e}");
    assert_eq!(
        call(&state, "GET", "/v1", Some("Bearer tok-new"))
            .await
            .status,
        200,
        "the keys in force stay"
    );
    let _ = std::fs::remove_file(&path);
}

#[tokio::test]
async fn a_keys_file_that_cannot_be_read_closes_the_service() {
    let path = std::env::temp_dir().join("mechcalc-keys-that-do-not-exist.txt");
    assert!(
        AppState::try_new(ServiceConfig {
            api_keys_file: Some(path.to_path_buf()),
            ..common::config()
        })
        .is_err()
    );
    let state = state_with(&path);
    assert_eq!(call(&state, "GET", "/v1", None).await.status, 401);
    assert_eq!(
        call(&state, "GET", "/v1", Some("Bearer x")).await.status,
        401
    );
    assert_eq!(call(&state, "GET", "/healthz", None).await.status, 200);
}

#[tokio::test]
async fn without_keys_no_token_is_needed() {
    let state = AppState::new(common::config());
    assert_eq!(call(&state, "GET", "/v1", None).await.status, 200);
    assert_eq!(call(&state, "POST", CAM, None).await.status, 200);
    // A token sent to a service without keys is ignored, not refused.
    assert_eq!(
        call(&state, "POST", CAM, Some("Bearer anything"))
            .await
            .status,
        200
    );
}

#[test]
fn the_document_has_the_bearer_scheme_and_401_and_429_on_every_operation() {
    let doc: Value = serde_json::to_value(mechcalc::http::openapi()).expect("JSON");
    let scheme = &doc["components"]["securitySchemes"]["bearer"];
    assert_eq!(scheme["type"], "http");
    assert_eq!(scheme["scheme"], "bearer");
    assert_eq!(doc["security"], serde_json::json!([{"bearer": []}]));
    let mut operations = 0;
    for (path, item) in doc["paths"].as_object().expect("paths") {
        for (method, op) in item.as_object().expect("item") {
            operations += 1;
            if op["operationId"] == "get_health" {
                assert_eq!(op["security"], serde_json::json!([{}]), "healthz is public");
                continue;
            }
            for status in ["401", "429"] {
                let r = &op["responses"][status];
                assert!(
                    r["content"]["application/problem+json"].is_object(),
                    "{method} {path} does not document {status}"
                );
            }
            assert!(op["responses"]["401"]["headers"]["WWW-Authenticate"].is_object());
            assert!(op["responses"]["429"]["headers"]["Retry-After"].is_object());
        }
    }
    assert!(operations > 10);
}

#[test]
fn help_prints_units_in_plain_brackets() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mechcalc"))
        .arg("--help")
        .output()
        .expect("runs");
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(!help.contains("\\["), "escaped brackets in --help:\n{help}");
    assert!(help.contains("[ms]") && help.contains("[bytes]"), "{help}");
    assert!(help.contains("--api-keys-file") && help.contains("--client-queue-depth"));
    // The text is for the service's users: no notes about how the source is written.
    assert!(!help.contains("rustdoc"), "{help}");
}

/// A log sink for one test.
#[derive(Clone, Default)]
struct Captured(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);

impl std::io::Write for Captured {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        if let Ok(mut v) = self.0.lock() {
            v.extend_from_slice(b);
        }
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// What building the state with `config` logs.
fn start_log(config: ServiceConfig) -> String {
    let sink = Captured::default();
    let writer = sink.clone();
    let subscriber = tracing_subscriber::fmt()
        .with_ansi(false)
        .with_writer(move || writer.clone())
        .finish();
    tracing::subscriber::with_default(subscriber, || {
        let _ = AppState::try_new(config);
    });
    let bytes = sink.0.lock().map(|v| v.clone()).unwrap_or_default();
    String::from_utf8_lossy(&bytes).into_owned()
}

#[test]
fn a_non_loopback_bind_without_keys_warns_at_start() {
    let open = |bind: &str| ServiceConfig {
        bind: bind.parse().expect("address"),
        ..common::config()
    };
    let log = start_log(open("0.0.0.0:8080"));
    assert!(log.contains("WARN") && log.contains("no API keys"), "{log}");
    assert!(!start_log(open("127.0.0.1:8080")).contains("no API keys"));
    let keys = keys_file(&[("k", "tok-warn", None)]);
    let log = start_log(ServiceConfig {
        api_keys_file: Some(keys),
        ..open("0.0.0.0:8080")
    });
    assert!(!log.contains("no API keys"), "{log}");
}
