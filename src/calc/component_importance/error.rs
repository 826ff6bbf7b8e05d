//! Failures of the component-importance computation (after validation).

use crate::calc::{CalcFailure, FieldIssue, ProblemClass};
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

impl From<ComponentImportanceError> for CalcFailure {
    fn from(e: ComponentImportanceError) -> Self {
        let detail = e.to_string();
        let (class, code, pointer) = match &e {
            ComponentImportanceError::SimplePathBudget { .. } => (
                ProblemClass::TooLarge,
                "SIMPLE_PATH_BUDGET_EXCEEDED",
                Some("/options/betweenness"),
            ),
            ComponentImportanceError::PropagationPathBudget { .. } => (
                ProblemClass::TooLarge,
                "PROPAGATION_PATH_BUDGET_EXCEEDED",
                Some("/options/path_method"),
            ),
            ComponentImportanceError::RateOverflow { component, .. } => {
                let p = format!("/components/{component}/weibull");
                return Self {
                    class: ProblemClass::InvalidInput,
                    code: "HAZARD_RATE_OVERFLOW",
                    errors: vec![FieldIssue {
                        pointer: p,
                        detail: detail.clone(),
                    }],
                    detail,
                };
            }
            ComponentImportanceError::Stopped { .. } => {
                (ProblemClass::TooLarge, "BUDGET_EXHAUSTED", None)
            }
            ComponentImportanceError::Inconsistent { .. } => {
                (ProblemClass::Infeasible, "NUMERICAL_FAILURE", None)
            }
        };
        let errors = pointer
            .map(|p| {
                vec![FieldIssue {
                    pointer: p.to_owned(),
                    detail: detail.clone(),
                }]
            })
            .unwrap_or_default();
        Self {
            class,
            code,
            detail,
            errors,
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
