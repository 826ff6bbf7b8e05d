//! API keys and per-key request rates.
//!
//! * **Keys file** (`--api-keys-file`): one key a line, `<key id> <sha256 hex of the token>
//!   [<requests per minute>]`; `#` starts a comment. The service keeps only the hashes: a token is
//!   hashed on arrival (SHA-256) and compared with every key's hash in constant time. Tokens are
//!   never logged and never reach a metric; the key id is in the request's log line, a label of
//!   the request metrics, and names the client for fair queueing ([`crate::http::pool`]).
//! * **Reload**: SIGHUP reads the file again, and so does a change of the file's modification
//!   time or size (looked at every 10 s: a Kubernetes Secret volume changes with no signal). A file that fails to parse is refused as a whole
//!   (logged with its line number) and the keys in force stay. A key whose id and rate are
//!   unchanged keeps its token bucket across a reload.
//! * **Public routes**: `/healthz`, the page at `/`, the API docs and `/openapi.json` answer
//!   without a token (a browser must load them before the user pastes one; they hold no data and
//!   start no work). Every other route needs `Authorization: Bearer <token>`: missing or unknown
//!   → 401 problem+json with `WWW-Authenticate: Bearer`.
//! * **Rates**: a key with a rate has a token bucket of that many requests per minute and a burst
//!   of one minute's worth (GCRA, `governor`): beyond it 429 with `Retry-After`. Buckets are per
//!   key, so one key's burst never refuses another key.
//!
//! Without a keys file every request passes and the client is its remote address.

use std::net::SocketAddr;
use std::num::NonZeroU32;
use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};

use axum::extract::{ConnectInfo, Request, State};
use axum::http::{HeaderValue, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use governor::clock::{Clock, DefaultClock};
use governor::{DefaultDirectRateLimiter, Quota};
use sha2::{Digest, Sha256};
use subtle::ConstantTimeEq;

use super::pool::{REQUEST_INFO, RequestInfo};
use super::problem::{ApiError, Problem};
use super::state::AppState;

/// Routes that answer without a token (static, no data, no work).
const PUBLIC: &[&str] = &[
    "/healthz",
    "/",
    "/openapi.json",
    "/docs",
    "/docs/",
    "/docs/swagger-ui-bundle.js",
    "/docs/swagger-ui.css",
];

/// Name of the bearer security scheme in the OpenAPI document.
pub const SCHEME: &str = "bearer";

/// The key id a request was authenticated with, put on the response for the request log and
/// metrics.
#[derive(Debug, Clone)]
pub struct KeyId(pub Arc<str>);

/// One line of the keys file.
struct Key {
    id: Arc<str>,
    hash: [u8; 32],
    per_minute: Option<NonZeroU32>,
    bucket: Option<Arc<DefaultDirectRateLimiter>>,
}

/// The keys in force, replaced as a whole on reload.
#[derive(Default)]
struct Keys {
    keys: Vec<Key>,
}

/// API keys read from a file, reloadable.
pub struct KeyRing {
    path: PathBuf,
    keys: RwLock<Arc<Keys>>,
}

/// A line of the keys file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum KeysFileError {
    /// The file cannot be read.
    #[error("cannot read the API keys file {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A line does not parse.
    #[error("API keys file {path}, line {line}: {reason}")]
    Line {
        /// The file.
        path: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong (never the line's text: it holds a hash).
        reason: String,
    },
    /// No key at all: the service would refuse every request.
    #[error("API keys file {path} holds no key")]
    Empty {
        /// The file.
        path: String,
    },
}

/// The parsed lines of a keys file: `(id, sha256, requests per minute)`.
type Parsed = Vec<(String, [u8; 32], Option<NonZeroU32>)>;

/// Parse the text of a keys file (`path` only names it in errors).
///
/// # Errors
/// The first line that is not `<id> <64 hex digits> [<positive integer>]`, a repeated id or
/// hash, or a file without any key.
pub fn parse_keys(text: &str, path: &str) -> Result<Parsed, KeysFileError> {
    let mut out: Parsed = Vec::new();
    let err = |line: usize, reason: &str| KeysFileError::Line {
        path: path.to_owned(),
        line,
        reason: reason.to_owned(),
    };
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split_once('#').map_or(raw, |(l, _)| l).trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        let (id, hex, rate) = match fields.as_slice() {
            [id, hex] => (*id, *hex, None),
            [id, hex, rate] => (*id, *hex, Some(*rate)),
            _ => {
                return Err(err(
                    i + 1,
                    "expected `<key id> <sha256 hex> [<requests per minute>]`",
                ));
            }
        };
        let mut hash = [0u8; 32];
        if hex.len() != 64 || !hex.is_ascii() {
            return Err(err(
                i + 1,
                "the hash must be 64 hexadecimal digits (SHA-256)",
            ));
        }
        for (k, b) in hash.iter_mut().enumerate() {
            *b = u8::from_str_radix(&hex[2 * k..2 * k + 2], 16)
                .map_err(|_| err(i + 1, "the hash must be 64 hexadecimal digits (SHA-256)"))?;
        }
        let per_minute = match rate {
            None => None,
            Some(r) => Some(
                r.parse::<NonZeroU32>()
                    .map_err(|_| err(i + 1, "requests per minute must be a positive integer"))?,
            ),
        };
        if out.iter().any(|(o, _, _)| o == id) {
            return Err(err(i + 1, &format!("key id {id} appears twice")));
        }
        if out.iter().any(|(_, h, _)| h == &hash) {
            return Err(err(i + 1, "the same token hash appears twice"));
        }
        out.push((id.to_owned(), hash, per_minute));
    }
    if out.is_empty() {
        return Err(KeysFileError::Empty {
            path: path.to_owned(),
        });
    }
    Ok(out)
}

