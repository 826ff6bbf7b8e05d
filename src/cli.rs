//! `mechcalc run <endpoint> [FILE|-]`: one calculation from the command line, no server.
//!
//! The request goes through the same application the service runs (decoding, the shape check,
//! validation, the compute pool, the finite check, encoding), in process and without a socket,
//! so an answer here is byte-for-byte the answer the HTTP endpoint gives, and a bad request gets
//! the same problem details (on stderr, with a non-zero exit code).
//!
//! * `--batch`: the input is NDJSON (one request per line); the output is NDJSON in input order
//!   (an answer, or the problem details of that line). Lines run concurrently on the compute pool.
//! * `--svg`: the answer as an SVG picture instead of JSON (`Accept: image/svg+xml`).
//! * `--report OUT.html`: write the calculation report (`Accept: text/html`) to `OUT.html`.
//!
//! Exit codes: 0 every answer succeeded; 2 a request was refused (4xx: invalid, infeasible,
//! too large); 1 the service failed (5xx) or the input could not be read.

use std::io::{BufRead, Read, Write};
use std::process::ExitCode;

use axum::body::Body;
use axum::http::{Request, StatusCode, header};
use clap::Args;
use http_body_util::BodyExt;
use tower::ServiceExt;

use crate::config::ServiceConfig;
use crate::http::{AppState, app, meta};

/// Arguments of `mechcalc run`.
#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// The endpoint: its path (`/v1/cognates`) or the path without `/v1/` (`cognates`,
    /// `cam-law/evaluate`). `mechcalc run --list` lists them.
    #[arg(required_unless_present = "list")]
    pub endpoint: Option<String>,
    /// The request file (`-` or absent: standard input).
    pub file: Option<String>,
    /// Read NDJSON (one request per line) and write NDJSON (one answer per line, in order).
    #[arg(long)]
    pub batch: bool,
    /// Write the answer as an SVG picture instead of JSON.
    #[arg(long, conflicts_with = "batch")]
    pub svg: bool,
    /// Write the calculation report (self-contained HTML, `Accept: text/html`) to this file.
    #[arg(long, value_name = "OUT.html", conflicts_with_all = ["batch", "svg"])]
    pub report: Option<std::path::PathBuf>,
    /// Pretty-print JSON answers.
    #[arg(long)]
    pub pretty: bool,
    /// List the endpoints and exit.
    #[arg(long)]
    pub list: bool,
}

/// The POST endpoints of the service, from its OpenAPI document.
#[must_use]
pub fn endpoints() -> Vec<String> {
    meta::endpoint_index()
        .endpoints
        .into_iter()
        .filter(|e| e.method == "POST")
        .map(|e| e.path)
        .collect()
}

/// The path of `endpoint` given as a path or as a short name.
fn resolve(endpoint: &str) -> Option<String> {
    let want = endpoint.trim_start_matches('/').trim_start_matches("v1/");
    endpoints()
        .into_iter()
        .find(|p| p.trim_start_matches("/v1/") == want)
}

/// An answer: status, content type and body.
pub struct Answer {
    /// HTTP status the service would send.
    pub status: StatusCode,
    /// Content type.
    pub content_type: String,
    /// Body.
    pub body: Vec<u8>,
}

/// Run one request through the application in process.
pub async fn call(state: &AppState, path: &str, body: Vec<u8>, svg: bool) -> Answer {
    let accept = if svg {
        "image/svg+xml"
    } else {
        "application/json"
    };
    call_accept(state, path, body, accept).await
}

/// Run one request through the application in process, asking for the media type `accept`.
pub async fn call_accept(state: &AppState, path: &str, body: Vec<u8>, accept: &str) -> Answer {
    let req = Request::builder()
        .method("POST")
        .uri(path)
        .header(header::CONTENT_TYPE, "application/json")
        .header(header::ACCEPT, accept)
        .body(Body::from(body));
    let Ok(req) = req else {
        return internal("could not build the request");
    };
    let Ok(resp) = app(state.clone()).oneshot(req).await;
    let status = resp.status();
    let content_type = resp
        .headers()
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("")
        .to_owned();
    match resp.into_body().collect().await {
        Ok(b) => Answer {
            status,
            content_type,
            body: b.to_bytes().to_vec(),
        },
        Err(_) => internal("could not read the answer"),
    }
}

fn internal(msg: &str) -> Answer {
    Answer {
        status: StatusCode::INTERNAL_SERVER_ERROR,
        content_type: "application/problem+json".to_owned(),
        body: serde_json::json!({"type": "/problems/internal", "title": "Internal error",
            "status": 500, "code": "INTERNAL", "detail": msg, "errors": []})
        .to_string()
        .into_bytes(),
    }
}

