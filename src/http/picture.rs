//! Pictures by content negotiation: a calculation requested with `Accept: image/svg+xml` answers
//! with the SVG picture of its answer ([`crate::plot`]). The request is first completed with the
//! outputs the picture needs (curves, a dense grid), then runs exactly as a JSON request would;
//! a refused request still answers with its problem details. Without that `Accept` header
//! nothing changes, so the JSON path pays nothing for pictures.

use axum::body::{Body, to_bytes};
use axum::extract::{MatchedPath, Request};
use axum::http::{HeaderValue, Method, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use serde_json::Value;

use super::problem::ApiError;
use crate::plot::{self, PlotError};

/// Whether the client prefers SVG (it names `image/svg+xml` and not JSON first).
fn wants_svg(req: &Request) -> bool {
    req.method() == Method::POST
        && req
            .headers()
            .get(header::ACCEPT)
            .and_then(|v| v.to_str().ok())
            .is_some_and(|a| {
                let svg = a.find("image/svg+xml");
                let json = a.find("application/json");
                svg.is_some_and(|s| json.is_none_or(|j| s < j))
            })
}

/// The middleware.
pub async fn picture(req: Request, next: Next) -> Response {
    if !wants_svg(&req) {
        return next.run(req).await;
    }
    let route = req
        .extensions()
        .get::<MatchedPath>()
        .map(|m| m.as_str().to_owned())
        .unwrap_or_default();
    if !plot::has_picture(&route) {
        return ApiError::not_acceptable(&route).into_response();
    }
    let (mut parts, body) = req.into_parts();
    // The body limit is enforced again by the handler; this bound only protects the rewrite.
    let Ok(bytes) = to_bytes(body, 64 * 1024 * 1024).await else {
        return ApiError::malformed_json("could not read the request body").into_response();
    };
    let mut request: Value = match serde_json::from_slice(&bytes) {
        Ok(v) => v,
        // Not JSON: let the handler give its usual 400.
        Err(_) => {
            parts
                .headers
                .insert(header::ACCEPT, HeaderValue::from_static("application/json"));
            return next
                .run(Request::from_parts(parts, Body::from(bytes)))
                .await;
        }
    };
    plot::prepare(&route, &mut request);
    let body = serde_json::to_vec(&request).unwrap_or_else(|_| bytes.to_vec());
    parts
        .headers
        .insert(header::ACCEPT, HeaderValue::from_static("application/json"));
    parts.headers.remove(header::CONTENT_LENGTH);
    let resp = next.run(Request::from_parts(parts, Body::from(body))).await;
    if resp.status() != StatusCode::OK {
        return resp;
    }
    let (rparts, rbody) = resp.into_parts();
    let Ok(answer_bytes) = to_bytes(rbody, usize::MAX).await else {
        return ApiError::internal().into_response();
    };
    let Ok(answer) = serde_json::from_slice::<Value>(&answer_bytes) else {
        return ApiError::internal().into_response();
    };
    let drawn = {
        let route = route.clone();
        tokio::task::spawn_blocking(move || plot::render(&route, &request, &answer)).await
    };
    match drawn {
        Ok(Some(Ok(svg))) => {
            let mut r = svg.into_response();
            r.headers_mut().insert(
                header::CONTENT_TYPE,
                HeaderValue::from_static("image/svg+xml"),
            );
            if let Some(t) = rparts.headers.get("server-timing") {
                r.headers_mut().insert("server-timing", t.clone());
            }
            r
        }
        Ok(Some(Err(PlotError::Missing(what)))) => {
            ApiError::nothing_to_draw(&route, &format!("the answer has no `{what}` to draw"))
                .into_response()
        }
        Ok(Some(Err(e))) => {
            tracing::error!(error = %e, "picture could not be drawn");
            ApiError::internal().into_response()
        }
        Ok(None) | Err(_) => ApiError::internal().into_response(),
    }
}
