//! Cross-cutting HTTP layers: request ids, the one log line per request (rejections and client
//! aborts included), request metrics, hardening headers and CORS.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use axum::extract::{MatchedPath, Request};
use axum::http::{HeaderName, HeaderValue, Method, header};
use axum::middleware::Next;
use axum::response::Response;
use tower_http::cors::{AllowOrigin, CorsLayer};
use tower_http::request_id::{MakeRequestId, RequestId};
use tracing::Instrument;

use super::auth::KeyId;
use super::pool::{REQUEST_INFO, RequestInfo};

/// The request-id header: accepted from the client, generated when absent, echoed and logged.
pub const REQUEST_ID: HeaderName = HeaderName::from_static("x-request-id");

/// Generates request ids: a per-process random prefix and a counter (unique, cheap, sortable).
#[derive(Clone)]
pub struct MakeId {
    prefix: u32,
    counter: std::sync::Arc<AtomicU64>,
}

impl Default for MakeId {
    fn default() -> Self {
        Self {
            prefix: rand::random(),
            counter: std::sync::Arc::new(AtomicU64::new(0)),
        }
    }
}

impl MakeRequestId for MakeId {
    fn make_request_id<B>(&mut self, _req: &axum::http::Request<B>) -> Option<RequestId> {
        let n = self.counter.fetch_add(1, Ordering::Relaxed);
        HeaderValue::from_str(&format!("{:08x}-{n:012x}", self.prefix))
            .ok()
            .map(RequestId::new)
    }
}

/// Logs the request once when it is dropped without an answer (the client went away).
struct AbortLog {
    method: Method,
    route: String,
    request_id: String,
    start: Instant,
    done: bool,
}

impl Drop for AbortLog {
    fn drop(&mut self) {
        if !self.done {
            let latency_ms = self.start.elapsed().as_secs_f64() * 1e3;
            metrics::counter!("mechcalc_requests_aborted_total", "route" => self.route.clone())
                .increment(1);
            tracing::warn!(method = %self.method, route = %self.route, request_id = %self.request_id,
                latency_ms, "request aborted by the client");
        }
    }
}

/// One structured log line per request (method, path, route, status, latency, request id, API key
/// id; never bodies or tokens), request metrics (labelled by route, status and key id), and the route/body size the compute pool learns from.
pub async fn log_request(req: Request, next: Next) -> Response {
    let method = req.method().clone();
    let path = req.uri().path().to_owned();
    let route = req
        .extensions()
        .get::<MatchedPath>()
        .map_or_else(|| "unmatched".to_owned(), |m| m.as_str().to_owned());
    let request_id = req
        .headers()
        .get(&REQUEST_ID)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("")
        .to_owned();
    let body_bytes = req
        .headers()
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let span = tracing::info_span!("request", %method, %path, %request_id);
    let mut abort = AbortLog {
        method: method.clone(),
        route: route.clone(),
        request_id: request_id.clone(),
        start: Instant::now(),
        done: false,
    };
    let info = RequestInfo {
        route: route.clone(),
        body_bytes,
        progress: None,
        client: std::sync::Arc::from(""),
        door_ns: std::sync::Arc::default(),
    };
    let resp = REQUEST_INFO
        .scope(info, next.run(req).instrument(span))
        .await;
    abort.done = true;
    let latency = abort.start.elapsed().as_secs_f64();
    let status = resp.status().as_u16();
    // The API key id (never the token); `-` when the service has no keys or the request none.
    let key = resp
        .extensions()
        .get::<KeyId>()
        .map_or_else(|| "-".to_owned(), |k| k.0.to_string());
    metrics::counter!("mechcalc_requests_total", "route" => route.clone(), "status" => status.to_string(), "key" => key.clone())
        .increment(1);
    metrics::histogram!("mechcalc_request_duration_seconds", "route" => route.clone(), "key" => key.clone())
        .record(latency);
    tracing::info!(%method, %path, %route, status, latency_ms = latency * 1e3, %request_id, %key, "request");
    if body_bytes >= super::memory::LARGE_BODY_BYTES {
        super::memory::give_back();
    }
    resp
}

/// Response headers every answer carries unless the handler set its own.
pub fn hardening_headers() -> [(HeaderName, HeaderValue); 5] {
    [
        (
            header::X_CONTENT_TYPE_OPTIONS,
            HeaderValue::from_static("nosniff"),
        ),
        (header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY")),
        (
            header::CONTENT_SECURITY_POLICY,
            HeaderValue::from_static("frame-ancestors 'none'"),
        ),
        (
            header::REFERRER_POLICY,
            HeaderValue::from_static("no-referrer"),
        ),
        (header::CACHE_CONTROL, HeaderValue::from_static("no-store")),
    ]
}

/// CORS for browser-based tools: off (no layer) unless origins are configured.
#[must_use]
pub fn cors(origins: &[String]) -> Option<CorsLayer> {
    let origins: Vec<&String> = origins.iter().filter(|o| !o.trim().is_empty()).collect();
    if origins.is_empty() {
        return None;
    }
    let allow = if origins.iter().any(|o| o.trim() == "*") {
        AllowOrigin::any()
    } else {
        AllowOrigin::list(
            origins
                .iter()
                .filter_map(|o| HeaderValue::from_str(o.trim()).ok()),
        )
    };
    Some(
        CorsLayer::new()
            .allow_origin(allow)
            .allow_methods([Method::GET, Method::POST, Method::OPTIONS])
            .allow_headers([
                header::CONTENT_TYPE,
                header::ACCEPT,
                header::AUTHORIZATION,
                REQUEST_ID,
            ])
            .expose_headers([
                REQUEST_ID,
                header::RETRY_AFTER,
                header::WWW_AUTHENTICATE,
                HeaderName::from_static("server-timing"),
            ])
            .max_age(std::time::Duration::from_secs(600)),
    )
}
