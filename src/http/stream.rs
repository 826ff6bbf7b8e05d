//! Progress for long work: any calculation requested with `Accept: text/event-stream` answers as
//! a Server-Sent Events stream of `progress` events (fraction done, best objective so far,
//! elapsed) while it runs, then one final event: `result` with exactly the JSON answer the
//! non-streaming request gets, or `problem` with the problem details. Without that `Accept`
//! header nothing changes. Closing the stream cancels the job, like any client that goes away.

use std::sync::Arc;

use axum::extract::Request;
use axum::http::{HeaderValue, Method, header};
use axum::middleware::Next;
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use futures_util::stream;
use http_body_util::BodyExt;
use tokio::sync::mpsc;

use super::pool::REQUEST_INFO;
use crate::numerics::budget::{Progress, ProgressSink};

/// Whether the client asked for an event stream.
fn wants_events(req: &Request) -> bool {
    req.method() == Method::POST
        && req
            .headers()
            .get(header::ACCEPT)
            .and_then(|v| v.to_str().ok())
            .is_some_and(|a| a.contains("text/event-stream"))
}

/// Aborts the running request when the event stream is dropped (the client went away).
struct AbortOnDrop(tokio::task::AbortHandle);

impl Drop for AbortOnDrop {
    fn drop(&mut self) {
        self.0.abort();
    }
}

enum State {
    Running {
        rx: mpsc::UnboundedReceiver<Progress>,
        task: tokio::task::JoinHandle<Response>,
        _guard: AbortOnDrop,
    },
    Done,
}

/// The middleware: passes every other request through unchanged.
pub async fn event_stream(mut req: Request, next: Next) -> Response {
    if !wants_events(&req) {
        return next.run(req).await;
    }
    let (tx, rx) = mpsc::unbounded_channel();
    let sink = Arc::new(ProgressSink::new(move |p| {
        let _ = tx.send(p);
    }));
    let mut info = REQUEST_INFO.try_with(Clone::clone).unwrap_or_default();
    info.progress = Some(sink);
    // The handler answers JSON; the stream carries it.
    req.headers_mut()
        .insert(header::ACCEPT, HeaderValue::from_static("application/json"));
    let task = tokio::spawn(REQUEST_INFO.scope(info, next.run(req)));
    let guard = AbortOnDrop(task.abort_handle());
    let events = stream::unfold(
        State::Running {
            rx,
            task,
            _guard: guard,
        },
        |state| async move {
            let State::Running {
                mut rx,
                mut task,
                _guard,
            } = state
            else {
                return None;
            };
            tokio::select! {
                biased;
                Some(p) = rx.recv() => {
                    let ev = Event::default().event("progress").json_data(p).unwrap_or_default();
                    Some((Ok::<_, std::convert::Infallible>(ev), State::Running { rx, task, _guard }))
                }
                done = &mut task => {
                    let ev = match done {
                        Ok(resp) => final_event(resp).await,
                        Err(_) => Event::default().event("problem").data(
                            r#"{"type":"/problems/internal","title":"Internal error","status":500,"code":"INTERNAL","detail":"the calculation ended without an answer","errors":[]}"#,
                        ),
                    };
                    Some((Ok(ev), State::Done))
                }
            }
        },
    );
    Sse::new(events)
        .keep_alive(KeepAlive::default())
        .into_response()
}

/// `result` with the JSON answer, or `problem` with the problem details.
async fn final_event(resp: Response) -> Event {
    let ok = resp.status().is_success();
    let body = match resp.into_body().collect().await {
        Ok(b) => String::from_utf8_lossy(&b.to_bytes()).into_owned(),
        Err(_) => String::new(),
    };
    Event::default()
        .event(if ok { "result" } else { "problem" })
        .data(body)
}
