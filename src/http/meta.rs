//! Service endpoints that are not calculations: health, the endpoint index, the OpenAPI
//! document and the interactive API docs (Swagger UI, vendored so it works with no network on
//! the server side). The docs' "Authorize" button and the page's token field take an API key
//! token; `/healthz`, the page, the docs and the document itself answer without one.

use std::sync::OnceLock;

use axum::Json;
use axum::extract::State;
use axum::http::{HeaderValue, header};
use axum::response::{Html, IntoResponse, Response};
use serde::Serialize;
use utoipa::ToSchema;

use super::auth::AuthResponses;
use super::state::AppState;

/// Liveness and basic capacity information.
#[derive(Debug, Serialize, ToSchema)]
pub struct Health {
    /// Always `"ok"` when the service answers.
    #[schema(example = "ok")]
    pub status: &'static str,
    /// Service version (Cargo package version).
    #[schema(example = "0.1.0")]
    pub version: &'static str,
    /// Compute slots free right now.
    pub compute_slots_free: usize,
}

/// Service health.
#[utoipa::path(
    get,
    path = "/healthz",
    tag = "service",
    operation_id = "get_health",
    security(()),
    responses((status = 200, description = "The service is up (never behind API keys)", body = Health))
)]
pub async fn healthz(State(state): State<AppState>) -> Json<Health> {
    Json(Health {
        status: "ok",
        version: env!("CARGO_PKG_VERSION"),
        compute_slots_free: state.pool.available_slots(),
    })
}

/// One endpoint of the service.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct EndpointLine {
    /// HTTP method.
    #[schema(example = "POST")]
    pub method: String,
    /// Path.
    #[schema(example = "/v1/cam-law/evaluate")]
    pub path: String,
    /// One-line description.
    pub summary: String,
}

/// The endpoint index.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct EndpointIndex {
    /// Service name.
    #[schema(example = "mechcalc")]
    pub service: &'static str,
    /// Service version.
    pub version: &'static str,
    /// Path of the OpenAPI document.
    #[schema(example = "/openapi.json")]
    pub openapi: &'static str,
    /// Path of the interactive API docs.
    #[schema(example = "/docs")]
    pub docs: &'static str,
    /// Every endpoint, one line each.
    pub endpoints: Vec<EndpointLine>,
}

/// The index, built from the OpenAPI document so it cannot drift from it.
#[must_use]
pub fn endpoint_index() -> EndpointIndex {
    let api = super::openapi();
    let mut endpoints = Vec::new();
    for (path, item) in &api.paths.paths {
        let ops = [
            ("GET", item.get.as_ref()),
            ("POST", item.post.as_ref()),
            ("PUT", item.put.as_ref()),
            ("DELETE", item.delete.as_ref()),
        ];
        for (method, op) in ops {
            if let Some(op) = op {
                endpoints.push(EndpointLine {
                    method: method.to_owned(),
                    path: path.clone(),
                    summary: op.summary.clone().unwrap_or_default(),
                });
            }
        }
    }
    EndpointIndex {
        service: "mechcalc",
        version: env!("CARGO_PKG_VERSION"),
        openapi: "/openapi.json",
        docs: "/docs",
        endpoints,
    }
}

/// List the endpoints, one line each.
#[utoipa::path(
    get,
    path = "/v1",
    tag = "service",
    operation_id = "list_endpoints",
    responses((status = 200, description = "Every endpoint with a one-line summary", body = EndpointIndex), AuthResponses)
)]
pub async fn index() -> Response {
    static BODY: OnceLock<Vec<u8>> = OnceLock::new();
    json_bytes(BODY.get_or_init(|| serde_json::to_vec(&endpoint_index()).unwrap_or_default()))
}

/// The OpenAPI 3.1 document (JSON), serialized once per process.
pub async fn openapi_json() -> Response {
    static BODY: OnceLock<Vec<u8>> = OnceLock::new();
    json_bytes(
        BODY.get_or_init(|| {
            serde_json::to_vec_pretty(super::openapi::document()).unwrap_or_default()
        }),
    )
}

