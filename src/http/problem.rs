//! RFC 9457 problem details: the one place where failures become HTTP responses.
//!
//! Every error the service sends is `application/problem+json` with a stable `type` per failure
//! class, a machine-readable `code`, and an `errors[]` list of `{pointer, detail}` naming each
//! offending field by JSON pointer (RFC 6901).

use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde::Serialize;
use utoipa::ToSchema;

use crate::calc::{CalcFailure, FieldIssue, ProblemClass};

/// Media type of every error body.
pub const PROBLEM_JSON: &str = "application/problem+json";

/// One offending field of a request.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct ProblemField {
    /// JSON pointer (RFC 6901) into the request body; `""` is the whole body.
    #[schema(example = "/constraints/t_b")]
    pub pointer: String,
    /// What is wrong with the field and the limit it breaks.
    #[schema(example = "must be > t_a = 1, got 0.5")]
    pub detail: String,
}

/// An RFC 9457 problem-details body.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct Problem {
    /// Stable URI reference identifying the failure class, e.g. `/problems/invalid-input`.
    #[serde(rename = "type")]
    #[schema(example = "/problems/invalid-input")]
    pub type_uri: String,
    /// Short, human-readable summary of the class.
    #[schema(example = "Request failed validation")]
    pub title: String,
    /// HTTP status code.
    #[schema(example = 422)]
    pub status: u16,
    /// Explanation specific to this occurrence.
    #[schema(example = "2 fields failed validation")]
    pub detail: String,
    /// Stable machine-readable code clients can branch on (e.g. `INVALID_INPUT`, `UNDERCUT`).
    #[schema(example = "INVALID_INPUT")]
    pub code: String,
    /// Offending fields, each with a JSON pointer (empty when the failure is not tied to a field).
    pub errors: Vec<ProblemField>,
}

/// An error on its way to becoming a problem+json response (boxed: it travels in `Result`s).
#[derive(Debug, Clone)]
pub struct ApiError(Box<Inner>);

#[derive(Debug, Clone)]
struct Inner {
    status: StatusCode,
    slug: &'static str,
    title: &'static str,
    code: String,
    detail: String,
    errors: Vec<ProblemField>,
    retry_after_s: Option<u64>,
}

impl ApiError {
    fn new(
        status: StatusCode,
        slug: &'static str,
        title: &'static str,
        code: &str,
        detail: impl Into<String>,
    ) -> Self {
        Self(Box::new(Inner {
            status,
            slug,
            title,
            code: code.to_owned(),
            detail: detail.into(),
            errors: Vec::new(),
            retry_after_s: None,
        }))
    }

    /// Attach one offending field.
    #[must_use]
    pub fn with_field(mut self, pointer: impl Into<String>, detail: impl Into<String>) -> Self {
        self.0.errors.push(ProblemField {
            pointer: pointer.into(),
            detail: detail.into(),
        });
        self
    }

