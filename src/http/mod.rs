//! The HTTP layer: router, OpenAPI document, problem+json errors, the JSON extractor, the
//! compute pool and the request log. Calculations live in [`crate::calc`]; a handler here only
//! decodes, runs the module's `run` on the compute pool, and responds.
//!
//! Adding an endpoint: write `src/http/<module>.rs` with a `#[utoipa::path]` handler that calls
//! [`run_calc`], and register it in `api_router` with one `.routes(routes!(...))` line.

pub mod auth;
pub mod bezier_motion;
pub mod bus_fuel_economy;
pub mod cam_law;
pub mod cam_law_fit;
pub mod cognates;
pub mod component_importance;
pub mod continuum_workspace;
pub mod formats;
pub mod irefc;
pub mod json;
pub mod layers;
pub mod machining_size;
pub mod memory;
pub mod meta;
pub mod openapi;
pub mod picture;
pub mod pool;
pub mod problem;
pub mod serve;
pub mod spatial_coupling;
pub mod state;
pub mod stream;
pub mod strict;
pub mod telemetry;
pub mod vibration_absorber;

pub mod finite;

use axum::Router;
use axum::body::Body;
use axum::extract::DefaultBodyLimit;
use axum::http::{HeaderName, HeaderValue, Method, Uri, header};
use axum::middleware;
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use serde::Serialize;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::request_id::{PropagateRequestIdLayer, SetRequestIdLayer};
use tower_http::set_header::SetResponseHeaderLayer;
use utoipa::OpenApi;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::calc::CalcFailure;
use crate::numerics::Budget;

pub use json::{ApiJson, Valid};
pub use problem::{ApiError, Problem, ProblemField};
pub use state::AppState;

/// Error responses every calculation endpoint can give (all `application/problem+json`).
#[derive(utoipa::IntoResponses)]
pub enum ProblemResponses {
    /// The body is not well-formed JSON.
    #[response(
        status = 400,
        description = "Malformed JSON (`/problems/malformed-json`)",
        content_type = "application/problem+json"
    )]
    MalformedJson(Problem),
    /// The endpoint has no picture (`Accept: image/svg+xml`).
    #[response(
        status = 406,
        description = "No representation in the accepted media type (`/problems/not-acceptable`)",
        content_type = "application/problem+json"
    )]
    NotAcceptable(Problem),
    /// The body did not arrive within the body timeout.
    #[response(
        status = 408,
        description = "Request body timeout (`/problems/request-timeout`)",
        content_type = "application/problem+json"
    )]
    RequestTimeout(Problem),
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
    /// No bearer token, or one that matches no API key (only when the service has API keys).
    #[response(status = 401, description = "Missing or unknown API key (`/problems/unauthorized`); send `Authorization: Bearer <token>`", content_type = "application/problem+json", headers(("WWW-Authenticate" = String, description = "`Bearer realm=\"mechcalc\"`")))]
    Unauthorized(Problem),
    /// The key's rate is spent, or the client has its share of waiting jobs.
    #[response(status = 429, description = "The API key's requests per minute are spent (`RATE_LIMITED`) or the client has as many jobs waiting as one client may (`CLIENT_QUEUE_FULL`) (`/problems/too-many-requests`); retry after `Retry-After` seconds", content_type = "application/problem+json", headers(("Retry-After" = u64, description = "Seconds to wait before retrying")))]
    TooManyRequests(Problem),
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
        (name = "motion-laws", description = "Servo motion laws: Bezier laws with zero residual vibration of a compliant drive"),
        (name = "continuum-robots", description = "Parallel continuum manipulators: forward kinematics, stability, assembly modes and workspace"),
        (name = "machining-size", description = "Machined dimensions: gradient-boosted trees with XGBoost's semantics, exact SHAP explanations and the paper's data diagnostics"),
        (name = "spatial-linkages", description = "Spatial couplings: closed-form kinematics of the RP1PR coupling between crossed shafts"),
        (name = "vibration", description = "Structural vibration control: active electromagnetic vibration absorber on a cantilever"),
    ),
    components(schemas(Problem, ProblemField)),
    modifiers(&BearerAuth)
)]
struct ApiDoc;

/// The bearer security scheme, required by every operation that does not opt out (`/healthz`).
struct BearerAuth;