fn json_bytes(body: &'static [u8]) -> Response {
    let mut r = body.into_response();
    r.headers_mut().insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("application/json"),
    );
    r
}

/// An `api/` example request, embedded in the binary.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct ExampleRequest {
    /// File name under `api/`.
    pub file: &'static str,
    /// The endpoint it is sent to.
    pub endpoint: &'static str,
    /// The request body.
    #[schema(value_type = Object)]
    pub request: serde_json::Value,
}

mod embedded {
    include!(concat!(env!("OUT_DIR"), "/examples.rs"));
}

/// Every `api/` example request (ready to send; the page at `/` loads them).
#[utoipa::path(
    get,
    path = "/v1/examples",
    tag = "service",
    operation_id = "list_examples",
    responses((status = 200, description = "Every example request with its endpoint", body = [ExampleRequest]), AuthResponses)
)]
pub async fn examples() -> Response {
    static BODY: OnceLock<Vec<u8>> = OnceLock::new();
    json_bytes(BODY.get_or_init(|| {
        let list: Vec<ExampleRequest> = embedded::EXAMPLES
            .iter()
            .map(|(file, endpoint, body)| ExampleRequest {
                file,
                endpoint,
                request: serde_json::from_str(body).unwrap_or_default(),
            })
            .collect();
        serde_json::to_vec(&list).unwrap_or_default()
    }))
}

const INDEX_HTML: &str = include_str!("../../assets/index.html");

/// The browser page: endpoints, examples in an editable box, the JSON answer and its picture.
pub async fn page() -> Html<&'static str> {
    Html(INDEX_HTML)
}

/// Prometheus metrics of this process (text exposition format), built from the `metrics`
/// facade: requests by route and status, latency histograms, job times by lane, compute-slot
/// and queue occupancy, cancelled jobs, budget stops, rejections.
pub async fn metrics(State(state): State<AppState>) -> Response {
    let pool = &state.pool;
    metrics::gauge!("mechcalc_compute_slots").set(pool.slots() as f64);
    metrics::gauge!("mechcalc_compute_slots_free").set(pool.available_slots() as f64);
    metrics::gauge!("mechcalc_queue_depth_waiting").set(pool.waiting() as f64);
    let body = super::telemetry::render();
    let mut r = body.into_response();
    r.headers_mut().insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("text/plain; version=0.0.4; charset=utf-8"),
    );
    r
}

const DOCS_HTML: &str = r##"<!doctype html>
<html lang="en">
<head>
  <meta charset="utf-8">
  <title>mechcalc API</title>
  <link rel="stylesheet" href="/docs/swagger-ui.css">
</head>
<body>
  <div id="swagger-ui"></div>
  <script src="/docs/swagger-ui-bundle.js"></script>
  <script>
    // "Authorize" takes the API key token (the document's bearer scheme); it lives in this page
    // only and is sent with every "Try it out".
    window.ui = SwaggerUIBundle({ url: "/openapi.json", dom_id: "#swagger-ui", deepLinking: true });
  </script>
</body>
</html>
"##;

/// Interactive API docs.
pub async fn docs() -> Html<&'static str> {
    Html(DOCS_HTML)
}

const SWAGGER_JS: &[u8] = include_bytes!("../../assets/swagger-ui/swagger-ui-bundle.js");
const SWAGGER_CSS: &[u8] = include_bytes!("../../assets/swagger-ui/swagger-ui.css");

fn asset(bytes: &'static [u8], content_type: &'static str) -> Response {
    let mut r = bytes.into_response();
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    h.insert(
        header::CACHE_CONTROL,
        HeaderValue::from_static("public, max-age=86400"),
    );
    r
}

/// Swagger UI script.
pub async fn swagger_js() -> Response {
    asset(SWAGGER_JS, "text/javascript; charset=utf-8")
}

/// Swagger UI stylesheet.
pub async fn swagger_css() -> Response {
    asset(SWAGGER_CSS, "text/css; charset=utf-8")
}
