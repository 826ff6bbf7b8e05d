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
//! * `--shard I/N`: block `I` of `N` of a sweep (the request's `shard` is set to `{index: I,
//!   count: N}`); `--out PATH` writes the answer to `PATH` (only when it succeeded, and whole:
//!   a Kubernetes Indexed Job's pod runs `mechcalc run <endpoint> request.json --shard
//!   $(JOB_COMPLETION_INDEX)/N --out /results/shard-$(JOB_COMPLETION_INDEX).json`). The
//!   answer is the service's with one member added, the request's digest
//!   ([`crate::merge::DIGEST_MEMBER`]), by which the merge tells shards of different requests
//!   apart.
//!
//! `mechcalc merge <endpoint> SHARD_FILE...`: the shards' answers merged into the unsharded
//! answer ([`crate::merge`]).
//! * `--report OUT.html`: write the calculation report (`Accept: text/html`) to `OUT.html`.
//!
//! Exit codes: 0 every answer succeeded; 2 a request was refused (4xx: invalid, infeasible,
//! too large; a request or endpoint that cannot be sharded; shards that do not merge); 1 the
//! service failed (5xx) or the input could not be read or the output written.

use std::io::{BufRead, Read, Write};
use std::process::ExitCode;

use axum::body::Body;
use axum::http::{Request, StatusCode, header};
use clap::Args;
use http_body_util::BodyExt;
use tower::ServiceExt;

use crate::calc::common::Shard;
use crate::config::ServiceConfig;
use crate::http::{AppState, app, meta};
use crate::merge::{ShardFile, Sweep};

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
    /// Compute block I of N of the request's sweep (`--shard 3/8`; sets the request's `shard`
    /// to `{"index": I, "count": N}`). Merge the N answers with `mechcalc merge`.
    #[arg(long, value_name = "I/N", value_parser = parse_shard, conflicts_with = "batch")]
    pub shard: Option<Shard>,
    /// Write the answer to this file instead of standard output (only when the request
    /// succeeded; the file appears whole or not at all).
    #[arg(long, value_name = "PATH", conflicts_with = "batch")]
    pub out: Option<std::path::PathBuf>,
}

/// Arguments of `mechcalc merge`.
#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// The sweep endpoint the shards answered: its path (`/v1/irefc-stress`) or the path
    /// without `/v1/` (`irefc-stress`, `bus-fuel-economy`, `machining-size/train`,
    /// `continuum-workspace`).
    pub endpoint: String,
    /// The shards' answers (files written by `mechcalc run --shard I/N`, or the service's
    /// answers to requests with `shard`), one per index 0..N, in any order.
    #[arg(required = true, value_name = "SHARD_FILE")]
    pub shards: Vec<std::path::PathBuf>,
    /// The request the shards were computed from (with or without `shard`). Needed for the
    /// bus comparison (its desirability weights), and checked against the shards.
    #[arg(long, value_name = "FILE")]
    pub request: Option<std::path::PathBuf>,
    /// Write the merged answer to this file instead of standard output.
    #[arg(long, value_name = "PATH")]
    pub out: Option<std::path::PathBuf>,
    /// Pretty-print the merged answer.
    #[arg(long)]
    pub pretty: bool,
}

/// `I/N` with `I < N`, both integers (`3/8`).
///
/// # Errors
/// A message saying what is wrong with the text.
pub fn parse_shard(text: &str) -> Result<Shard, String> {
    let bad = || {
        format!(
            "expected I/N (block I of N, 0 <= I < N, e.g. 3/8), got {text:?}; in a Kubernetes \
             Indexed Job I is $(JOB_COMPLETION_INDEX), in a Slurm array $SLURM_ARRAY_TASK_ID"
        )
    };
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let index: u32 = i.trim().parse().map_err(|_| bad())?;
    let count: u32 = n.trim().parse().map_err(|_| bad())?;
    if count == 0 || index >= count {
        return Err(format!(
            "shard {index}/{count}: the index must be below the count (0 <= I < N)"
        ));
    }
    Ok(Shard { index, count })
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
        let mut text = endpoints().join("\n");
        text.push('\n');
        return write_stdout(text.as_bytes());
    }
    let Some(path) = args.endpoint.as_deref().and_then(resolve) else {
        eprintln!(
            "unknown endpoint {:?}; one of: {}",
            args.endpoint.as_deref().unwrap_or(""),
            endpoints().join(", ")
        );
        return ExitCode::from(2);
    };
    let mut input = match read_input(args.file.as_deref()) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("cannot read the request: {e}");
            return ExitCode::from(1);
        }
    };
    let mut digest = None;
    if let Some(shard) = args.shard {
        match sharded(&path, &input, shard) {
            Ok((b, d)) => (input, digest) = (b, Some(d)),
            Err(msg) => {
                eprintln!(
                    "mechcalc run --shard {}/{}: {msg}",
                    shard.index, shard.count
                );
                return ExitCode::from(2);
            }
        }
    }
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
            let out = args.out.as_deref();
            single(
                &state,
                &path,
                input,
                args.svg,
                args.pretty,
                out,
                digest.as_deref(),
            )
            .await
        }
    });
    ExitCode::from(code)
}

