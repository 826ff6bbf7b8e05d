//! Reports, tables and drawings by content negotiation (modelled on [`super::picture`]): a
//! calculation requested with `Accept: text/html` answers with its calculation report,
//! `text/csv` with a table of its answer (`?table=NAME` picks one), `image/vnd.dxf` with its
//! geometry ([`crate::export`]). The request runs exactly as a JSON request would (a drawing first
//! turns on the outputs it needs, as a picture does); a refused request answers with its problem
//! details. A format the endpoint does not offer is a 406 listing the media types it does offer.
//! Without one of these `Accept` types nothing changes.

use axum::body::{Body, to_bytes};
use axum::extract::{MatchedPath, Request};
use axum::http::{HeaderValue, Method, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use serde_json::Value;

use super::problem::{ApiError, PROBLEM_JSON, Problem};
use crate::export::{self, CSV, DXF, HTML};

/// A format this middleware answers in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The calculation report.
    Html,
    /// A table.
    Csv,
    /// A drawing.
    Dxf,
}

impl Format {
    /// Its media type.
    #[must_use]
    pub const fn media_type(self) -> &'static str {
        match self {
            Self::Html => HTML,
            Self::Csv => CSV,
            Self::Dxf => DXF,
        }
    }

    const fn content_type(self) -> &'static str {
        match self {
            Self::Html => "text/html; charset=utf-8",
            Self::Csv => "text/csv; charset=utf-8; header=present",
            Self::Dxf => "image/vnd.dxf",
        }
    }

    const fn extension(self) -> &'static str {
        match self {
            Self::Html => "html",
            Self::Csv => "csv",
            Self::Dxf => "dxf",
        }
    }
}

/// The format the client prefers: the first media type its `Accept` names among JSON, the event
/// stream, SVG and ours, when it is ours.
fn wanted(req: &Request) -> Option<Format> {
    if req.method() != Method::POST {
        return None;
    }
    let accept = req.headers().get(header::ACCEPT)?.to_str().ok()?;
    let first = |t: &str| accept.find(t);
    let others = ["application/json", "text/event-stream", "image/svg+xml"]
        .iter()
        .filter_map(|t| first(t))
        .min();
    [Format::Html, Format::Csv, Format::Dxf]
        .into_iter()
        .filter_map(|f| first(f.media_type()).map(|i| (i, f)))
        .min_by_key(|(i, _)| *i)
        .filter(|(i, _)| others.is_none_or(|o| *i < o))
        .map(|(_, f)| f)
}

/// The `table` query parameter.
fn table_param(req: &Request) -> Option<String> {
    req.uri().query()?.split('&').find_map(|kv| {
        let (k, v) = kv.split_once('=')?;
        (k == "table").then(|| v.to_owned())
    })
}

/// A 406 problem+json answer.
fn not_acceptable(code: &str, detail: String) -> Response {
    let p = Problem {
        type_uri: "/problems/not-acceptable".to_owned(),
        title: "Not acceptable".to_owned(),
        status: StatusCode::NOT_ACCEPTABLE.as_u16(),
        detail,
        code: code.to_owned(),
        errors: Vec::new(),
    };
    let body = serde_json::to_vec(&p).unwrap_or_default();
    let mut r = (StatusCode::NOT_ACCEPTABLE, body).into_response();
    r.headers_mut()
        .insert(header::CONTENT_TYPE, HeaderValue::from_static(PROBLEM_JSON));
    r
}

/// The 406 of an endpoint that does not offer `format`, listing what it offers.
#[must_use]
pub fn format_not_offered(route: &str, format: Format) -> Response {
    not_acceptable(
        "NOT_ACCEPTABLE",
        format!(
            "{route} has no {} representation; available: {}",
            format.media_type(),
            export::media_types(route).join(", ")
        ),
    )
}

