//! The compute pool: admission, queueing, lanes, budgets and cancellation for every calculation.
//!
//! * **Heavy lane.** Calculations run on the process's one rayon pool (sized by
//!   `--compute-threads`), at most `slots` at once, with at most `queue_depth` more waiting; beyond
//!   that a request is refused with 503 + `Retry-After`. The `Retry-After` value is the real
//!   backlog: jobs ahead × the recent mean job time / slots. A request whose expected wait already
//!   exceeds its time budget is refused at once instead of after waiting for nothing.
//! * **Cheap lane.** Requests known to be cheap (a closed-form evaluation: the route's recent jobs
//!   took well under a millisecond and the body is small) do not queue behind sweeps: they run on
//!   a small separate lane (twice the slots at once, on tokio's blocking threads), or, below half a
//!   millisecond, inline on the thread serving the request (at most cores − 1 at once, so one
//!   connection thread is always free). Their CPU is bounded by that lane's size × their (short)
//!   duration.
//! * **Budget.** Each job receives a [`Budget`]: the request's own time limit (capped by the
//!   server's maximum) counted from the request's arrival, so queueing spends it too; the threads
//!   its parallel parts may use (`--threads-per-job`, on the same rayon pool); and a cancellation
//!   flag raised when the request is dropped (the client went away) or the service's shutdown
//!   deadline passes, so the job stops at its next budget check and frees its slot.
//! * A panic inside a job is logged and becomes a 500 whose body does not echo it.

use std::collections::HashMap;
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

use tokio::sync::{OwnedSemaphorePermit, Semaphore};

use crate::numerics::Budget;

use super::problem::ApiError;

/// A route whose recent jobs took less than this (mean) is served on the cheap lane.
const CHEAP_JOB: Duration = Duration::from_millis(2);
/// A cheap route whose recent jobs took less than this runs inline, on the thread that serves the
/// request (no hand-off to another thread: the hand-off alone costs tens of microseconds).
const INLINE_JOB: Duration = Duration::from_micros(500);
/// Bodies above this size never take the cheap lane (decoding alone may take milliseconds).
const CHEAP_BODY_BYTES: usize = 64 * 1024;
/// Weight of the newest observation in the running mean of job times.
const EWMA_WEIGHT: f64 = 0.2;

/// What a handler knows about a request before it is queued.
#[derive(Debug, Clone, Default)]
pub struct Demand {
    /// The request's own time limit (`time_limit_ms`), if it gives one.
    pub time_limit: Option<Duration>,
    /// The module's estimate of the work, if it has one.
    pub cost: Cost,
}

/// A module's estimate of a request's work.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Cost {
    /// Unknown: the lane is chosen from the route's recent job times and the body size.
    #[default]
    Unknown,
    /// Closed form, sub-millisecond: always the cheap lane.
    Cheap,
    /// Iterative or swept work: always the heavy lane.
    Heavy,
}

impl From<Option<Duration>> for Demand {
    fn from(time_limit: Option<Duration>) -> Self {
        Self {
            time_limit,
            cost: Cost::Unknown,
        }
    }
}

tokio::task_local! {
    /// The matched route and body size of the request being served (set by the request layer),
    /// so the pool can learn per-route job times without every handler passing them.
    pub static REQUEST_INFO: RequestInfo;
}

/// Route and body size of the request in flight, and where its progress goes.
#[derive(Clone, Default)]
pub struct RequestInfo {
    /// The matched route (e.g. `/v1/cognates`), or empty.
    pub route: String,
    /// Declared body size \[bytes\], if known.
    pub body_bytes: usize,
    /// Progress sink of a streaming request (`Accept: text/event-stream`).
    pub progress: Option<Arc<crate::numerics::budget::ProgressSink>>,
}

/// Where a job runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lane {
    /// On the thread serving the request (sub-millisecond jobs).
    Inline,
    /// On the cheap lane (tokio's blocking threads, `cheap` permits).
    Cheap,
    /// On the rayon compute pool behind the admission semaphore.
    Heavy,
}

/// Semaphore-bounded access to the compute pool.
#[derive(Clone)]
pub struct ComputePool {
    inner: Arc<Inner>,
}

