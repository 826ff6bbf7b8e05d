//! Time, evaluation and thread budgets that iterative solvers check every iteration.
//!
//! Blocking tasks cannot be aborted from outside, so every solver polls its [`Budget`] once per
//! iteration (generation, Newton step, sweep node, ...) and stops with [`StopReason::Deadline`],
//! [`StopReason::MaxEvaluations`] or [`StopReason::Cancelled`] when it is spent, returning its
//! best-so-far answer. The budget also says how many threads the job may use for its parallel
//! parts ([`Budget::threads`], consumed by [`crate::numerics::parallel`]): the compute pool sets it,
//! so that admission bounds the CPU.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;
use utoipa::ToSchema;

/// A wall-clock deadline plus an optional cap on objective/model evaluations, the number of threads
/// the job may use, a cancellation flag the service raises when the client has gone, and an
/// optional progress sink (streaming clients see how far a long job is).
#[derive(Clone)]
pub struct Budget {
    start: Instant,
    deadline: Instant,
    max_evaluations: Option<u64>,
    threads: usize,
    cancel: Option<Arc<AtomicBool>>,
    progress: Option<Arc<ProgressSink>>,
    max_response_bytes: Option<u64>,
}

impl std::fmt::Debug for Budget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Budget")
            .field("remaining", &self.remaining())
            .field("max_evaluations", &self.max_evaluations)
            .field("threads", &self.threads)
            .field("cancelled", &self.cancelled())
            .field("progress", &self.progress.is_some())
            .field("max_response_bytes", &self.max_response_bytes)
            .finish()
    }
}

/// How far a long job is, for streaming clients.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct Progress {
    /// Fraction of the work done, in [0, 1] (an estimate for open-ended solvers).
    pub fraction: f64,
    /// Best objective so far, when the job is an optimisation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub best: Option<f64>,
    /// Wall-clock time since the request arrived \[ms\].
    pub elapsed_ms: f64,
}

/// Where progress goes: a callback, called at most every [`PROGRESS_INTERVAL`].
pub struct ProgressSink {
    send: Box<dyn Fn(Progress) + Send + Sync>,
    last_ns: std::sync::atomic::AtomicU64,
}

/// Smallest interval between two progress reports of one job.
pub const PROGRESS_INTERVAL: Duration = Duration::from_millis(100);

impl ProgressSink {
    /// A sink that calls `send` with each report.
    pub fn new(send: impl Fn(Progress) + Send + Sync + 'static) -> Self {
        Self {
            send: Box::new(send),
            last_ns: std::sync::atomic::AtomicU64::new(0),
        }
    }
}

/// The threads a job may use when nobody says otherwise: the machine's cores (read once: the
/// query reads cgroup files and costs tens of microseconds).
fn default_threads() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES
        .get_or_init(|| std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get))
}

impl Budget {
    /// A budget of `limit` wall-clock time from now, without an evaluation cap.
    #[must_use]
    pub fn new(limit: Duration) -> Self {
        Self::starting_at(Instant::now(), limit)
    }

    /// A budget of `limit` counted from `start` (for example the request's arrival, so that time
    /// spent waiting in the admission queue is part of the budget), without an evaluation cap.
    #[must_use]
    pub fn starting_at(start: Instant, limit: Duration) -> Self {
        Self {
            start,
            deadline: start
                .checked_add(limit)
                .unwrap_or(start + Duration::from_secs(86_400)),
            max_evaluations: None,
            threads: default_threads(),
            cancel: None,
            progress: None,
            max_response_bytes: None,
        }
    }

    /// The same budget, reporting progress to `sink`.
    #[must_use]
    pub fn with_progress(mut self, sink: Arc<ProgressSink>) -> Self {
        self.progress = Some(sink);
        self
    }

    /// Report progress (`fraction` of the work done, best objective so far). Cheap when nobody
    /// listens; at most one report per [`PROGRESS_INTERVAL`] reaches the listener, except the
    /// first.
    pub fn progress(&self, fraction: f64, best: Option<f64>) {
        let Some(sink) = &self.progress else {
            return;
        };
        let now = u64::try_from(self.start.elapsed().as_nanos()).unwrap_or(u64::MAX);
        let last = sink.last_ns.load(Ordering::Relaxed);
        let interval = u64::try_from(PROGRESS_INTERVAL.as_nanos()).unwrap_or(u64::MAX);
        if last != 0 && now.saturating_sub(last) < interval {
            return;
        }
        if sink
            .last_ns
            .compare_exchange(last, now.max(1), Ordering::Relaxed, Ordering::Relaxed)
            .is_err()
        {
            return;
        }
        (sink.send)(Progress {
            fraction: if fraction.is_finite() {
                fraction.clamp(0.0, 1.0)
            } else {
                0.0
            },
            best: best.filter(|b| b.is_finite()),
            elapsed_ms: self.elapsed_ms(),
        });
    }