async fn single(
    state: &AppState,
    path: &str,
    input: Vec<u8>,
    svg: bool,
    pp: bool,
    out_file: Option<&std::path::Path>,
    digest: Option<&str>,
) -> u8 {
    let mut a = call(state, path, input, svg).await;
    let code = exit_for(a.status);
    if code == 0
        && let Some(d) = digest
    {
        a.body = with_digest(&a.body, d);
    }
    let mut body = if pp && a.content_type.contains("json") {
        pretty(&a.body)
    } else {
        a.body
    };
    body.push(b'\n');
    if code != 0 {
        let _ = std::io::stderr().lock().write_all(&body);
        return code;
    }
    match out_file {
        Some(f) => match write_file(f, &body) {
            Ok(()) => 0,
            Err(e) => {
                eprintln!("cannot write {}: {e}", f.display());
                1
            }
        },
        None => stdout_code(&body),
    }
}

/// The request `input` (JSON) with its `shard` set to `shard` and the request's digest, or
/// why it cannot be sharded.
fn sharded(path: &str, input: &[u8], shard: Shard) -> Result<(Vec<u8>, String), String> {
    let req: serde_json::Value =
        serde_json::from_slice(input).map_err(|e| format!("the request is not valid JSON: {e}"))?;
    let digest = crate::merge::request_digest(&req);
    let req = crate::merge::with_shard(path, &req, shard)?;
    let body = serde_json::to_vec(&req).map_err(|e| format!("cannot encode the request: {e}"))?;
    Ok((body, digest))
}

/// A shard's answer with the digest of its request added last
/// ([`crate::merge::DIGEST_MEMBER`]), so that `mechcalc merge` can tell shards of different
/// requests apart.
fn with_digest(body: &[u8], digest: &str) -> Vec<u8> {
    let Ok(serde_json::Value::Object(mut answer)) = serde_json::from_slice(body) else {
        return body.to_vec();
    };
    answer.insert(
        crate::merge::DIGEST_MEMBER.to_owned(),
        serde_json::Value::from(digest),
    );
    serde_json::to_vec(&answer).unwrap_or_else(|_| body.to_vec())
}

/// Writes `bytes` to `path` whole or not at all: into a temporary file beside it, then renamed
/// (a reader, e.g. the merge step of a Job, never sees half an answer).
fn write_file(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp-{}", std::process::id()));
    let tmp = std::path::PathBuf::from(tmp);
    let written = std::fs::File::create(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()
    });
    match written.and_then(|()| std::fs::rename(&tmp, path)) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Writes `bytes` to standard output; a closed pipe (`| head`) ends the output quietly.
///
/// Exit code 0 when written or when the reader has gone, 1 on another error.
#[must_use]
pub fn write_stdout(bytes: &[u8]) -> ExitCode {
    ExitCode::from(stdout_code(bytes))
}

/// [`write_stdout`] as a number.
fn stdout_code(bytes: &[u8]) -> u8 {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        // A reader that stops early (`| head`) is not a failure of the command.
        Ok(()) => 0,
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => 0,
        Err(e) => {
            eprintln!("cannot write to standard output: {e}");
            1
        }
    }
}

/// `mechcalc merge ...`.
#[must_use]
pub fn merge(args: &MergeArgs) -> ExitCode {
    let sweep = resolve(&args.endpoint).and_then(|p| Sweep::from_path(&p));
    let Some(sweep) = sweep else {
        eprintln!(
            "mechcalc merge: {:?} is not a shardable endpoint; one of: {}",
            args.endpoint,
            Sweep::ALL
                .iter()
                .map(|s| format!("{} ({})", s.path(), s.items()))
                .collect::<Vec<_>>()
                .join(", ")
        );
        return ExitCode::from(2);
    };
    let read = |f: &std::path::Path| -> Result<serde_json::Value, (u8, String)> {
        let bytes =
            std::fs::read(f).map_err(|e| (1, format!("cannot read {}: {e}", f.display())))?;
        serde_json::from_slice(&bytes).map_err(|e| (2, format!("{} is not JSON: {e}", f.display())))
    };
    let mut shards = Vec::with_capacity(args.shards.len());
    for f in &args.shards {
        match read(f) {
            Ok(answer) => shards.push(ShardFile {
                name: f.display().to_string(),
                answer,
            }),
            Err((code, msg)) => {
                eprintln!("mechcalc merge: {msg}");
                return ExitCode::from(code);
            }
        }
    }
    let request = match args.request.as_deref().map(read).transpose() {
        Ok(r) => r,
        Err((code, msg)) => {
            eprintln!("mechcalc merge: the request: {msg}");
            return ExitCode::from(code);
        }
    };
    let merged = match crate::merge::merge(sweep, shards, request.as_ref()) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("mechcalc merge: {e}");
            return ExitCode::from(2);
        }
    };
    let encoded = if args.pretty {
        serde_json::to_vec_pretty(&merged)
    } else {
        serde_json::to_vec(&merged)
    };
    let mut body = match encoded {
        Ok(b) => b,
        Err(e) => {
            eprintln!("mechcalc merge: cannot encode the merged answer: {e}");
            return ExitCode::from(1);
        }
    };
    body.push(b'\n');
    match &args.out {
        Some(f) => match write_file(f, &body) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("mechcalc merge: cannot write {}: {e}", f.display());
                ExitCode::from(1)
            }
        },
        None => write_stdout(&body),
    }
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