struct Inner {
    slots: Arc<Semaphore>,
    n_slots: usize,
    cheap: Arc<Semaphore>,
    /// Jobs running inline on the connection threads at once (always leaves one thread free).
    inline: Arc<Semaphore>,
    waiting: AtomicUsize,
    queue_depth: usize,
    max_budget: Duration,
    threads_per_job: AtomicUsize,
    /// Recent mean job time per route [µs].
    route_us: Mutex<HashMap<String, f64>>,
    /// Recent mean heavy-lane job time [µs], for the backlog estimate.
    heavy_mean_us: AtomicU64,
    /// Cancellation flags of running jobs (weak: a finished job's flag is gone).
    running: Mutex<Vec<Weak<AtomicBool>>>,
    stopping: AtomicBool,
}

/// Raises the job's cancellation flag when the request is dropped before the job finished.
struct CancelOnDrop {
    flag: Arc<AtomicBool>,
    done: bool,
}

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if !self.done {
            self.flag.store(true, Ordering::Relaxed);
            metrics::counter!("mechcalc_jobs_cancelled_total", "cause" => "client_gone")
                .increment(1);
            tracing::warn!(
                "client went away; the running job is cancelled at its next budget check"
            );
        }
    }
}

/// Decrements the waiting counter however the wait ends (permit, timeout or cancellation).
struct WaitGuard<'a>(&'a AtomicUsize);

impl Drop for WaitGuard<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
        metrics::gauge!("mechcalc_queue_waiting").decrement(1.0);
    }
}

impl ComputePool {
    /// A pool with `slots` concurrent heavy jobs, `queue_depth` waiters and a server-wide budget
    /// cap; each job may use every thread of the rayon pool for its parallel parts; the cheap lane
    /// runs as many jobs at once as there are slots, times two.
    #[must_use]
    pub fn new(slots: usize, queue_depth: usize, max_budget: Duration) -> Self {
        let slots = slots.max(1);
        Self {
            inner: Arc::new(Inner {
                slots: Arc::new(Semaphore::new(slots)),
                n_slots: slots,
                cheap: Arc::new(Semaphore::new(2 * slots)),
                inline: Arc::new(Semaphore::new(
                    std::thread::available_parallelism()
                        .map_or(1, std::num::NonZeroUsize::get)
                        .saturating_sub(1)
                        .max(1),
                )),
                waiting: AtomicUsize::new(0),
                queue_depth,
                max_budget,
                threads_per_job: AtomicUsize::new(rayon::current_num_threads()),
                route_us: Mutex::new(HashMap::new()),
                heavy_mean_us: AtomicU64::new(0),
                running: Mutex::new(Vec::new()),
                stopping: AtomicBool::new(false),
            }),
        }
    }

    /// The same pool with `threads` threads per job for parallel parts (at least 1).
    #[must_use]
    pub fn with_threads_per_job(self, threads: usize) -> Self {
        self.inner
            .threads_per_job
            .store(threads.max(1), Ordering::Relaxed);
        self
    }

    /// Threads one job may use for its parallel parts.
    #[must_use]
    pub fn threads_per_job(&self) -> usize {
        self.inner.threads_per_job.load(Ordering::Relaxed)
    }

    /// The server-wide cap on a job's time budget.
    #[must_use]
    pub fn max_budget(&self) -> Duration {
        self.inner.max_budget
    }

    /// Heavy-lane slots free right now.
    #[must_use]
    pub fn available_slots(&self) -> usize {
        self.inner.slots.available_permits()
    }

    /// Heavy-lane slots in all.
    #[must_use]
    pub fn slots(&self) -> usize {
        self.inner.n_slots
    }

    /// Requests waiting for a heavy-lane slot right now.
    #[must_use]
    pub fn waiting(&self) -> usize {
        self.inner.waiting.load(Ordering::SeqCst)
    }

