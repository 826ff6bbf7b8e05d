//! The HTTP layer: router, OpenAPI document, problem+json errors, the JSON extractor, the
//! compute pool and the request log. Calculations live in [`crate::calc`]; a handler here only
//! decodes, runs the module's `run` on the compute pool, and responds.
//!
//! Adding an endpoint: write `src/http/<module>.rs` with a `#[utoipa::path]` handler that calls
//! [`run_calc`], and register it in `api_router` with one `.routes(routes!(...))` line.

pub mod bus_fuel_economy;
pub mod cam_law;
pub mod cam_law_fit;
pub mod cognates;
pub mod component_importance;
pub mod continuum_workspace;
pub mod irefc;
pub mod json;
pub mod machining_size;
pub mod meta;
pub mod openapi;
pub mod pool;
pub mod problem;
pub mod state;

pub mod finite;

use std::time::{Duration, Instant};

use axum::Router;
use axum::body::Body;
use axum::extract::{DefaultBodyLimit, Request};
use axum::http::{HeaderValue, Method, Uri, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use serde::Serialize;
use tower_http::catch_panic::CatchPanicLayer;
use tracing::Instrument;
use utoipa::OpenApi;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::calc::CalcFailure;
use crate::numerics::Budget;

pub use json::ApiJson;
pub use problem::{ApiError, Problem, ProblemField};
pub use state::AppState;

/// Error responses every calculation endpoint can give (all `application/problem+json`).
#[derive(utoipa::IntoResponses)]
#[allow(dead_code)]
pub enum ProblemResponses {
    /// The body is not well-formed JSON.
    #[response(
        status = 400,
        description = "Malformed JSON (`/problems/malformed-json`)",
        content_type = "application/problem+json"
    )]
    MalformedJson(Problem),
    /// The body exceeds the configured size limit.
    #[response(
        status = 413,
        description = "Body too large (`/problems/body-too-large`)",
        content_type = "application/problem+json"
    )]
    TooLarge(Problem),
    /// The Content-Type is not JSON.
    #[response(
        status = 415,
        description = "Content-Type is not application/json (`/problems/unsupported-media-type`)",
        content_type = "application/problem+json"
    )]
    UnsupportedMediaType(Problem),
    /// Invalid, infeasible, non-converged or oversized input; `errors[]` points at each offending field.
    #[response(
        status = 422,
        description = "Invalid or infeasible input (`/problems/invalid-input`, `/problems/infeasible`, `/problems/not-converged`, `/problems/too-large`)",
        content_type = "application/problem+json"
    )]
    Unprocessable(Problem),
    /// A bug; the detail is logged, never echoed.
    #[response(
        status = 500,
        description = "Internal error (`/problems/internal`)",
        content_type = "application/problem+json"
    )]
    Internal(Problem),
    /// Every compute slot is busy and the queue is full.
    #[response(status = 503, description = "Compute pool saturated (`/problems/overloaded`); retry after `Retry-After` seconds", content_type = "application/problem+json", headers(("Retry-After" = u64, description = "Seconds to wait before retrying")))]
    Overloaded(Problem),
}

#[derive(OpenApi)]
#[openapi(
    info(
        title = "mechcalc",
        description = "Research methods from machine design as fast, exact, validated calculations. \
Every error is `application/problem+json` (RFC 9457) with a stable `type`, a `code` and an `errors[]` list of \
JSON pointers to the offending fields.",
        license(name = "MIT OR Apache-2.0")
    ),
    tags(
        (name = "service", description = "Health and discovery"),
        (name = "cam-law", description = "Cam motion laws: evaluation and identification"),
        (name = "linkages", description = "Planar linkages: Roberts–Chebyshev cognates of a four-bar"),
        (name = "reliability", description = "Reliability and maintenance: component importance under fault propagation"),
        (name = "bus-fuel-economy", description = "Drive-cycle energy of an electric bus with an AC-loss-aware traction motor"),
        (name = "irefc", description = "Cycloid gears with intermediate rolling elements and a free cage: contact stresses, design sweeps, efficiency"),
        (name = "continuum-robots", description = "Parallel continuum manipulators: forward kinematics, stability, assembly modes and workspace"),
        (name = "machining-size", description = "Machined dimensions: gradient-boosted trees with XGBoost's semantics, exact SHAP explanations and the paper's data diagnostics"),
    ),
    components(schemas(Problem, ProblemField))
)]
struct ApiDoc;

