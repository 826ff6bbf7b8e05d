//! Time and evaluation budgets that iterative solvers check every iteration.
//!
//! Blocking tasks cannot be aborted from outside, so every solver polls its [`Budget`] once per
//! iteration (generation, Newton step, sweep node, ...) and stops with [`StopReason::Deadline`] or
//! [`StopReason::MaxEvaluations`] when it is spent, returning its best-so-far answer.

use std::time::{Duration, Instant};

use serde::Serialize;
use utoipa::ToSchema;

/// A wall-clock deadline plus an optional cap on objective/model evaluations.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    start: Instant,
    deadline: Instant,
    max_evaluations: Option<u64>,
}

impl Budget {
    /// A budget of `limit` wall-clock time from now, without an evaluation cap.
    #[must_use]
    pub fn new(limit: Duration) -> Self {
        let start = Instant::now();
        Self {
            start,
            deadline: start
                .checked_add(limit)
                .unwrap_or(start + Duration::from_secs(86_400)),
            max_evaluations: None,
        }
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

    /// The tighter of this budget's deadline and `now + limit`.
    #[must_use]
    pub fn capped(mut self, limit: Duration) -> Self {
        if let Some(d) = Instant::now().checked_add(limit) {
            self.deadline = self.deadline.min(d);
        }
        self
    }

    /// True once the wall-clock deadline has passed.
    #[must_use]
    pub fn expired(&self) -> bool {
        Instant::now() >= self.deadline
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

    /// Why a solver must stop now, if it must: deadline first, then the evaluation cap.
    #[must_use]
    pub fn check(&self, evaluations: u64) -> Option<StopReason> {
        if self.expired() {
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
}

/// What a solver cost and how it stopped; every heavy endpoint returns one.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct SolverReport {
    /// How the solver stopped.
    pub stop_reason: StopReason,
    /// Iterations (generations, Newton steps, sweep nodes) performed.
    #[schema(minimum = 0)]
    pub iterations: u64,
    /// Model/objective evaluations performed.
    #[schema(minimum = 0)]
    pub evaluations: u64,
    /// Wall-clock time spent in the solver [ms].
    #[schema(minimum = 0.0)]
    pub elapsed_ms: f64,
}
