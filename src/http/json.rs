//! The JSON request extractor: content-type check (415), size limit (413), syntax (400) and
//! data errors (422) with a JSON pointer taken from serde's path.

use std::time::Duration;

use axum::body::Bytes;
use axum::extract::{FromRequest, Request};
use axum::http::{StatusCode, header};
use serde::de::DeserializeOwned;

use super::problem::ApiError;
use super::state::AppState;

/// A JSON request body decoded into `T`, with every failure mapped to problem+json.
#[derive(Debug)]
pub struct ApiJson<T>(pub T);

/// Whether a Content-Type header value names JSON (`application/json` or any `+json` type).
fn is_json(content_type: &str) -> bool {
    let essence = content_type
        .split(';')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_lowercase();
    essence == "application/json"
        || (essence.starts_with("application/") && essence.ends_with("+json"))
}

/// Escape one JSON-pointer reference token (RFC 6901 §3).
fn escape_token(token: &str) -> String {
    token.replace('~', "~0").replace('/', "~1")
}

/// Turn serde_path_to_error's path into a JSON pointer.
fn pointer_of(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for seg in path.iter() {
        match seg {
            Segment::Seq { index } => {
                out.push('/');
                out.push_str(&index.to_string());
            }
            Segment::Map { key } => {
                out.push('/');
                out.push_str(&escape_token(key));
            }
            Segment::Enum { variant } => {
                out.push('/');
                out.push_str(&escape_token(variant));
            }
            Segment::Unknown => {}
        }
    }
    out
}

/// serde reports a missing field at the parent object; point at the field itself. (An unknown
/// field's key is already the last path segment.)
fn missing_field_in(message: &str) -> Option<&str> {
    message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next())
}

/// Decode `bytes` as `T`, mapping failures: syntax/EOF → 400, data → 422 with a pointer.
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, ApiError> {
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let value = serde_path_to_error::deserialize(&mut de).map_err(|err| {
        let mut pointer = pointer_of(err.path());
        let inner = err.into_inner();
        let message = strip_position(&inner.to_string());
        match inner.classify() {
            serde_json::error::Category::Data => {
                if let Some(field) = missing_field_in(&message) {
                    pointer.push('/');
                    pointer.push_str(&escape_token(field));
                }
                ApiError::invalid_field(pointer, message)
            }
            _ => {
                let e = ApiError::malformed_json(format!(
                    "{message} at line {}, column {}",
                    inner.line(),
                    inner.column()
                ));
                if pointer.is_empty() {
                    e
                } else {
                    e.with_field(pointer, message)
                }
            }
        }
    })?;
    de.end().map_err(|e| {
        ApiError::malformed_json(format!("trailing characters after the JSON value: {e}"))
    })?;
    Ok(value)
}

/// serde_json appends " at line L column C" to messages; the pointer says where, so drop it.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}

/// Bodies up to this size are decoded inline (microseconds); larger ones on the blocking pool.
const INLINE_DECODE_BYTES: usize = 64 * 1024;

/// Large bodies decoded at once, at most.
fn decode_slots() -> &'static tokio::sync::Semaphore {
    static SLOTS: std::sync::OnceLock<tokio::sync::Semaphore> = std::sync::OnceLock::new();
    SLOTS.get_or_init(|| {
        tokio::sync::Semaphore::new(
            std::thread::available_parallelism().map_or(2, std::num::NonZeroUsize::get),
        )
    })
}

impl<T: DeserializeOwned + utoipa::ToSchema + Send + 'static> FromRequest<AppState> for ApiJson<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &AppState) -> Result<Self, Self::Rejection> {
        let ct = req
            .headers()
            .get(header::CONTENT_TYPE)
            .map(|v| v.to_str().unwrap_or("(non-ASCII)").to_owned());
        match ct.as_deref() {
            Some(c) if is_json(c) => {}
            other => return Err(ApiError::unsupported_media_type(other)),
        }
        let limit = state.config.max_body_bytes;
        let timeout_ms = state.config.body_timeout_ms;
        let read = Bytes::from_request(req, state);
        let bytes = tokio::time::timeout(Duration::from_millis(timeout_ms.max(1)), read)
            .await
            .map_err(|_| ApiError::request_timeout(timeout_ms))?
            .map_err(|rejection| {
                if rejection.status() == StatusCode::PAYLOAD_TOO_LARGE {
                    ApiError::body_too_large(limit)
                } else {
                    ApiError::malformed_json(format!(
                        "could not read the request body: {rejection}"
                    ))
                }
            })?;
        let schema = T::name();
        let inline = bytes.len() <= INLINE_DECODE_BYTES;
        let decode_and_check = move || {
            let v = decode(&bytes)?;
            super::shape::check(&schema, &bytes)?;
            Ok(ApiJson(v))
        };
        if inline {
            return decode_and_check();
        }
        // A large body takes milliseconds to decode: do it off the threads that serve
        // connections, at most `DECODE_SLOTS` at once.
        let _permit = decode_slots()
            .acquire()
            .await
            .map_err(|_| ApiError::internal())?;
        tokio::task::spawn_blocking(decode_and_check)
            .await
            .map_err(|_| ApiError::internal())?
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[expect(
        dead_code,
        reason = "the fields exist to be deserialized and rejected, never read"
    )]
    struct Inner {
        t_b: f64,
    }

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[expect(
        dead_code,
        reason = "the fields exist to be deserialized and rejected, never read"
    )]
    struct Outer {
        items: Vec<Inner>,
    }

    #[test]
    fn content_types() {
        assert!(is_json("application/json"));
        assert!(is_json("application/json; charset=utf-8"));
        assert!(is_json("application/problem+json"));
        assert!(!is_json("text/plain"));
        assert!(!is_json("application/x-www-form-urlencoded"));
    }

    #[test]
    fn type_error_points_at_field() {
        let e = decode::<Outer>(br#"{"items":[{"t_b":1},{"t_b":"x"}]}"#).unwrap_err();
        assert_eq!(e.status(), StatusCode::UNPROCESSABLE_ENTITY);
        assert_eq!(e.body().errors[0].pointer, "/items/1/t_b");
    }

    #[test]
    fn unknown_and_missing_fields_point_at_the_field() {
        let e = decode::<Outer>(br#"{"items":[{"t_b":1,"tb":2}]}"#).unwrap_err();
        assert_eq!(e.body().errors[0].pointer, "/items/0/tb");
        let e = decode::<Outer>(br#"{"items":[{}]}"#).unwrap_err();
        assert_eq!(e.body().errors[0].pointer, "/items/0/t_b");
    }

    #[test]
    fn syntax_error_is_400() {
        let e = decode::<Outer>(br#"{"items":[{"t_b":1},"#).unwrap_err();
        assert_eq!(e.status(), StatusCode::BAD_REQUEST);
        let e = decode::<Outer>(br#"{"items":[]} x"#).unwrap_err();
        assert_eq!(e.status(), StatusCode::BAD_REQUEST);
    }

    #[test]
    fn pointer_tokens_are_escaped() {
        assert_eq!(escape_token("a/b~c"), "a~1b~0c");
    }
}