    /// Stop taking work and cancel every running job (the shutdown deadline has passed).
    pub fn cancel_all(&self) {
        self.inner.stopping.store(true, Ordering::SeqCst);
        let flags = self
            .inner
            .running
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default();
        let mut n = 0u64;
        for f in flags.iter().filter_map(Weak::upgrade) {
            f.store(true, Ordering::Relaxed);
            n += 1;
        }
        metrics::counter!("mechcalc_jobs_cancelled_total", "cause" => "shutdown").increment(n);
        tracing::warn!(jobs = n, "shutdown deadline: running jobs cancelled");
    }

    /// Expected wait for a heavy slot with `ahead` queued jobs ahead and every slot busy [µs]:
    /// the running jobs are on average half done, so they count as half a job each.
    fn expected_wait_us(&self, ahead: usize) -> u64 {
        let mean = self.inner.heavy_mean_us.load(Ordering::Relaxed) as f64;
        let slots = self.inner.n_slots as f64;
        ((ahead as f64 + 0.5 * slots) * mean / slots).round() as u64
    }

    /// Seconds to tell a refused client: the backlog ahead of it, at least 1.
    fn retry_after_s(&self) -> u64 {
        self.expected_wait_us(self.waiting())
            .div_ceil(1_000_000)
            .max(1)
    }

    /// Take a heavy slot, waiting in the queue if there is room; 503 when the queue is full, when
    /// the expected wait already exceeds `max_wait`, or when the wait outlasts it.
    pub async fn acquire(&self, max_wait: Duration) -> Result<OwnedSemaphorePermit, ApiError> {
        if self.inner.stopping.load(Ordering::SeqCst) {
            return Err(ApiError::shutting_down());
        }
        if let Ok(p) = Arc::clone(&self.inner.slots).try_acquire_owned() {
            return Ok(p);
        }
        let ahead = self.inner.waiting.fetch_add(1, Ordering::SeqCst);
        metrics::gauge!("mechcalc_queue_waiting").increment(1.0);
        let _guard = WaitGuard(&self.inner.waiting);
        if ahead >= self.inner.queue_depth {
            metrics::counter!("mechcalc_rejected_total", "cause" => "queue_full").increment(1);
            return Err(ApiError::overloaded(self.retry_after_s()));
        }
        let wait_us = self.expected_wait_us(ahead);
        let budget_us = u64::try_from(max_wait.as_micros()).unwrap_or(u64::MAX);
        if wait_us > budget_us {
            metrics::counter!("mechcalc_rejected_total", "cause" => "cannot_start_in_time")
                .increment(1);
            return Err(ApiError::cannot_start_in_time(
                self.retry_after_s(),
                wait_us / 1000,
                budget_us / 1000,
            ));
        }
        match tokio::time::timeout(max_wait, Arc::clone(&self.inner.slots).acquire_owned()).await {
            Ok(Ok(p)) => Ok(p),
            _ => {
                metrics::counter!("mechcalc_rejected_total", "cause" => "wait_timeout")
                    .increment(1);
                Err(ApiError::overloaded(self.retry_after_s()))
            }
        }
    }

    /// The lane of a request on `info` with `cost`.
    fn lane(&self, cost: Cost, info: &RequestInfo) -> Lane {
        let recent_us = self
            .inner
            .route_us
            .lock()
            .ok()
            .and_then(|m| m.get(&info.route).copied());
        let small = info.body_bytes <= CHEAP_BODY_BYTES;
        let inline = small && recent_us.is_some_and(|us| us < INLINE_JOB.as_secs_f64() * 1e6);
        match cost {
            Cost::Heavy => Lane::Heavy,
            Cost::Cheap | Cost::Unknown if inline => Lane::Inline,
            Cost::Cheap => Lane::Cheap,
            Cost::Unknown => {
                if small && recent_us.is_some_and(|us| us < CHEAP_JOB.as_secs_f64() * 1e6) {
                    Lane::Cheap
                } else {
                    Lane::Heavy
                }
            }
        }
    }