/// The documented routes; the OpenAPI document is generated from exactly these. Also returns
/// the schema names claimed by two different Rust types (see [`openapi::Registry`]).
fn api_router() -> (OpenApiRouter<AppState>, Vec<String>) {
    openapi::Registry::new(OpenApiRouter::with_openapi(ApiDoc::openapi()))
        .route(routes!(meta::healthz))
        .route(routes!(meta::index))
        .route(routes!(cam_law::evaluate))
        .route(routes!(cam_law_fit::fit))
        .route(routes!(cognates::construct))
        .route(routes!(component_importance::rank))
        .route(routes!(bus_fuel_economy::compute))
        .route(routes!(bus_fuel_economy::motor_map))
        .route(routes!(irefc::stress))
        .route(routes!(irefc::efficiency))
        .route(routes!(continuum_workspace::solve))
        .route(routes!(machining_size::train))
        .route(routes!(machining_size::predict))
        .route(routes!(machining_size::analyze))
        .finish()
}

/// The document as utoipa generates it, before [`openapi::document`] completes it.
fn api_parts() -> (utoipa::openapi::OpenApi, Vec<String>) {
    let (router, conflicts) = api_router();
    (router.split_for_parts().1, conflicts)
}

/// The OpenAPI document of the service (generated from the handlers and wire types, completed
/// from the bounds tables; see [`openapi`]).
#[must_use]
pub fn openapi() -> utoipa::openapi::OpenApi {
    serde_json::from_value(openapi::document().clone()).unwrap_or_else(|_| api_parts().0)
}

/// The whole application. Tests drive it without a socket.
pub fn app(state: AppState) -> Router {
    let (router, _api) = api_router().0.split_for_parts();
    let body_limit = state.config.max_body_bytes;
    router
        .route("/openapi.json", get(meta::openapi_json))
        .route("/docs", get(meta::docs))
        .route("/docs/", get(meta::docs))
        .route("/docs/swagger-ui-bundle.js", get(meta::swagger_js))
        .route("/docs/swagger-ui.css", get(meta::swagger_css))
        .fallback(not_found)
        .method_not_allowed_fallback(method_not_allowed)
        .with_state(state)
        .layer(DefaultBodyLimit::max(body_limit))
        .layer(CatchPanicLayer::custom(panic_response))
        .layer(middleware::from_fn(log_request))
}

async fn not_found(uri: Uri) -> ApiError {
    ApiError::not_found(uri.path())
}

async fn method_not_allowed(method: Method, uri: Uri) -> ApiError {
    ApiError::method_not_allowed(method.as_str(), uri.path())
}

fn panic_response(payload: Box<dyn std::any::Any + Send + 'static>) -> Response<Body> {
    tracing::error!(panic = %pool::panic_message(payload), "handler panicked");
    ApiError::internal().into_response()
}

/// One structured log line per request: method, path, status, latency. Bodies are never logged.
async fn log_request(req: Request, next: Next) -> Response {
    let method = req.method().clone();
    let path = req.uri().path().to_owned();
    let span = tracing::info_span!("request", %method, %path);
    let start = Instant::now();
    let resp = next.run(req).instrument(span).await;
    let latency_ms = start.elapsed().as_secs_f64() * 1e3;
    tracing::info!(%method, %path, status = resp.status().as_u16(), latency_ms, "request");
    resp
}

/// Serialize a calculation's response as JSON, refusing to send a non-finite number (a bug:
/// logged, answered with 500).
pub fn respond<T: Serialize>(value: &T) -> Result<Response, ApiError> {
    if let Some(pointer) = finite::first_non_finite(value) {
        tracing::error!(%pointer, "calculation produced a non-finite number");
        return Err(ApiError::internal());
    }
    let body = serde_json::to_vec(value).map_err(|e| {
        tracing::error!(error = %e, "response serialization failed");
        ApiError::internal()
    })?;
    let mut r = body.into_response();
    r.headers_mut().insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("application/json"),
    );
    Ok(r)
}

/// Run a module's calculation on the compute pool with a budget of `limit` (capped by the server
/// maximum), map its failure to problem+json and respond.
pub async fn run_calc<T, F>(
    state: &AppState,
    limit: Option<Duration>,
    job: F,
) -> Result<Response, ApiError>
where
    T: Serialize + Send + 'static,
    F: FnOnce(&Budget) -> Result<T, CalcFailure> + Send + 'static,
{
    let out = state.pool.run(limit, job).await??;
    respond(&out)
}
