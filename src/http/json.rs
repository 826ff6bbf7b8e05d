//! The door: content-type check (415), size limit (413), one typed parse of the body (400 when it
//! is not JSON; 422 with serde's JSON pointer for a wrong type, an unknown or missing member),
//! then every per-field rule the wire types declare ([`crate::calc::rules`]), all before the
//! request reaches the compute pool.

use std::time::Duration;

use axum::body::Bytes;
use axum::extract::{FromRequest, Request};
use axum::http::{StatusCode, header};
use serde::de::DeserializeOwned;

use super::problem::ApiError;
use super::state::AppState;
use crate::calc::common::TimeLimited;
use crate::calc::{CalcFailure, Rules};

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
    let value =
        serde_path_to_error::deserialize(super::strict::Strict(&mut de)).map_err(|err| {
            let mut pointer = pointer_of(err.path());
            let inner = err.into_inner();
            let message = strip_position(&inner.to_string());
            // A number beyond f64 is well-formed JSON: a value problem at its pointer, not a 400.
            let out_of_range = message == "number out of range";
            match inner.classify() {
                _ if out_of_range => ApiError::invalid_field(
                    pointer,
                    "number out of range: not representable as a finite double",
                ),
                serde_json::error::Category::Data => {
                    if let Some(field) = missing_field_in(&message) {
                        pointer.push('/');
                        pointer.push_str(&escape_token(field));
                    }
                    ApiError::invalid_field(pointer, message)
                }
                // serde_json reports some wrong types (`null` for a required enum) as syntax
                // errors; a body that is JSON is never a 400 (checked on this error path only).
                _ if !pointer.is_empty()
                    && serde_json::from_slice::<serde::de::IgnoredAny>(bytes).is_ok() =>
                {
                    ApiError::invalid_field(pointer, format!("invalid value: {message}"))
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

/// Read the body: content type, size, time; every failure as problem+json.
async fn body_bytes(req: Request, state: &AppState) -> Result<Bytes, ApiError> {
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
    tokio::time::timeout(Duration::from_millis(timeout_ms.max(1)), read)
        .await
        .map_err(|_| ApiError::request_timeout(timeout_ms))?
        .map_err(|rejection| {
            if rejection.status() == StatusCode::PAYLOAD_TOO_LARGE {
                ApiError::body_too_large(limit)
            } else {
                ApiError::malformed_json(format!("could not read the request body: {rejection}"))
            }
        })
}

/// Run `work` on the bytes: inline for a small body (microseconds), else off the threads that
/// serve connections, at most `DECODE_SLOTS` large bodies at once.
async fn off_the_connection<R: Send + 'static>(
    bytes: Bytes,
    work: impl FnOnce(Bytes) -> Result<R, ApiError> + Send + 'static,
) -> Result<R, ApiError> {
    if bytes.len() <= INLINE_DECODE_BYTES {
        return work(bytes);
    }
    let _permit = decode_slots()
        .acquire()
        .await
        .map_err(|_| ApiError::internal())?;
    tokio::task::spawn_blocking(move || work(bytes))
        .await
        .map_err(|_| ApiError::internal())?
}

/// Note the door's time on the request in flight (reported as `door` in `Server-Timing`).
fn record_door(took: Duration) {
    let ns = u64::try_from(took.as_nanos()).unwrap_or(u64::MAX).max(1);
    let _ = super::pool::REQUEST_INFO.try_with(|i| {
        i.door_ns.store(ns, std::sync::atomic::Ordering::Relaxed);
    });
}

/// Decode a body as `T` (one typed parse) and check every per-field rule `T` declares.
///
/// # Errors
/// 400 when the body is not JSON; 422 listing the offending fields.
pub fn decode_checked<T: DeserializeOwned + Rules>(bytes: &[u8]) -> Result<T, ApiError> {
    let v: T = decode(bytes)?;
    crate::calc::rules::check(&v)?;
    Ok(v)
}

impl<T: DeserializeOwned + Rules + Send + 'static> FromRequest<AppState> for ApiJson<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &AppState) -> Result<Self, Self::Rejection> {
        let bytes = body_bytes(req, state).await?;
        let door = std::time::Instant::now();
        let decoded = off_the_connection(bytes, |b| decode_checked(&b).map(ApiJson)).await;
        record_door(door.elapsed());
        decoded
    }
}

/// The request of an endpoint through the whole door: decoded (one typed parse), every per-field
/// rule checked, then converted into the module's validated input `I` (the rules between
/// fields), all before anything is queued. `limit` is the request's `time_limit_ms`.
#[derive(Debug)]
pub struct Valid<R, I> {
    /// The validated input.
    pub input: I,
    /// The request's own time limit.
    pub limit: Option<Duration>,
    _wire: std::marker::PhantomData<fn() -> R>,
}

impl<R, I> FromRequest<AppState> for Valid<R, I>
where
    R: DeserializeOwned + Rules + TimeLimited + Send + 'static,
    I: TryFrom<R, Error = CalcFailure> + Send + 'static,
{
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &AppState) -> Result<Self, Self::Rejection> {
        let bytes = body_bytes(req, state).await?;
        let door = std::time::Instant::now();
        let valid = off_the_connection(bytes, |b| {
            let wire: R = decode_checked(&b)?;
            drop(b);
            let limit = wire.time_limit();
            let input = I::try_from(wire)?;
            Ok(Self {
                input,
                limit,
                _wire: std::marker::PhantomData,
            })
        })
        .await;
        record_door(door.elapsed());
        valid
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
    fn a_number_beyond_f64_is_a_value_problem_at_its_pointer() {
        let e = decode::<Outer>(br#"{"items":[{"t_b":1e400}]}"#).unwrap_err();
        assert_eq!(e.status(), StatusCode::UNPROCESSABLE_ENTITY);
        assert_eq!(e.body().errors[0].pointer, "/items/0/t_b");
    }

    #[derive(Debug, serde::Deserialize)]
    #[serde(rename_all = "snake_case")]
    enum Mode {
        Single,
    }

    #[derive(Debug, serde::Deserialize)]
    #[expect(dead_code, reason = "decoded to be refused, never read")]
    struct WithMode {
        mode: Mode,
    }

    #[test]
    fn null_for_a_required_enum_is_a_value_problem_not_a_400() {
        let e = decode::<WithMode>(br#"{"mode": null}"#).unwrap_err();
        assert_eq!(e.status(), StatusCode::UNPROCESSABLE_ENTITY);
        assert_eq!(e.body().errors[0].pointer, "/mode");
        let e = decode::<WithMode>(br#"{"mode": nul"#).unwrap_err();
        assert_eq!(e.status(), StatusCode::BAD_REQUEST);
    }

    #[test]
    fn pointer_tokens_are_escaped() {
        assert_eq!(escape_token("a/b~c"), "a~1b~0c");
    }
}