/// The middleware.
pub async fn formats(req: Request, next: Next) -> Response {
    let Some(format) = wanted(&req) else {
        return next.run(req).await;
    };
    let Some(route) = req
        .extensions()
        .get::<MatchedPath>()
        .map(|m| m.as_str().to_owned())
    else {
        return next.run(req).await;
    };
    if !export::media_types(&route).contains(&format.media_type()) {
        return format_not_offered(&route, format);
    }
    let table = table_param(&req);
    if let Some(name) = &table
        && format == Format::Csv
        && !export::table::tables(&route).iter().any(|t| t.name == name)
    {
        let known: Vec<&str> = export::table::tables(&route)
            .iter()
            .map(|t| t.name)
            .collect();
        return not_acceptable(
            "UNKNOWN_TABLE",
            format!(
                "{route} has no table `{name}`; its tables: {}",
                known.join(", ")
            ),
        );
    }
    let request_id = req
        .headers()
        .get(super::layers::REQUEST_ID)
        .and_then(|v| v.to_str().ok())
        .map(str::to_owned);
    let (mut parts, body) = req.into_parts();
    parts
        .headers
        .insert(header::ACCEPT, HeaderValue::from_static("application/json"));
    // The body limit is enforced again by the handler; this bound only protects the rewrite.
    let Ok(bytes) = to_bytes(body, 64 * 1024 * 1024).await else {
        return ApiError::malformed_json("could not read the request body").into_response();
    };
    let Ok(mut request) = serde_json::from_slice::<Value>(&bytes) else {
        // Not JSON: let the handler give its usual 400.
        return next
            .run(Request::from_parts(parts, Body::from(bytes)))
            .await;
    };
    let run_body = if format == Format::Dxf {
        export::dxf::prepare(&route, &mut request);
        parts.headers.remove(header::CONTENT_LENGTH);
        serde_json::to_vec(&request).unwrap_or_else(|_| bytes.to_vec())
    } else {
        bytes.to_vec()
    };
    let resp = next
        .run(Request::from_parts(parts, Body::from(run_body)))
        .await;
    if resp.status() != StatusCode::OK {
        return resp;
    }
    let (rparts, rbody) = resp.into_parts();
    let Ok(answer_bytes) = to_bytes(rbody, usize::MAX).await else {
        return ApiError::internal().into_response();
    };
    let made = {
        let route = route.clone();
        tokio::task::spawn_blocking(move || {
            make(
                format,
                &route,
                &bytes,
                &request,
                &answer_bytes,
                table.as_deref(),
                request_id,
            )
        })
        .await
    };
    let made = match made {
        Ok(m) => m,
        Err(_) => return ApiError::internal().into_response(),
    };
    match made {
        Ok(out) => respond(format, &route, out, rparts.headers.get("server-timing")),
        Err(resp) => *resp,
    }
}

/// The response carrying `out`: its media type, a file name, the calculation's Server-Timing.
fn respond(format: Format, route: &str, out: Vec<u8>, timing: Option<&HeaderValue>) -> Response {
    let mut r = out.into_response();
    let h = r.headers_mut();
    h.insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static(format.content_type()),
    );
    let name = route.trim_start_matches("/v1/").replace('/', "-");
    let disposition = if format == Format::Html {
        "inline"
    } else {
        "attachment"
    };
    if let Ok(v) = HeaderValue::from_str(&format!(
        "{disposition}; filename=\"{name}.{}\"",
        format.extension()
    )) {
        h.insert(header::CONTENT_DISPOSITION, v);
    }
    if let Some(t) = timing {
        h.insert("server-timing", t.clone());
    }
    r
}

/// The bytes of `format` from the exact request, the request as run and the JSON answer.
fn make(
    format: Format,
    route: &str,
    request_bytes: &[u8],
    request: &Value,
    answer_bytes: &[u8],
    table: Option<&str>,
    request_id: Option<String>,
) -> Result<Vec<u8>, Box<Response>> {
    let Ok(answer) = serde_json::from_slice::<Value>(answer_bytes) else {
        return Err(Box::new(ApiError::internal().into_response()));
    };
    let doc = super::openapi::document();
    match format {
        Format::Html => {
            let time = chrono::Utc::now().to_rfc3339_opts(chrono::SecondsFormat::Millis, true);
            Ok(export::report::render(&export::report::ReportInput {
                route,
                request_bytes,
                request,
                answer_bytes,
                answer: &answer,
                doc,
                time_utc: &time,
                request_id: request_id.as_deref(),
            })
            .into_bytes())
        }
        Format::Csv => export::csv(route, request, &answer, doc, table).map_err(|e| {
            Box::new(match e {
                export::TableError::Unknown { .. } => {
                    not_acceptable("UNKNOWN_TABLE", e.to_string())
                }
                export::TableError::Absent(why) => not_acceptable(
                    "NOTHING_TO_TABULATE",
                    format!("{route}: no table of this answer ({why}); ask for application/json"),
                ),
                export::TableError::Write(_) => {
                    tracing::error!(error = %e, "table could not be written");
                    ApiError::internal().into_response()
                }
            })
        }),
        Format::Dxf => export::dxf::render(route, request, &answer).map_err(|e| {
            Box::new(match e {
                export::dxf::DxfError::Nothing(why) => {
                    ApiError::nothing_to_draw(route, &why).into_response()
                }
                export::dxf::DxfError::Write(_) => {
                    tracing::error!(error = %e, "drawing could not be written");
                    ApiError::internal().into_response()
                }
            })
        }),
    }
}