    /// The larger of the fractions of the time limit and of the evaluation cap spent after
    /// `evaluations` evaluations: a progress estimate for open-ended solvers.
    #[must_use]
    pub fn spent_fraction(&self, evaluations: u64) -> f64 {
        let total = self
            .deadline
            .saturating_duration_since(self.start)
            .as_secs_f64();
        let by_time = if total > 0.0 {
            self.start.elapsed().as_secs_f64() / total
        } else {
            1.0
        };
        // Evaluation counts are far below 2^53: exact in f64.
        let by_evaluations = self
            .max_evaluations
            .map_or(0.0, |m| evaluations as f64 / m.max(1) as f64);
        by_time.max(by_evaluations).clamp(0.0, 1.0)
    }

    /// A budget that, for practical purposes, never runs out (one day). For tests and benchmarks.
    #[must_use]
    pub fn unlimited() -> Self {
        Self::new(Duration::from_secs(86_400))
    }

    /// The same deadline with an evaluation cap.
    #[must_use]
    pub fn with_max_evaluations(mut self, max: u64) -> Self {
        self.max_evaluations = Some(max);
        self
    }

    /// The same budget allowed `threads` threads (at least 1) for its parallel parts.
    #[must_use]
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads.max(1);
        self
    }

    /// The same budget, cancelled once `flag` is raised (the service raises it when the client
    /// disconnects or the service shuts down).
    #[must_use]
    pub fn with_cancel_flag(mut self, flag: Arc<AtomicBool>) -> Self {
        self.cancel = Some(flag);
        self
    }

    /// The same budget, with the service's limit on the size of the answer \[bytes\]: modules
    /// that can estimate their answer's size refuse a request over it before computing
    /// ([`crate::calc::common::ResponseSize::check`]).
    #[must_use]
    pub fn with_max_response_bytes(mut self, bytes: usize) -> Self {
        self.max_response_bytes = Some(u64::try_from(bytes).unwrap_or(u64::MAX));
        self
    }

    /// The limit on the size of the answer \[bytes\], if the service sets one.
    #[must_use]
    pub fn max_response_bytes(&self) -> Option<u64> {
        self.max_response_bytes
    }

    /// Threads this job may use for its parallel parts (at least 1).
    #[must_use]
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// True once the job has been cancelled (client gone, service stopping).
    #[must_use]
    pub fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// The tighter of this budget's deadline and `now + limit`.
    #[must_use]
    pub fn capped(mut self, limit: Duration) -> Self {
        if let Some(d) = Instant::now().checked_add(limit) {
            self.deadline = self.deadline.min(d);
        }
        self
    }

    /// True once the wall-clock deadline has passed, or the job was cancelled (a cancelled job is
    /// out of time: every solver that polls `expired` stops at its next check).
    #[must_use]
    pub fn expired(&self) -> bool {
        self.cancelled() || Instant::now() >= self.deadline
    }

    /// True when `evaluations` has reached the evaluation cap (never, without a cap).
    #[must_use]
    pub fn evaluations_exhausted(&self, evaluations: u64) -> bool {
        self.max_evaluations.is_some_and(|m| evaluations >= m)
    }

    /// The evaluation cap, if any.
    #[must_use]
    pub fn max_evaluations(&self) -> Option<u64> {
        self.max_evaluations
    }

    /// Why a solver must stop now, if it must: cancellation first, then the deadline, then the
    /// evaluation cap.
    #[must_use]
    pub fn check(&self, evaluations: u64) -> Option<StopReason> {
        if self.cancelled() {
            Some(StopReason::Cancelled)
        } else if self.expired() {
            Some(StopReason::Deadline)
        } else if self.evaluations_exhausted(evaluations) {
            Some(StopReason::MaxEvaluations)
        } else {
            None
        }
    }

    /// Time left before the deadline (zero once expired).
    #[must_use]
    pub fn remaining(&self) -> Duration {
        self.deadline.saturating_duration_since(Instant::now())
    }

    /// Wall-clock time since the budget was created, in milliseconds.
    #[must_use]
    pub fn elapsed_ms(&self) -> f64 {
        self.start.elapsed().as_secs_f64() * 1e3
    }
}

/// How an iterative solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The convergence criterion was met.
    Converged,
    /// The iteration/generation limit was reached.
    MaxIterations,
    /// The evaluation cap was reached; the best-so-far answer is returned.
    MaxEvaluations,
    /// The wall-clock budget ran out; the best-so-far answer is returned.
    Deadline,
    /// No relative improvement for the configured number of iterations.
    Stall,
    /// The method is closed-form or finite: it ran to completion.
    Completed,
    /// The client went away or the service is stopping; the job stopped at its next check.
    Cancelled,
}

/// What a solver cost and how it stopped; every endpoint with iterative or swept work returns one
/// as `report` (one shape across the service).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
#[schema(as = Report)]
pub struct SolverReport {
    /// How the solver stopped.
    pub stop_reason: StopReason,
    /// Iterations (generations, Newton steps, sweep nodes) performed.
    pub iterations: u64,
    /// Model/objective evaluations performed.
    pub evaluations: u64,
    /// Wall-clock time spent in the solver \[ms\].
    pub elapsed_ms: f64,
}