    fn observe(&self, route: &str, heavy: bool, elapsed: Duration) {
        let us = elapsed.as_secs_f64() * 1e6;
        if let Ok(mut m) = self.inner.route_us.lock() {
            let e = m.entry(route.to_owned()).or_insert(us);
            *e += EWMA_WEIGHT * (us - *e);
        }
        if heavy {
            let old = self.inner.heavy_mean_us.load(Ordering::Relaxed) as f64;
            let new = if old == 0.0 {
                us
            } else {
                old + EWMA_WEIGHT * (us - old)
            };
            self.inner
                .heavy_mean_us
                .store(new.round() as u64, Ordering::Relaxed);
        }
        metrics::histogram!("mechcalc_job_seconds", "route" => route.to_owned(), "lane" => if heavy { "heavy" } else { "cheap" })
            .record(elapsed.as_secs_f64());
    }

    fn register(&self, flag: &Arc<AtomicBool>) {
        if let Ok(mut v) = self.inner.running.lock() {
            v.retain(|w| w.strong_count() > 0);
            v.push(Arc::downgrade(flag));
        }
    }

    /// Run `job` with a budget of the demand's time limit (capped by the server maximum; the
    /// maximum when `None`) counted from now, queueing included: on the cheap lane when the
    /// request is known to be cheap, else on the rayon pool behind the admission semaphore. The
    /// job keeps the caller's tracing span. Dropping the returned future (the client went away)
    /// cancels the job's budget.
    pub async fn run<T, F>(&self, demand: impl Into<Demand>, job: F) -> Result<T, ApiError>
    where
        T: Send + 'static,
        F: FnOnce(&Budget) -> T + Send + 'static,
    {
        let demand = demand.into();
        let arrived = Instant::now();
        let limit = demand
            .time_limit
            .map_or(self.inner.max_budget, |r| r.min(self.inner.max_budget));
        let info = REQUEST_INFO.try_with(Clone::clone).unwrap_or_default();
        let mut lane = self.lane(demand.cost, &info);
        let inline_permit = match lane {
            Lane::Inline => Arc::clone(&self.inner.inline).try_acquire_owned().ok(),
            _ => None,
        };
        if lane == Lane::Inline && inline_permit.is_none() {
            lane = Lane::Cheap;
        }
        let heavy = lane == Lane::Heavy;
        let permit = match (lane, inline_permit) {
            (Lane::Inline, Some(p)) => p,
            (Lane::Heavy, _) => self.acquire(limit).await?,
            // Cheap jobs last microseconds: wait for the cheap lane rather than queue behind
            // sweeps.
            _ => match tokio::time::timeout(limit, Arc::clone(&self.inner.cheap).acquire_owned())
                .await
            {
                Ok(Ok(p)) => p,
                _ => return Err(ApiError::overloaded(1)),
            },
        };
        let mut cancel = CancelOnDrop {
            flag: Arc::new(AtomicBool::new(false)),
            done: false,
        };
        self.register(&cancel.flag);
        let mut budget = Budget::starting_at(arrived, limit)
            .with_threads(self.threads_per_job())
            .with_cancel_flag(Arc::clone(&cancel.flag));
        if let Some(sink) = &info.progress {
            budget = budget.with_progress(Arc::clone(sink));
        }
        let span = tracing::Span::current();
        let (tx, rx) = tokio::sync::oneshot::channel();
        let gauge = if heavy {
            "mechcalc_heavy_jobs_running"
        } else {
            "mechcalc_cheap_jobs_running"
        };
        metrics::gauge!(gauge).increment(1.0);
        let task = move || {
            let _entered = span.enter();
            let started = Instant::now();
            let out = std::panic::catch_unwind(AssertUnwindSafe(|| job(&budget)));
            let elapsed = started.elapsed();
            let stopped_early = budget.cancelled() || budget.expired();
            drop(permit);
            // The receiver is gone only when the request was dropped; nobody wants the answer.
            let _ = tx.send((out, elapsed, stopped_early));
        };
        match lane {
            Lane::Heavy => rayon::spawn(task),
            Lane::Cheap => drop(tokio::task::spawn_blocking(task)),
            Lane::Inline => task(),
        }
        let out = rx.await;
        cancel.done = true;
        metrics::gauge!(gauge).decrement(1.0);
        match out {
            Ok((Ok(v), elapsed, stopped_early)) => {
                self.observe(&info.route, heavy, elapsed);
                if stopped_early {
                    metrics::counter!("mechcalc_budget_stops_total", "route" => info.route.clone())
                        .increment(1);
                }
                Ok(v)
            }
            Ok((Err(payload), _, _)) => {
                tracing::error!(panic = %panic_message(payload), "compute job panicked");
                Err(ApiError::internal())
            }
            Err(_) => {
                tracing::error!("compute job ended without an answer");
                Err(ApiError::internal())
            }
        }
    }
}