fn read_input(file: Option<&str>) -> std::io::Result<Vec<u8>> {
    let mut buf = Vec::new();
    match file {
        None | Some("-") => {
            std::io::stdin().read_to_end(&mut buf)?;
        }
        Some(f) => buf = std::fs::read(f)?,
    }
    Ok(buf)
}

fn exit_for(status: StatusCode) -> u8 {
    if status.is_success() {
        0
    } else if status.is_client_error() {
        2
    } else {
        1
    }
}

fn pretty(body: &[u8]) -> Vec<u8> {
    serde_json::from_slice::<serde_json::Value>(body)
        .ok()
        .and_then(|v| serde_json::to_vec_pretty(&v).ok())
        .unwrap_or_else(|| body.to_vec())
}

/// `mechcalc run ...`.
pub fn run(args: &RunArgs, config: ServiceConfig) -> ExitCode {
    if args.list {
        for e in endpoints() {
            println!("{e}");
        }
        return ExitCode::SUCCESS;
    }
    let Some(path) = args.endpoint.as_deref().and_then(resolve) else {
        eprintln!(
            "unknown endpoint {:?}; one of: {}",
            args.endpoint.as_deref().unwrap_or(""),
            endpoints().join(", ")
        );
        return ExitCode::from(2);
    };
    let input = match read_input(args.file.as_deref()) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("cannot read the request: {e}");
            return ExitCode::from(1);
        }
    };
    let Ok(rt) = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
    else {
        eprintln!("cannot start the runtime");
        return ExitCode::from(1);
    };
    let state = AppState::new(config);
    let code = rt.block_on(async {
        if args.batch {
            batch(&state, &path, &input, args.pretty).await
        } else if let Some(out) = &args.report {
            report(&state, &path, input, out).await
        } else {
            single(&state, &path, input, args.svg, args.pretty).await
        }
    });
    ExitCode::from(code)
}

async fn single(state: &AppState, path: &str, input: Vec<u8>, svg: bool, pp: bool) -> u8 {
    let a = call(state, path, input, svg).await;
    let code = exit_for(a.status);
    let body = if pp && a.content_type.contains("json") {
        pretty(&a.body)
    } else {
        a.body
    };
    let mut out: Box<dyn Write> = if code == 0 {
        Box::new(std::io::stdout().lock())
    } else {
        Box::new(std::io::stderr().lock())
    };
    let _ = out.write_all(&body);
    let _ = out.write_all(b"\n");
    code
}

/// `--report OUT.html`: the report to the file; a refused request's problem details to stderr.
async fn report(state: &AppState, path: &str, input: Vec<u8>, out: &std::path::Path) -> u8 {
    let a = call_accept(state, path, input, crate::export::HTML).await;
    let code = exit_for(a.status);
    if code != 0 {
        let mut err = std::io::stderr().lock();
        let _ = err.write_all(&a.body);
        let _ = err.write_all(b"\n");
        return code;
    }
    if let Err(e) = std::fs::write(out, &a.body) {
        eprintln!("cannot write {}: {e}", out.display());
        return 1;
    }
    0
}

async fn batch(state: &AppState, path: &str, input: &[u8], pp: bool) -> u8 {
    let lines: Vec<Vec<u8>> = input
        .lines()
        .map_while(Result::ok)
        .filter(|l| !l.trim().is_empty())
        .map(String::into_bytes)
        .collect();
    // As many lines in flight as the compute pool runs at once: every core busy, nothing refused
    // for a full queue; answers are written in input order.
    let in_flight = std::sync::Arc::new(tokio::sync::Semaphore::new(state.pool.slots()));
    let mut tasks = Vec::with_capacity(lines.len());
    for l in lines {
        let Ok(permit) = std::sync::Arc::clone(&in_flight).acquire_owned().await else {
            break;
        };
        let state = state.clone();
        let path = path.to_owned();
        tasks.push(tokio::spawn(async move {
            let a = call(&state, &path, l, false).await;
            drop(permit);
            a
        }));
    }
    let mut worst = 0u8;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for t in tasks {
        let a = match t.await {
            Ok(a) => a,
            Err(_) => internal("a batch line failed"),
        };
        worst = worst.max(exit_for(a.status));
        let body = if pp { pretty(&a.body) } else { a.body };
        // NDJSON: one line per answer (compact JSON has no raw newlines).
        let line = if pp {
            serde_json::from_slice::<serde_json::Value>(&body)
                .map(|v| v.to_string().into_bytes())
                .unwrap_or(body)
        } else {
            body
        };
        let _ = out.write_all(&line);
        let _ = out.write_all(b"\n");
    }
    worst
}
