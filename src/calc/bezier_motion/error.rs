//! Failures of the Bezier-motion computation that depend on derived quantities (field-level
//! validation problems are collected in `input.rs`).

use thiserror::Error;

use crate::calc::{CalcFailure, ProblemClass};

/// Error of [`super::compute::compute`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BezierMotionError {
    /// The end state needs the Gauss–Legendre path (`r > 1`) and `rho_max = T·|p_fast|` exceeds
    /// its limit (very over-damped joints, ξ ≳ 30).
    #[error(
        "rho_max = T·|fastest pole| = {rho_max:.6e} exceeds {limit:e} on the Gauss–Legendre path \
         (damping ratio ξ = {xi:.6e}); reduce c, T or k·f"
    )]
    RhoTooLarge {
        /// `T·|p_fast|`.
        rho_max: f64,
        /// The limit.
        limit: f64,
        /// Damping ratio of the offending system.
        xi: f64,
        /// Request field to blame.
        pointer: String,
    },
    /// A time history was requested and `rho_max` exceeds the sub-step budget of spec §3.8.
    #[error(
        "time history needs ≈ rho_max/8 sub-steps: rho_max = {rho_max:.6e} exceeds {limit:e}; \
         omit outputs.time_history or reduce c, k or T"
    )]
    HistoryTooLarge {
        /// `T·|p_fast|`.
        rho_max: f64,
        /// The limit.
        limit: f64,
    },
    /// The L2 objective's Hessian has no Cholesky factor.
    #[error("the {objective} objective's Hessian is not numerically positive definite")]
    ObjectiveSingular {
        /// Objective name.
        objective: &'static str,
    },
    /// A result overflowed (inputs at the extremes of their ranges).
    #[error("the {what} is not finite for these inputs (overflow)")]
    NonFinite {
        /// What overflowed.
        what: &'static str,
    },
    /// The time budget ran out.
    #[error("time budget exhausted during {stage}")]
    Deadline {
        /// What was running.
        stage: &'static str,
    },
}

impl From<BezierMotionError> for CalcFailure {
    fn from(e: BezierMotionError) -> Self {
        let detail = e.to_string();
        match e {
            BezierMotionError::RhoTooLarge { pointer, .. } => {
                CalcFailure::field(ProblemClass::TooLarge, "RHO_TOO_LARGE", pointer, detail)
            }
            BezierMotionError::HistoryTooLarge { .. } => CalcFailure::field(
                ProblemClass::TooLarge,
                "HISTORY_TOO_LARGE",
                "/outputs/time_history/n_samples",
                detail,
            ),
            BezierMotionError::ObjectiveSingular { .. } => CalcFailure::field(
                ProblemClass::NotConverged,
                "OBJECTIVE_SINGULAR",
                "/optimize/objective",
                detail,
            ),
            BezierMotionError::NonFinite { .. } => {
                CalcFailure::general(ProblemClass::Infeasible, "NON_FINITE_RESULT", detail)
            }
            BezierMotionError::Deadline { .. } => {
                CalcFailure::general(ProblemClass::TooLarge, "DEADLINE_EXCEEDED", detail)
            }
        }
    }
}
