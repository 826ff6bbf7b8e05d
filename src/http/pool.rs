//! The compute pool: calculations run on tokio's blocking pool, at most `slots` at once, with at
//! most `queue_depth` more waiting; beyond that a request is refused with 503 + `Retry-After`.
//!
//! Each job receives a [`Budget`]: the request's own time limit capped by the server's maximum.
//! Blocking tasks cannot be cancelled, so solvers check the budget every iteration and return
//! their best-so-far answer with an honest stop reason.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use tokio::sync::{OwnedSemaphorePermit, Semaphore};
use tracing::Instrument;

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
}

/// Decrements the waiting counter however the wait ends (permit, timeout or cancellation).
struct WaitGuard(Arc<AtomicUsize>);

impl Drop for WaitGuard {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

impl ComputePool {
    /// A pool with `slots` concurrent jobs, `queue_depth` waiters and a server-wide budget cap.
    #[must_use]
    pub fn new(slots: usize, queue_depth: usize, max_budget: Duration) -> Self {
        Self {
            slots: Arc::new(Semaphore::new(slots.max(1))),
            waiting: Arc::new(AtomicUsize::new(0)),
            queue_depth,
            max_budget,
        }
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

    /// Run `job` on the blocking pool with a budget of `requested` (capped by the server maximum;
    /// the maximum when `None`). The job keeps the caller's tracing span. A panic inside the job
    /// is logged and becomes a 500 whose body does not echo it.
    pub async fn run<T, F>(&self, requested: Option<Duration>, job: F) -> Result<T, ApiError>
    where
        T: Send + 'static,
        F: FnOnce(&Budget) -> T + Send + 'static,
    {
        let limit = requested.map_or(self.max_budget, |r| r.min(self.max_budget));
        let permit = self.acquire(limit).await?;
        let span = tracing::Span::current();
        let handle = tokio::task::spawn_blocking(move || {
            let _entered = span.enter();
            let budget = Budget::new(limit);
            let out = job(&budget);
            drop(permit);
            out
        });
        match handle.instrument(tracing::Span::current()).await {
            Ok(v) => Ok(v),
            Err(e) => {
                if e.is_panic() {
                    let msg = panic_message(e.into_panic());
                    tracing::error!(panic = %msg, "compute job panicked");
                } else {
                    tracing::error!(error = %e, "compute job failed to complete");
                }
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
