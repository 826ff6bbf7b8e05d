//! Failures of the component-importance computation (after validation).

use crate::calc::{CalcFailure, CrossRule};
use crate::numerics::{Budget, StopReason};

/// Why a valid request could not be answered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ComponentImportanceError {
    /// All-simple-path betweenness on a graph with cycles needs more simple paths than allowed.
    #[error(
        "the graph has cycles and all-simple-path betweenness needs more than max_simple_paths = \
         {budget} simple paths (stopped after {enumerated}); use options.betweenness = \
         \"shortest_paths\" (Brandes shortest-path betweenness, O(n·m), a different measure) or \
         raise options.max_simple_paths (at most 1e8)"
    )]
    SimplePathBudget {
        /// Simple paths enumerated when the budget ran out.
        enumerated: u64,
        /// The `max_simple_paths` budget.
        budget: u64,
    },
    /// The exact propagation sum over simple paths of length ≤ K on a cyclic graph needs more
    /// paths than allowed.
    #[error(
        "the graph has cycles and the exact propagation sum over simple paths of length <= \
         {path_cap} needs more than max_simple_paths = {budget} paths (stopped after \
         {enumerated}); use options.path_method = \"walks\" (matrix powers, an upper bound on \
         cyclic graphs), options.path_cap <= 3 (exact closed form, polynomial) or raise \
         options.max_simple_paths (at most 1e8)"
    )]
    PropagationPathBudget {
        /// Paths enumerated when the budget ran out.
        enumerated: u64,
        /// The `max_simple_paths` budget.
        budget: u64,
        /// The path cap K.
        path_cap: usize,
    },
    /// The caller's time or evaluation budget ran out during a stage.
    #[error(
        "computation stopped during {stage} ({reason:?}) after {elapsed_ms:.1} ms and \
         {evaluations} path evaluations; the graph is too large or dense for the time budget \
         (try options.betweenness = \"shortest_paths\", options.path_method = \"walks\", a \
         smaller path_cap, fewer times_h or outputs.centralities = false)"
    )]
    Stopped {
        /// The stage that was running.
        stage: &'static str,
        /// Why it stopped.
        reason: StopReason,
        /// Paths enumerated so far.
        evaluations: u64,
        /// Elapsed time \[ms\].
        elapsed_ms: f64,
    },
    /// The Weibull hazard rate or the failure-mode risk RI = λ·S of a component exceeds the f64
    /// range at a requested time (β < 1 with t ≪ η, or β > 1 with t ≫ η, at absurd scales).
    #[error(
        "the hazard rate of component \"{id}\" at t = {time_h} h is beyond the f64 range \
         (λ = {lambda:e} /h, RI = λ·Σα·impact = {ri:e} /h); check eta_h, beta and times_h"
    )]
    RateOverflow {
        /// Component index.
        component: usize,
        /// Component id.
        id: String,
        /// Time index.
        time_index: usize,
        /// Time \[h\].
        time_h: f64,
        /// λ [1/h] (possibly infinite).
        lambda: f64,
        /// RI [1/h] (possibly infinite).
        ri: f64,
    },
    /// A result failed its final finiteness/consistency check (a defect, reported instead of
    /// returning NaN).
    #[error("internal consistency check failed: {what}")]
    Inconsistent {
        /// What failed.
        what: String,
    },
}

/// All-simple-path betweenness on a cyclic graph stays within `max_simple_paths`.
pub const SIMPLE_PATH_BUDGET_RULE: CrossRule = CrossRule::too_large(
    "SIMPLE_PATH_BUDGET_EXCEEDED",
    &[
        "/options/betweenness",
        "/options/max_simple_paths",
        "/edges",
    ],
    "On a graph with cycles, all-simple-path betweenness enumerates at most max_simple_paths \
     simple paths (else use betweenness \"shortest_paths\").",
);
/// The exact propagation sum on a cyclic graph with K > 3 stays within `max_simple_paths`.
pub const PROPAGATION_PATH_BUDGET_RULE: CrossRule = CrossRule::too_large(
    "PROPAGATION_PATH_BUDGET_EXCEEDED",
    &[
        "/options/path_method",
        "/options/path_cap",
        "/options/max_simple_paths",
        "/edges",
    ],
    "On a graph with cycles, the exact propagation sum over simple paths of length <= path_cap \
     enumerates at most max_simple_paths paths (else use path_method \"walks\" or path_cap <= 3).",
);
/// The work fits the request's time and evaluation budget.
pub const BUDGET_RULE: CrossRule = CrossRule::too_large(
    "BUDGET_EXHAUSTED",
    &["/time_limit_ms"],
    "The calculation finishes within the request's time_limit_ms (capped by the service).",
);
/// Every hazard rate and failure-mode risk stays within f64.
pub const HAZARD_RATE_RULE: CrossRule = CrossRule::invalid(
    "HAZARD_RATE_OVERFLOW",
    &["/components/*/weibull", "/times_h/*"],
    "The Weibull hazard rate λ(t) and the risk RI = λ·Σα·impact of every component stay finite \
     in f64 at every requested time.",
);
/// Every reported number is finite and consistent.
pub const NUMERICAL_RULE: CrossRule = CrossRule::infeasible(
    "NUMERICAL_FAILURE",
    &[],
    "Every reported number is finite and the indices are consistent (a final check).",
);

impl From<ComponentImportanceError> for CalcFailure {
    fn from(e: ComponentImportanceError) -> Self {
        let detail = e.to_string();
        match &e {
            ComponentImportanceError::SimplePathBudget { .. } => {
                SIMPLE_PATH_BUDGET_RULE.fail("/options/betweenness", detail)
            }
            ComponentImportanceError::PropagationPathBudget { .. } => {
                PROPAGATION_PATH_BUDGET_RULE.fail("/options/path_method", detail)
            }
            ComponentImportanceError::RateOverflow { component, .. } => {
                HAZARD_RATE_RULE.fail(format!("/components/{component}/weibull"), detail)
            }
            ComponentImportanceError::Stopped { .. } => BUDGET_RULE.fail_general(detail),
            ComponentImportanceError::Inconsistent { .. } => NUMERICAL_RULE.fail_general(detail),
        }
    }
}

/// Work counters of the budgeted stages (per-source passes and enumerated paths).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Work {
    /// Per-source passes (BFS, path-count DP, DFS roots, power iterations).
    pub passes: u64,
    /// Simple paths enumerated by depth-first search (betweenness and propagation).
    pub paths: u64,
}

impl Work {
    /// Fail with [`ComponentImportanceError::Stopped`] if the budget is spent.
    ///
    /// # Errors
    /// [`ComponentImportanceError::Stopped`] when the deadline passed or the evaluation cap
    /// (counted in enumerated paths) is reached.
    pub fn check(
        &self,
        budget: &Budget,
        stage: &'static str,
    ) -> Result<(), ComponentImportanceError> {
        match budget.check(self.paths) {
            None => Ok(()),
            Some(reason) => Err(ComponentImportanceError::Stopped {
                stage,
                reason,
                evaluations: self.paths,
                elapsed_ms: budget.elapsed_ms(),
            }),
        }
    }
}