impl utoipa::Modify for BearerAuth {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::security::{
            HttpAuthScheme, HttpBuilder, SecurityRequirement, SecurityScheme,
        };
        doc.components
            .get_or_insert_with(Default::default)
            .add_security_scheme(
                auth::SCHEME,
                SecurityScheme::Http(
                    HttpBuilder::new()
                        .scheme(HttpAuthScheme::Bearer)
                        .description(Some(
                            "API key token (only when the service runs with `--api-keys-file`): \
                         `Authorization: Bearer <token>`",
                        ))
                        .build(),
                ),
            );
        doc.security = Some(vec![SecurityRequirement::new(
            auth::SCHEME,
            Vec::<String>::new(),
        )]);
    }
}

/// The documented routes; the OpenAPI document is generated from exactly these. Also returns
/// the schema names claimed by two different Rust types (see [`openapi::Registry`]).
fn api_router() -> (OpenApiRouter<AppState>, Vec<String>) {
    openapi::Registry::new(OpenApiRouter::with_openapi(ApiDoc::openapi()))
        .route(routes!(meta::healthz))
        .route(routes!(meta::index))
        .route(routes!(meta::examples))
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
        .route(routes!(spatial_coupling::evaluate))
        .route(routes!(vibration_absorber::analyze))
        .route(routes!(bezier_motion::solve))
        .finish()
}

/// The rules between fields (and of feasibility) of each POST operation, for the document's
/// `x-cross-field-rules` (see [`crate::calc::rules::CrossRule`]).
#[must_use]
pub fn cross_field_rules() -> Vec<(&'static str, &'static [crate::calc::CrossRule])> {
    use crate::calc;
    vec![
        (
            "/v1/bezier-motion-law",
            calc::bezier_motion::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/bus-fuel-economy",
            calc::bus_fuel_economy::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/bus-fuel-economy/motor-map",
            calc::bus_fuel_economy::input::MOTOR_MAP_RULES,
        ),
        (
            "/v1/cam-law/evaluate",
            calc::cam_law::input::CROSS_FIELD_RULES,
        ),
        ("/v1/cognates", calc::cognates::input::CROSS_FIELD_RULES),
        (
            "/v1/component-importance",
            calc::component_importance::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/continuum-workspace",
            calc::continuum_workspace::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/fit-cam-law",
            calc::cam_law_fit::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/irefc-efficiency",
            calc::irefc::efficiency::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/irefc-stress",
            calc::irefc::stress::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/machining-size/analyze",
            calc::machining_size::input::ANALYZE_RULES,
        ),
        (
            "/v1/machining-size/predict",
            calc::machining_size::input::PREDICT_RULES,
        ),
        (
            "/v1/machining-size/train",
            calc::machining_size::input::TRAIN_RULES,
        ),
        (
            "/v1/spatial-coupling",
            calc::spatial_coupling::input::CROSS_FIELD_RULES,
        ),
        (
            "/v1/vibration-absorber",
            calc::vibration_absorber::input::CROSS_FIELD_RULES,
        ),
    ]
}

/// The document as utoipa generates it, before [`openapi::document`] completes it.
fn api_parts() -> (utoipa::openapi::OpenApi, Vec<String>) {
    let (router, conflicts) = api_router();
    (router.split_for_parts().1, conflicts)
}

/// The OpenAPI document of the service (generated from the handlers and wire types, completed
/// from the bounds tables; see [`openapi`](mod@openapi)).
#[must_use]
pub fn openapi() -> utoipa::openapi::OpenApi {
    serde_json::from_value(openapi::document().clone()).unwrap_or_else(|_| api_parts().0)
}

/// The OpenAPI document as YAML (`openapi.yaml`, `--print-openapi`): the very document served at
/// `/openapi.json`, keyword for keyword (a round trip through utoipa's types would drop the
/// keywords they do not model, such as a `oneOf` beside `properties`).
///
/// # Errors
/// The YAML writer's failure (not expected for a JSON document).
pub fn openapi_yaml() -> Result<String, serde_norway::Error> {
    serde_norway::to_string(openapi::document())
}

/// The routes of the application, built once per process (generating the routes' OpenAPI
/// items is most of the cost of building the app; tests and `mechcalc run` build many apps).
fn routes() -> Router<AppState> {
    static ROUTES: std::sync::OnceLock<Router<AppState>> = std::sync::OnceLock::new();
    ROUTES
        .get_or_init(|| {
            let (router, _api) = api_router().0.split_for_parts();
            router
                .route("/", get(meta::page))
                .route("/openapi.json", get(meta::openapi_json))
                .route("/metrics", get(meta::metrics))
                .route("/docs", get(meta::docs))
                .route("/docs/", get(meta::docs))
                .route("/docs/swagger-ui-bundle.js", get(meta::swagger_js))
                .route("/docs/swagger-ui.css", get(meta::swagger_css))
                .fallback(not_found)
                .method_not_allowed_fallback(method_not_allowed)
        })
        .clone()
}

