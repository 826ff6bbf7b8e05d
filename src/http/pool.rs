//! The compute pool: calculations run on the process's one rayon pool (sized by
//! `--compute-threads`), at most `slots` at once, with at most `queue_depth` more waiting; beyond
//! that a request is refused with 503 + `Retry-After`.
//!
//! Each job receives a [`Budget`]: the request's own time limit (capped by the server's maximum)
//! counted from the request's arrival, so queueing spends it too; the number of threads its
//! parallel parts may use (`--threads-per-job`, through [`crate::numerics::parallel`], on the same
//! rayon pool, so the CPU of all jobs together stays within the pool); and a cancellation flag that
//! is raised when the request is dropped (the client went away), so the job stops at its next
//! budget check and frees its slot. Solvers check the budget every iteration and return their
//! best-so-far answer with an honest stop reason.

use std::panic::AssertUnwindSafe;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use tokio::sync::{OwnedSemaphorePermit, Semaphore};

use crate::numerics::Budget;

use super::problem::ApiError;

/// Seconds a refused client is told to wait before retrying.
const RETRY_AFTER_S: u64 = 1;

/// Semaphore-bounded access to tokio's blocking pool.
#[derive(Clone)]
pub struct ComputePool {
    slots: Arc<Semaphore>,
    waiting: Arc<AtomicUsize>,
    queue_depth: usize,
    max_budget: Duration,
    threads_per_job: usize,
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
            tracing::warn!(
                "client went away; the running job is cancelled at its next budget check"
            );
        }
    }
}

/// Decrements the waiting counter however the wait ends (permit, timeout or cancellation).
struct WaitGuard(Arc<AtomicUsize>);

impl Drop for WaitGuard {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

impl ComputePool {
    /// A pool with `slots` concurrent jobs, `queue_depth` waiters and a server-wide budget cap;
    /// each job may use every thread of the rayon pool for its parallel parts.
    #[must_use]
    pub fn new(slots: usize, queue_depth: usize, max_budget: Duration) -> Self {
        Self {
            slots: Arc::new(Semaphore::new(slots.max(1))),
            waiting: Arc::new(AtomicUsize::new(0)),
            queue_depth,
            max_budget,
            threads_per_job: rayon::current_num_threads(),
        }
    }

    /// The same pool with `threads` threads per job for parallel parts (at least 1).
    #[must_use]
    pub fn with_threads_per_job(mut self, threads: usize) -> Self {
        self.threads_per_job = threads.max(1);
        self
    }

    /// Threads one job may use for its parallel parts.
    #[must_use]
    pub fn threads_per_job(&self) -> usize {
        self.threads_per_job
    }

    /// The server-wide cap on a job's time budget.
    #[must_use]
    pub fn max_budget(&self) -> Duration {
        self.max_budget
    }

    /// Compute slots free right now.
    #[must_use]
    pub fn available_slots(&self) -> usize {
        self.slots.available_permits()
    }

    /// Take a slot, waiting in the queue if there is room; 503 when the queue is full or the wait
    /// outlasts `max_wait`.
    pub async fn acquire(&self, max_wait: Duration) -> Result<OwnedSemaphorePermit, ApiError> {
        if let Ok(p) = Arc::clone(&self.slots).try_acquire_owned() {
            return Ok(p);
        }
        if self.waiting.fetch_add(1, Ordering::SeqCst) >= self.queue_depth {
            self.waiting.fetch_sub(1, Ordering::SeqCst);
            return Err(ApiError::overloaded(RETRY_AFTER_S));
        }
        let _guard = WaitGuard(Arc::clone(&self.waiting));
        match tokio::time::timeout(max_wait, Arc::clone(&self.slots).acquire_owned()).await {
            Ok(Ok(p)) => Ok(p),
            _ => Err(ApiError::overloaded(RETRY_AFTER_S)),
        }
    }

    /// Run `job` on the compute pool with a budget of `requested` (capped by the server maximum;
    /// the maximum when `None`) counted from now, queueing included. The job keeps the caller's
    /// tracing span. A panic inside the job is logged and becomes a 500 whose body does not echo
    /// it. Dropping the returned future (the client went away) cancels the job's budget.
    pub async fn run<T, F>(&self, requested: Option<Duration>, job: F) -> Result<T, ApiError>
    where
        T: Send + 'static,
        F: FnOnce(&Budget) -> T + Send + 'static,
    {
        let arrived = Instant::now();
        let limit = requested.map_or(self.max_budget, |r| r.min(self.max_budget));
        let permit = self.acquire(limit).await?;
        let mut cancel = CancelOnDrop {
            flag: Arc::new(AtomicBool::new(false)),
            done: false,
        };
        let budget = Budget::starting_at(arrived, limit)
            .with_threads(self.threads_per_job)
            .with_cancel_flag(Arc::clone(&cancel.flag));
        let span = tracing::Span::current();
        let (tx, rx) = tokio::sync::oneshot::channel();
        rayon::spawn(move || {
            let _entered = span.enter();
            let out = std::panic::catch_unwind(AssertUnwindSafe(|| job(&budget)));
            drop(permit);
            // The receiver is gone only when the request was dropped; nobody wants the answer.
            let _ = tx.send(out);
        });
        let out = rx.await;
        cancel.done = true;
        match out {
            Ok(Ok(v)) => Ok(v),
            Ok(Err(payload)) => {
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
}
