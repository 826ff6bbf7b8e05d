//! Where the time of an answer goes outside the calculation: for every `api/` example (the
//! largest answers of every endpoint), the in-process round trip through the whole router
//! (decode, shape check, admission, compute, finite check, encoding, middleware) against the
//! compute time the service itself reports in its `Server-Timing` header. Prints a table for
//! benches/RESULTS.md. Target (issue "cheap answers with big bodies"): overhead ≤ 0.15 ms for a
//! 70 KB answer.
//!
//! `cargo bench --bench service_overhead`

use std::time::Instant;

use axum::body::Body;
use axum::http::Request;
use http_body_util::BodyExt;
use mechcalc::config::ServiceConfig;
use mechcalc::{AppState, app};
use tower::ServiceExt;

#[path = "support/mod.rs"]
mod support;

/// One metric of the service's `Server-Timing` header [ms].
fn timing_ms(headers: &axum::http::HeaderMap, name: &str) -> f64 {
    let key = format!("{name};dur=");
    headers
        .get("server-timing")
        .and_then(|v| v.to_str().ok())
        .and_then(|s| {
            s.split(',')
                .find_map(|p| p.trim().strip_prefix(key.as_str()))
                .and_then(|d| d.parse().ok())
        })
        .unwrap_or(f64::NAN)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime");
    let router = app(AppState::new(ServiceConfig::default()));
    println!(
        "| example | answer KB | runs | total ms | compute ms | overhead ms | of which encode ms | of which queue ms | rest ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    rt.block_on(async {
        for (file, endpoint, body) in support::api_examples() {
            let send = || {
                let req = Request::builder()
                    .method("POST")
                    .uri(&endpoint)
                    .header("content-type", "application/json")
                    .body(Body::from(body.clone()))
                    .expect("request");
                router.clone().oneshot(req)
            };
            // Warm-up, and the cost of one run to size the repetitions.
            let t0 = Instant::now();
            let r = send().await.expect("infallible");
            let first = t0.elapsed().as_secs_f64();
            let status = r.status();
            let bytes = r.into_body().collect().await.expect("body").to_bytes();
            if !status.is_success() {
                println!("| {file} | — | — | status {status} | | | |");
                continue;
            }
            let runs = ((2.0 / first.max(1e-6)) as usize).clamp(5, 400);
            let mut cols: [Vec<f64>; 6] = Default::default();
            for _ in 0..runs {
                let t = Instant::now();
                let r = send().await.expect("infallible");
                let c = timing_ms(r.headers(), "compute");
                let e = timing_ms(r.headers(), "encode");
                let q = timing_ms(r.headers(), "queue");
                let _ = r.into_body().collect().await.expect("body").to_bytes();
                let ms = t.elapsed().as_secs_f64() * 1e3;
                for (col, v) in cols.iter_mut().zip([ms, c, ms - c, e, q, ms - c - e - q]) {
                    col.push(v);
                }
            }
            let kb = bytes.len() as f64 / 1024.0;
            let [t, c, o, e, q, rest] = cols.map(|mut v| median(&mut v));
            println!(
                "| {file} | {kb:.1} | {runs} | {t:.4} | {c:.4} | {o:.4} | {e:.4} | {q:.4} | {rest:.4} |"
            );
        }
    });
}