/// The whole application. Tests drive it without a socket.
pub fn app(state: AppState) -> Router {
    let body_limit = state.config.max_body_bytes;
    let authenticate = middleware::from_fn_with_state(state.clone(), auth::authenticate);
    let cors = layers::cors(&state.config.cors_origins);
    // The idle keep-alive limit (the request-head timeout), announced so clients replace a pooled
    // connection before the server closes it rather than write a request into a closed one.
    let keep_alive = HeaderValue::from_str(&format!(
        "timeout={}",
        (state.config.header_timeout_ms / 1000).max(1)
    ))
    .unwrap_or_else(|_| HeaderValue::from_static("timeout=1"));
    let mut app = routes()
        .with_state(state)
        .layer(DefaultBodyLimit::max(body_limit))
        .layer(CatchPanicLayer::custom(panic_response))
        .layer(middleware::from_fn(picture::picture))
        .layer(middleware::from_fn(formats::formats))
        .layer(middleware::from_fn(stream::event_stream))
        .layer(authenticate)
        .layer(middleware::from_fn(layers::log_request));
    for (name, value) in layers::hardening_headers() {
        app = app.layer(SetResponseHeaderLayer::if_not_present(name, value));
    }
    app = app.layer(SetResponseHeaderLayer::if_not_present(
        HeaderName::from_static("keep-alive"),
        keep_alive,
    ));
    if let Some(cors) = cors {
        app = app.layer(cors);
    }
    app.layer(PropagateRequestIdLayer::new(layers::REQUEST_ID))
        .layer(SetRequestIdLayer::new(
            layers::REQUEST_ID,
            layers::MakeId::default(),
        ))
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

/// Serialize a calculation's response as JSON, refusing to send a non-finite number (a defect:
/// logged as an error, answered with 422 `NON_FINITE_ANSWER`).
pub fn respond<T: Serialize>(value: &T) -> Result<Response, ApiError> {
    encode(value).map(json_response)
}

/// First capacity of an answer's buffer [bytes].
const ENCODE_CAPACITY: usize = 16 * 1024;

/// The JSON body of a response, written once into a pre-sized buffer, with the finite-number
/// guard folded into that one pass: serde_json writes a non-finite float as `null`, so the
/// writer refuses every `null`. Answers of calculations hold no `null` (absent fields are
/// omitted), so the common case is one pass; when a `null` does come, the value is walked for a
/// non-finite number (found: a 422 naming it) and, if it was a legitimate `null`, written again
/// without the guard. Runs inside the compute job, so large answers are encoded on the bounded
/// compute pool, not on the threads that accept connections.
pub fn encode<T: Serialize>(value: &T) -> Result<Vec<u8>, ApiError> {
    // Pre-sized: most answers fit, and a large one (tens of KB) doubles a few times at most.
    let mut body = Vec::with_capacity(ENCODE_CAPACITY);
    let mut guarded = serde_json::Serializer::with_formatter(&mut body, NoNull);
    match value.serialize(&mut guarded) {
        Ok(()) => return Ok(body),
        Err(e) if !e.is_io() => return Err(serialization_failed(&e)),
        Err(_) => {}
    }
    if let Some(pointer) = finite::first_non_finite(value) {
        // Still a defect of the module (logged as an error for the developers), but the client
        // gets a typed refusal naming the number, never a NaN and never a 500.
        tracing::error!(%pointer, "calculation produced a non-finite number");
        return Err(ApiError::from(
            crate::calc::common::NON_FINITE_ANSWER_RULE.fail_general(format!(
                "the answer's {pointer} is not a finite number for these inputs (they lie at the \
                 extremes of their ranges); the service refuses the request rather than send it"
            )),
        ));
    }
    body.clear();
    serde_json::to_writer(&mut body, value).map_err(|e| serialization_failed(&e))?;
    Ok(body)
}

fn serialization_failed(e: &serde_json::Error) -> ApiError {
    tracing::error!(error = %e, "response serialization failed");
    ApiError::internal()
}

/// serde_json's compact format, refusing to write `null` (where a non-finite float would go).
struct NoNull;

impl serde_json::ser::Formatter for NoNull {
    fn write_null<W: ?Sized + std::io::Write>(&mut self, _: &mut W) -> std::io::Result<()> {
        Err(std::io::Error::other("null in an answer"))
    }
}

/// An `application/json` response from an encoded body.
fn json_response(body: Vec<u8>) -> Response {
    let mut r = body.into_response();
    r.headers_mut().insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("application/json"),
    );
    r
}