    /// 400: the body is not well-formed JSON.
    pub fn malformed_json(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::BAD_REQUEST,
            "malformed-json",
            "Malformed JSON body",
            "MALFORMED_JSON",
            detail,
        )
    }

    /// 415: the request's content type is not JSON.
    pub fn unsupported_media_type(got: Option<&str>) -> Self {
        let detail = match got {
            Some(ct) => format!("expected Content-Type: application/json, got {ct}"),
            None => {
                "expected Content-Type: application/json, got no Content-Type header".to_owned()
            }
        };
        Self::new(
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "unsupported-media-type",
            "Unsupported media type",
            "UNSUPPORTED_MEDIA_TYPE",
            detail,
        )
    }

    /// 413: the body exceeds the configured maximum size.
    pub fn body_too_large(limit_bytes: usize) -> Self {
        Self::new(
            StatusCode::PAYLOAD_TOO_LARGE,
            "body-too-large",
            "Request body too large",
            "BODY_TOO_LARGE",
            format!("request body exceeds the limit of {limit_bytes} bytes"),
        )
    }

    /// 404: no such route.
    pub fn not_found(path: &str) -> Self {
        Self::new(
            StatusCode::NOT_FOUND,
            "not-found",
            "Not found",
            "NOT_FOUND",
            format!("no endpoint at {path}; GET /v1 lists the endpoints"),
        )
    }

    /// 405: the route exists but not for this method.
    pub fn method_not_allowed(method: &str, path: &str) -> Self {
        Self::new(
            StatusCode::METHOD_NOT_ALLOWED,
            "method-not-allowed",
            "Method not allowed",
            "METHOD_NOT_ALLOWED",
            format!(
                "{method} is not allowed on {path}; GET /v1 lists the endpoints and their methods"
            ),
        )
    }

    /// 422 from a decode error (wrong type, missing or unknown field) at `pointer`.
    pub fn invalid_field(pointer: impl Into<String>, detail: impl Into<String>) -> Self {
        let pointer = pointer.into();
        let detail = detail.into();
        Self::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            "invalid-input",
            "Request failed validation",
            "INVALID_INPUT",
            format!(
                "{} {detail}",
                if pointer.is_empty() {
                    "body:"
                } else {
                    pointer.as_str()
                }
            ),
        )
        .with_field(pointer, detail)
    }

    /// 503: every compute slot is busy and the wait queue is full.
    pub fn overloaded(retry_after_s: u64) -> Self {
        let mut e = Self::new(
            StatusCode::SERVICE_UNAVAILABLE,
            "overloaded",
            "Compute pool saturated",
            "OVERLOADED",
            format!("all compute slots are busy; retry in {retry_after_s} s"),
        );
        e.0.retry_after_s = Some(retry_after_s);
        e
    }

    /// 406: the endpoint has no representation in the media type the client accepts.
    pub fn not_acceptable(route: &str) -> Self {
        Self::new(
            StatusCode::NOT_ACCEPTABLE,
            "not-acceptable",
            "Not acceptable",
            "NOT_ACCEPTABLE",
            format!("{route} answers application/json (and text/event-stream); it has no picture"),
        )
    }

    /// 406: the answer was computed but holds nothing the endpoint's picture can draw (for
    /// example a workspace sweep that accepted no node, or an empty shard); the JSON answer is
    /// still available with `Accept: application/json`.
    pub fn nothing_to_draw(route: &str, why: &str) -> Self {
        Self::new(
            StatusCode::NOT_ACCEPTABLE,
            "not-acceptable",
            "Not acceptable",
            "NOTHING_TO_DRAW",
            format!("{route}: no picture of this answer ({why}); ask for application/json"),
        )
    }

    /// 408: the request body did not arrive within the body timeout.
    pub fn request_timeout(timeout_ms: u64) -> Self {
        Self::new(
            StatusCode::REQUEST_TIMEOUT,
            "request-timeout",
            "Request body timeout",
            "REQUEST_TIMEOUT",
            format!("the request body did not arrive within {timeout_ms} ms"),
        )
    }

    /// 503: the service is stopping and takes no new work.
    pub fn shutting_down() -> Self {
        let mut e = Self::new(
            StatusCode::SERVICE_UNAVAILABLE,
            "overloaded",
            "Service stopping",
            "SHUTTING_DOWN",
            "the service is shutting down; retry against another replica",
        );
        e.0.retry_after_s = Some(1);
        e
    }

    /// 503 when the queue cannot start the job before its time budget runs out: refused at once
    /// instead of after waiting for nothing.
    pub fn cannot_start_in_time(retry_after_s: u64, wait_ms: u64, budget_ms: u64) -> Self {
        let mut e = Self::new(
            StatusCode::SERVICE_UNAVAILABLE,
            "overloaded",
            "Compute pool saturated",
            "OVERLOADED",
            format!(
                "the expected wait for a compute slot ({wait_ms} ms) exceeds the request's time \
                 budget ({budget_ms} ms); retry in {retry_after_s} s or send a larger time_limit_ms"
            ),
        );
        e.0.retry_after_s = Some(retry_after_s);
        e
    }

    /// 401: the request carries no bearer token, or one that matches no API key (the caller adds
    /// `WWW-Authenticate: Bearer`).
    pub fn unauthorized(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::UNAUTHORIZED,
            "unauthorized",
            "Unauthorized",
            "UNAUTHORIZED",
            detail,
        )
    }

    /// 429: the client sent more than its API key allows (`RATE_LIMITED`) or already has as many
    /// jobs waiting as one client may (`CLIENT_QUEUE_FULL`); retry after `retry_after_s`.
    pub fn too_many_requests(code: &str, retry_after_s: u64, detail: impl Into<String>) -> Self {
        let mut e = Self::new(
            StatusCode::TOO_MANY_REQUESTS,
            "too-many-requests",
            "Too many requests",
            code,
            detail,
        );
        e.0.retry_after_s = Some(retry_after_s);
        e
    }

    /// 500: a bug. The detail sent to the client is generic; the cause is logged, never echoed.
    pub fn internal() -> Self {
        Self::new(
            StatusCode::INTERNAL_SERVER_ERROR,
            "internal",
            "Internal error",
            "INTERNAL",
            "the service hit an internal error; it has been logged",
        )
    }

    /// HTTP status of this error.
    #[must_use]
    pub fn status(&self) -> StatusCode {
        self.0.status
    }

    /// The problem body.
    #[must_use]
    pub fn body(&self) -> Problem {
        let i = &self.0;
        Problem {
            type_uri: format!("/problems/{}", i.slug),
            title: i.title.to_owned(),
            status: i.status.as_u16(),
            detail: i.detail.clone(),
            code: i.code.clone(),
            errors: i.errors.clone(),
        }
    }
}

impl From<CalcFailure> for ApiError {
    fn from(f: CalcFailure) -> Self {
        let (slug, title) = match f.class {
            ProblemClass::InvalidInput => ("invalid-input", "Request failed validation"),
            ProblemClass::Infeasible => ("infeasible", "Input describes an infeasible design"),
            ProblemClass::NotConverged => ("not-converged", "Calculation did not converge"),
            ProblemClass::TooLarge => ("too-large", "Requested work exceeds the service limits"),
        };
        let mut e = Self::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            slug,
            title,
            f.code,
            f.detail,
        );
        e.0.errors = f
            .errors
            .into_iter()
            .map(|FieldIssue { pointer, detail }| ProblemField { pointer, detail })
            .collect();
        e
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let body = serde_json::to_vec(&self.body()).unwrap_or_else(|_| b"{}".to_vec());
        let mut resp = (self.0.status, body).into_response();
        let h = resp.headers_mut();
        h.insert(header::CONTENT_TYPE, HeaderValue::from_static(PROBLEM_JSON));
        if let Some(s) = self.0.retry_after_s {
            h.insert(header::RETRY_AFTER, HeaderValue::from(s));
        }
        resp
    }
}
