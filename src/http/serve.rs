//! The connection layer: accept loop, per-connection limits and graceful shutdown with a deadline.
//!
//! * **Request head / idle keep-alive**: a connection must deliver a complete request head within
//!   `--header-timeout-ms`, counted from when the server starts waiting for it (so a connection
//!   that sends nothing, half a head, or one byte every few seconds, and an idle keep-alive
//!   connection, are closed after it).
//! * **Body**: `--body-timeout-ms` bounds the time to receive a body (408; in the JSON extractor).
//! * **Response write**: a single write that stalls longer than `--write-timeout-ms` (a client
//!   that does not read) closes the connection and frees what it held.
//! * **Connection limit**: beyond `--max-connections` open connections, a new one gets an
//!   immediate `503` and is closed, so descriptors never run out and `/healthz` keeps answering on
//!   the connections that are served.
//! * **Remote address**: every request carries the connection's peer address
//!   (`ConnectInfo<SocketAddr>`); without API keys it names the client for fair queueing.
//! * **Metrics port** (`--metrics-bind`): [`serve_metrics`] answers `/metrics` and `/healthz`
//!   only, never behind API keys, so a network policy can admit the scraper to that port alone.
//! * **Shutdown**: on the signal the listener closes, in-flight requests get
//!   `--shutdown-grace-ms` to finish, then every running job is cancelled and `serve` returns.

use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use axum::Router;
use axum::extract::ConnectInfo;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::server::graceful::GracefulShutdown;
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;
use tokio::sync::Semaphore;
use tokio_io_timeout::TimeoutStream;
use tower::ServiceExt;

use super::pool::ComputePool;

/// Limits of the connection layer.
#[derive(Debug, Clone, Copy)]
pub struct ConnLimits {
    /// Time to deliver a request head; also the idle keep-alive limit.
    pub header_timeout: Duration,
    /// Longest one response write may stall.
    pub write_timeout: Duration,
    /// Open connections at most.
    pub max_connections: usize,
    /// Time in-flight requests get after the shutdown signal.
    pub shutdown_grace: Duration,
}

/// The answer to a connection over the limit, written without waiting and followed by close.
const OVER_LIMIT: &[u8] = b"HTTP/1.1 503 Service Unavailable\r\ncontent-type: application/problem+json\r\n\
retry-after: 1\r\nconnection: close\r\ncontent-length: 134\r\n\r\n\
{\"type\":\"/problems/overloaded\",\"title\":\"Too many connections\",\"status\":503,\"code\":\"TOO_MANY_CONNECTIONS\",\"detail\":\"retry\",\"errors\":[]}";

/// Serve `app` on `listener` until `shutdown` resolves, then drain within the grace period and
/// cancel what is still running in `pool`.
pub async fn serve(
    listener: TcpListener,
    app: Router,
    limits: ConnLimits,
    pool: ComputePool,
    shutdown: impl Future<Output = ()>,
) {
    let graceful = GracefulShutdown::new();
    let connections = Arc::new(Semaphore::new(limits.max_connections.max(1)));
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new())
        .header_read_timeout(limits.header_timeout)
        .keep_alive(true);
    tokio::pin!(shutdown);
    loop {
        let accepted = tokio::select! {
            a = listener.accept() => a,
            () = &mut shutdown => break,
        };
        let (tcp, peer) = match accepted {
            Ok(c) => c,
            Err(e) => {
                // Out of descriptors or a transient network error: back off briefly, keep serving.
                tracing::warn!(error = %e, "accept failed");
                metrics::counter!("mechcalc_accept_errors_total").increment(1);
                tokio::time::sleep(Duration::from_millis(20)).await;
                continue;
            }
        };
        let Ok(permit) = Arc::clone(&connections).try_acquire_owned() else {
            metrics::counter!("mechcalc_rejected_total", "cause" => "too_many_connections")
                .increment(1);
            // Best effort: the socket buffer takes these few bytes at once, or the client gets a
            // reset; either way the descriptor is released now.
            let _ = tcp.try_write(OVER_LIMIT);
            drop(tcp);
            continue;
        };
        let _ = tcp.set_nodelay(true);
        let mut stream = TimeoutStream::new(tcp);
        stream.set_write_timeout(Some(limits.write_timeout));
        let io = TokioIo::new(Box::pin(stream));
        // The remote address reaches the app (fair queueing names a client without a key by it).
        let svc =
            app.clone()
                .map_request(move |mut r: axum::http::Request<hyper::body::Incoming>| {
                    r.extensions_mut().insert(ConnectInfo(peer));
                    r
                });
        let conn = http.serve_connection(io, TowerToHyperService::new(svc));
        let conn = graceful.watch(conn);
        metrics::gauge!("mechcalc_connections_open").increment(1.0);
        tokio::spawn(async move {
            if let Err(e) = conn.await {
                tracing::debug!(error = %e, "connection ended with an error");
            }
            metrics::gauge!("mechcalc_connections_open").decrement(1.0);
            drop(permit);
        });
    }
    drop(listener);
    tracing::info!(
        grace_ms = limits.shutdown_grace.as_millis(),
        "shutdown: listener closed, finishing in-flight requests"
    );
    tokio::select! {
        () = graceful.shutdown() => tracing::info!("all connections finished"),
        () = tokio::time::sleep(limits.shutdown_grace) => {
            tracing::warn!("shutdown deadline reached; cancelling running jobs and closing connections");
            pool.cancel_all();
        }
    }
}

/// Serve `/metrics` and `/healthz` of `state` on `listener` (the `--metrics-bind` port) until
/// the process ends.
pub async fn serve_metrics(listener: TcpListener, state: super::AppState) {
    let app = Router::new()
        .route("/metrics", axum::routing::get(super::meta::metrics))
        .route("/healthz", axum::routing::get(super::meta::healthz))
        .with_state(state);
    if let Err(e) = axum::serve(listener, app).await {
        tracing::error!(error = %e, "the metrics listener stopped");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn over_limit_answer_is_well_formed() {
        let text = std::str::from_utf8(OVER_LIMIT).expect("ASCII");
        let (head, body) = text.split_once("\r\n\r\n").expect("head and body");
        let len: usize = head
            .lines()
            .find_map(|l| l.strip_prefix("content-length: "))
            .and_then(|v| v.parse().ok())
            .expect("content-length");
        assert_eq!(len, body.len());
        let v: serde_json::Value = serde_json::from_str(body).expect("JSON body");
        assert_eq!(v["status"], 503);
    }
}