/// SHA-256 of a token, as the keys file writes it (lowercase hex).
#[must_use]
pub fn token_hash_hex(token: &str) -> String {
    Sha256::digest(token.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Why a request is refused at the door.
enum Refusal {
    Missing,
    Unknown,
    Limited {
        id: Arc<str>,
        retry_after_s: u64,
        per_minute: u32,
    },
}

impl KeyRing {
    /// Read the keys file.
    ///
    /// # Errors
    /// See [`parse_keys`].
    pub fn load(path: &Path) -> Result<Self, KeysFileError> {
        let ring = Self {
            path: path.to_owned(),
            keys: RwLock::new(Arc::new(Keys::default())),
        };
        ring.reload()?;
        Ok(ring)
    }

    /// A key ring that refuses every request (the keys file could not be read when the state was
    /// built without a way to fail): closed, never open.
    #[must_use]
    pub fn refusing(path: &Path) -> Self {
        Self {
            path: path.to_owned(),
            keys: RwLock::new(Arc::new(Keys::default())),
        }
    }

    /// Read the file again and put its keys in force; on error the keys in force stay. Returns
    /// the number of keys.
    ///
    /// # Errors
    /// See [`parse_keys`].
    pub fn reload(&self) -> Result<usize, KeysFileError> {
        let name = self.path.display().to_string();
        let text = std::fs::read_to_string(&self.path).map_err(|source| KeysFileError::Read {
            path: name.clone(),
            source,
        })?;
        let parsed = parse_keys(&text, &name)?;
        let old = self.current();
        let keys = parsed
            .into_iter()
            .map(|(id, hash, per_minute)| {
                // Same id, same rate: keep the bucket, so a reload is no way around the limit.
                let bucket = old
                    .keys
                    .iter()
                    .find(|k| *k.id == *id && k.per_minute == per_minute)
                    .and_then(|k| k.bucket.clone())
                    .or_else(|| {
                        per_minute.map(|n| {
                            Arc::new(DefaultDirectRateLimiter::direct(Quota::per_minute(n)))
                        })
                    });
                Key {
                    id: id.into(),
                    hash,
                    per_minute,
                    bucket,
                }
            })
            .collect::<Vec<_>>();
        let n = keys.len();
        if let Ok(mut k) = self.keys.write() {
            *k = Arc::new(Keys { keys });
        }
        Ok(n)
    }

    fn current(&self) -> Arc<Keys> {
        self.keys.read().map(|k| Arc::clone(&k)).unwrap_or_default()
    }

    /// Key ids in force.
    #[must_use]
    pub fn ids(&self) -> Vec<String> {
        self.current()
            .keys
            .iter()
            .map(|k| k.id.to_string())
            .collect()
    }

    /// The key id of a bearer token, after its rate check.
    fn admit(&self, authorization: Option<&HeaderValue>) -> Result<Arc<str>, Refusal> {
        let token = authorization
            .and_then(|v| v.to_str().ok())
            .and_then(|v| {
                let (scheme, rest) = v.trim().split_once(' ')?;
                scheme.eq_ignore_ascii_case("bearer").then(|| rest.trim())
            })
            .filter(|t| !t.is_empty())
            .ok_or(Refusal::Missing)?;
        let hash: [u8; 32] = Sha256::digest(token.as_bytes()).into();
        let keys = self.current();
        // Compare with every key, each comparison in constant time, no early exit.
        let mut found = None;
        for (i, k) in keys.keys.iter().enumerate() {
            if bool::from(k.hash.ct_eq(&hash)) {
                found = Some(i);
            }
        }
        let key = found
            .and_then(|i| keys.keys.get(i))
            .ok_or(Refusal::Unknown)?;
        if let (Some(bucket), Some(n)) = (&key.bucket, key.per_minute)
            && let Err(not_until) = bucket.check()
        {
            let wait = not_until.wait_time_from(DefaultClock::default().now());
            return Err(Refusal::Limited {
                id: Arc::clone(&key.id),
                retry_after_s: wait.as_secs() + u64::from(wait.subsec_nanos() > 0),
                per_minute: n.get(),
            });
        }
        Ok(Arc::clone(&key.id))
    }
}

/// How often the keys file's modification time and size are looked at (a Kubernetes Secret
/// volume is updated in place and sends no signal).
const KEYS_POLL: std::time::Duration = std::time::Duration::from_secs(10);

/// Modification time and size of a file, to notice a change.
fn stamp(path: &Path) -> Option<(std::time::SystemTime, u64)> {
    let m = std::fs::metadata(path).ok()?;
    Some((m.modified().ok()?, m.len()))
}

/// Reread the keys file on every SIGHUP, and when its modification time or size changes, for
/// the life of the process (a no-op without keys).
pub fn reload_on_sighup(ring: Option<Arc<KeyRing>>) {
    let Some(ring) = ring else { return };
    tokio::spawn(async move {
        #[cfg(unix)]
        let mut hup = match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::hangup()) {
            Ok(s) => Some(s),
            Err(e) => {
                tracing::error!(error = %e, "cannot listen for SIGHUP; the keys file is polled only");
                None
            }
        };
        let mut last = stamp(&ring.path);
        let mut tick = tokio::time::interval(KEYS_POLL);
        loop {
            #[cfg(unix)]
            let hangup = async {
                match hup.as_mut() {
                    Some(h) => h.recv().await,
                    None => std::future::pending().await,
                }
            };
            #[cfg(not(unix))]
            let hangup = std::future::pending::<Option<()>>();
            let cause = tokio::select! {
                _ = hangup => "SIGHUP",
                _ = tick.tick() => {
                    if stamp(&ring.path) == last {
                        continue;
                    }
                    "the file changed"
                }
            };
            last = stamp(&ring.path);
            match ring.reload() {
                Ok(n) => {
                    metrics::counter!("mechcalc_api_key_reloads_total", "result" => "ok")
                        .increment(1);
                    tracing::info!(keys = n, cause, "API keys reloaded");
                }
                Err(e) => {
                    metrics::counter!("mechcalc_api_key_reloads_total", "result" => "error")
                        .increment(1);
                    tracing::error!(error = %e, cause, "API keys file refused; the keys in force stay");
                }
            }
        }
    });
}

/// The client a request belongs to for fair queueing: its key id, else its remote address (IP
/// only: one machine's connections are one client), else `local` (in-process requests).
fn peer_client(req: &Request) -> Arc<str> {
    req.extensions()
        .get::<ConnectInfo<SocketAddr>>()
        .map_or_else(|| Arc::from("local"), |c| Arc::from(c.0.ip().to_string()))
}

/// The middleware: authenticate, apply the key's rate, name the client for the compute pool.
pub async fn authenticate(State(state): State<AppState>, req: Request, next: Next) -> Response {
    let (client, key) = match &state.keys {
        None => (peer_client(&req), None),
        Some(_) if PUBLIC.contains(&req.uri().path()) => (peer_client(&req), None),
        Some(ring) => match ring.admit(req.headers().get(header::AUTHORIZATION)) {
            Ok(id) => (Arc::clone(&id), Some(id)),
            Err(refusal) => return refuse(refusal),
        },
    };
    let mut info: RequestInfo = REQUEST_INFO.try_with(Clone::clone).unwrap_or_default();
    info.client = client;
    let mut resp = REQUEST_INFO.scope(info, next.run(req)).await;
    if let Some(id) = key {
        resp.extensions_mut().insert(KeyId(id));
    }
    resp
}

fn refuse(refusal: Refusal) -> Response {
    match refusal {
        Refusal::Missing | Refusal::Unknown => {
            let (detail, challenge) = if matches!(refusal, Refusal::Missing) {
                (
                    "this service needs an API key: send `Authorization: Bearer <token>`",
                    r#"Bearer realm="mechcalc""#,
                )
            } else {
                (
                    "the bearer token matches no API key of this service",
                    r#"Bearer realm="mechcalc", error="invalid_token""#,
                )
            };
            metrics::counter!("mechcalc_unauthorized_total").increment(1);
            let mut r = ApiError::unauthorized(detail).into_response();
            r.headers_mut().insert(
                header::WWW_AUTHENTICATE,
                HeaderValue::from_static(challenge),
            );
            r
        }
        Refusal::Limited {
            id,
            retry_after_s,
            per_minute,
        } => {
            metrics::counter!("mechcalc_rate_limited_total", "key" => id.to_string()).increment(1);
            let mut r = ApiError::too_many_requests(
                "RATE_LIMITED",
                retry_after_s,
                format!(
                    "API key {id} allows {per_minute} requests per minute; retry in {retry_after_s} s"
                ),
            )
            .into_response();
            r.extensions_mut().insert(KeyId(id));
            r
        }
    }
}

/// Responses every operation behind API keys can give (all `application/problem+json`).
#[derive(utoipa::IntoResponses)]
pub enum AuthResponses {
    /// No bearer token, or one that matches no API key.
    #[response(status = 401, description = "Missing or unknown API key (`/problems/unauthorized`); send `Authorization: Bearer <token>`", content_type = "application/problem+json", headers(("WWW-Authenticate" = String, description = "`Bearer realm=\"mechcalc\"`")))]
    Unauthorized(Problem),
    /// The key's request rate is spent.
    #[response(status = 429, description = "The API key's requests per minute are spent (`RATE_LIMITED`) or the client has as many jobs waiting as one client may (`CLIENT_QUEUE_FULL`) (`/problems/too-many-requests`); retry after `Retry-After` seconds", content_type = "application/problem+json", headers(("Retry-After" = u64, description = "Seconds to wait before retrying")))]
    TooManyRequests(Problem),
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Parsed keys by id: `(sha256 hex, requests per minute)`.
    fn describe(parsed: &Parsed) -> HashMap<String, (String, Option<u32>)> {
        parsed
            .iter()
            .map(|(id, h, r)| {
                (
                    id.clone(),
                    (
                        h.iter().map(|b| format!("{b:02x}")).collect(),
                        r.map(NonZeroU32::get),
                    ),
                )
            })
            .collect()
    }

    const H1: &str = "9f86d081884c7d659a2feaa0c55ad015a3bf4f1b2b0b822cd15d6c15b0f00a08"; // "test"

    #[test]
    fn the_hash_is_sha256_hex() {
        assert_eq!(token_hash_hex("test"), H1);
    }

    #[test]
    fn keys_file_lines_and_comments() {
        let text = format!(
            "# mechcalc keys\n\nplm {H1} 120  # the PLM connector\nweb {} \n",
            token_hash_hex("other")
        );
        let p = parse_keys(&text, "k").expect("parses");
        let d = describe(&p);
        assert_eq!(d.len(), 2);
        assert_eq!(d["plm"], (H1.to_owned(), Some(120)));
        assert_eq!(d["web"].1, None);
    }

    #[test]
    fn bad_lines_name_their_line_and_never_their_text() {
        for (text, line, needle) in [
            (format!("a {H1}\nb nothex"), 2, "64 hexadecimal"),
            (format!("a {H1} 0"), 1, "positive integer"),
            (format!("a {H1} -5"), 1, "positive integer"),
            (format!("a {H1}\na {}", token_hash_hex("x")), 2, "twice"),
            (format!("a {H1}\nb {H1}"), 2, "twice"),
            (format!("a {H1} 5 extra"), 1, "expected"),
        ] {
            let e = parse_keys(&text, "k").expect_err("refused").to_string();
            assert!(e.contains(&format!("line {line}")), "{e}");
            assert!(e.contains(needle), "{e}");
            assert!(!e.contains(H1), "the error echoes a hash: {e}");
        }
        assert!(matches!(
            parse_keys("# only a comment\n", "k"),
            Err(KeysFileError::Empty { .. })
        ));
    }
}