/// Best-effort text of a panic payload, for the log only.
pub(crate) fn panic_message(payload: Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string panic payload".to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn full_queue_is_503_with_retry_after() {
        let pool = ComputePool::new(1, 0, Duration::from_secs(5));
        let held = pool
            .acquire(Duration::from_millis(10))
            .await
            .expect("first slot is free");
        let err = pool
            .acquire(Duration::from_millis(10))
            .await
            .expect_err("pool is full");
        assert_eq!(err.status().as_u16(), 503);
        drop(held);
        assert!(pool.acquire(Duration::from_millis(10)).await.is_ok());
    }

    #[tokio::test]
    async fn waiter_gets_slot_when_released() {
        let pool = ComputePool::new(1, 1, Duration::from_secs(5));
        let held = pool.acquire(Duration::from_millis(10)).await.expect("free");
        let p2 = pool.clone();
        let waiter = tokio::spawn(async move { p2.acquire(Duration::from_secs(5)).await.is_ok() });
        tokio::time::sleep(Duration::from_millis(20)).await;
        drop(held);
        assert!(waiter.await.expect("join"));
    }

    #[tokio::test]
    async fn budget_is_capped_by_server_max() {
        let pool = ComputePool::new(1, 0, Duration::from_millis(50));
        let remaining = pool
            .run(Some(Duration::from_secs(100)), |b| b.remaining())
            .await
            .expect("runs");
        assert!(remaining <= Duration::from_millis(50));
    }

    #[tokio::test]
    async fn panic_becomes_500() {
        let pool = ComputePool::new(1, 0, Duration::from_secs(1));
        let err = pool
            .run(None, |_| -> u8 { panic!("boom") })
            .await
            .expect_err("panics");
        assert_eq!(err.status().as_u16(), 500);
        assert!(!err.body().detail.contains("boom"));
    }

    #[tokio::test]
    async fn a_dropped_request_cancels_its_job() {
        let pool = ComputePool::new(1, 0, Duration::from_secs(30));
        let (seen_tx, seen_rx) = std::sync::mpsc::channel();
        let fut = pool.run(None, move |b| {
            let t = Instant::now();
            while !b.cancelled() && t.elapsed() < Duration::from_secs(20) {
                std::thread::sleep(Duration::from_millis(1));
            }
            let _ = seen_tx.send(b.cancelled());
        });
        // Let the job start, then drop the request future.
        let _ = tokio::time::timeout(Duration::from_millis(50), fut).await;
        let cancelled = seen_rx
            .recv_timeout(Duration::from_secs(5))
            .expect("the job stops");
        assert!(cancelled);
        // The slot is free again: the job's permit is released just after the job returns (with
        // no queue, an attempt in between is refused at once), so allow it a moment.
        let t = Instant::now();
        let mut freed = false;
        while !freed && t.elapsed() < Duration::from_secs(2) {
            freed = pool.acquire(Duration::from_secs(1)).await.is_ok();
            if !freed {
                tokio::time::sleep(Duration::from_millis(5)).await;
            }
        }
        assert!(
            freed,
            "the cancelled job's slot was not released within 2 s"
        );
    }

    #[tokio::test]
    async fn expected_wait_beyond_the_budget_is_refused_at_once() {
        let pool = ComputePool::new(1, 8, Duration::from_secs(30));
        pool.observe("/x", true, Duration::from_secs(2));
        let held = pool.acquire(Duration::from_secs(1)).await.expect("free");
        let t = Instant::now();
        let err = pool
            .acquire(Duration::from_millis(500))
            .await
            .expect_err("cannot start within 0.5 s behind a 2 s job");
        assert_eq!(err.status().as_u16(), 503);
        assert!(t.elapsed() < Duration::from_millis(100), "refused at once");
        assert!(err.body().detail.contains("expected wait"));
        drop(held);
    }
}