/// Run a module's calculation on the compute pool with a budget of `limit` (capped by the server
/// maximum), encode its answer there too, map its failure to problem+json and respond.
///
/// `demand` is the request's time limit (`Option<Duration>`) or a [`pool::Demand`] that also
/// carries the module's cost estimate. An answer larger than `--max-response-bytes` is refused
/// with a 422 (`/problems/too-large`) after encoding, as a backstop; modules that can tell the
/// size before computing refuse earlier, naming the option to change (the limit reaches them in
/// the [`Budget`], see [`crate::calc::common::ResponseSize`]).
pub async fn run_calc<T, F>(
    state: &AppState,
    demand: impl Into<pool::Demand>,
    job: F,
) -> Result<Response, ApiError>
where
    T: Serialize + Send + 'static,
    F: FnOnce(&Budget) -> Result<T, CalcFailure> + Send + 'static,
{
    let max_bytes = state.config.max_response_bytes;
    let arrived = std::time::Instant::now();
    let (body, compute, encoding, started, ended) = state
        .pool
        .run(demand, move |budget| {
            let started = std::time::Instant::now();
            // The limit reaches the module, which refuses an oversized answer before computing.
            let budget = &budget.clone().with_max_response_bytes(max_bytes);
            let out = job(budget).map_err(ApiError::from)?;
            let computed = std::time::Instant::now();
            let body = encode(&out)?;
            drop(out);
            if body.len() > max_bytes {
                return Err(ApiError::from(CalcFailure::general(
                    crate::calc::ProblemClass::TooLarge,
                    "RESPONSE_TOO_LARGE",
                    format!(
                        "the answer is {} bytes, over the service's limit of {max_bytes} \
                         bytes; request fewer points or fewer optional outputs",
                        body.len()
                    ),
                )));
            }
            Ok((
                body,
                computed - started,
                computed.elapsed(),
                started,
                std::time::Instant::now(),
            ))
        })
        .await??;
    // From the job's end to this task running again (the hand-back from a compute thread).
    let handback = ended.elapsed();
    let mut r = json_response(body);
    // Server-Timing (W3C): where the time of this answer went, for clients and benchmarks.
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let queue = started.saturating_duration_since(arrived);
    // The door (parse, rules) ran before `arrived`; reported apart so the three stages after it
    // keep their meaning.
    let door_ns = pool::REQUEST_INFO
        .try_with(|i| i.door_ns.load(std::sync::atomic::Ordering::Relaxed))
        .unwrap_or(0);
    let door = if door_ns == 0 {
        String::new()
    } else {
        format!("door;dur={:.3}, ", door_ns as f64 * 1e-6)
    };
    if let Ok(v) = HeaderValue::from_str(&format!(
        "{door}queue;dur={:.3}, compute;dur={:.3}, encode;dur={:.3}, handback;dur={:.3}",
        ms(queue),
        ms(compute),
        ms(encoding),
        ms(handback)
    )) {
        r.headers_mut()
            .insert(HeaderName::from_static("server-timing"), v);
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::encode;
    use serde::Serialize;

    #[derive(Serialize)]
    struct Answer {
        x: Vec<f64>,
        maybe: Option<f64>,
        #[serde(skip_serializing_if = "Option::is_none")]
        omitted: Option<f64>,
    }

    #[test]
    fn encode_writes_what_serde_json_writes() {
        for a in [
            Answer {
                x: vec![1.0, -2.5e-300, 3.0e12],
                maybe: Some(0.1),
                omitted: None,
            },
            // A legitimate `null` takes the slow path and still gives the same bytes.
            Answer {
                x: vec![],
                maybe: None,
                omitted: Some(7.0),
            },
        ] {
            let got = encode(&a).expect("finite answer");
            assert_eq!(got, serde_json::to_vec(&a).expect("json"));
        }
    }

    #[test]
    fn encode_refuses_a_non_finite_number_naming_it() {
        for (bad, at) in [
            (f64::NAN, "/x/1"),
            (f64::INFINITY, "/x/1"),
            (f64::NEG_INFINITY, "/x/1"),
        ] {
            let a = Answer {
                x: vec![1.0, bad],
                maybe: None,
                omitted: None,
            };
            let e = encode(&a).expect_err("non-finite");
            assert_eq!(e.status(), axum::http::StatusCode::UNPROCESSABLE_ENTITY);
            let body = serde_json::to_value(e.body()).expect("problem");
            assert_eq!(body["code"], "NON_FINITE_ANSWER", "{body}");
            assert!(
                body["detail"].as_str().is_some_and(|d| d.contains(at)),
                "{body}"
            );
        }
    }
}
