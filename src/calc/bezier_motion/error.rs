//! Failures of the Bezier-motion computation that depend on derived quantities (the request's
//! rules are checked at the door: `wire.rs`, `input.rs`), each a [`CrossRule`] listed under the
//! operation's `x-cross-field-rules`.

use thiserror::Error;

use crate::calc::{CalcFailure, CrossRule};

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

/// The drive's fastest pole stays within the Gauss–Legendre path's limit (`RHO_TOO_LARGE`).
pub const RHO_TOO_LARGE_RULE: CrossRule = CrossRule::too_large(
    "RHO_TOO_LARGE",
    &[
        "/system/c_Nms_per_rad",
        "/optimize/robust_stiffness_rel",
        "/outputs/sensitivity/stiffness_factors/*",
    ],
    "When the end state needs the Gauss–Legendre path, rho_max = T·|fastest pole| ≤ 2e5 (for the \
     nominal drive, the robust k·(1±δ) and every sensitivity factor k·f).",
);

/// A time history fits the sub-step budget (`HISTORY_TOO_LARGE`).
pub const HISTORY_TOO_LARGE_RULE: CrossRule = CrossRule::too_large(
    "HISTORY_TOO_LARGE",
    &["/outputs/time_history/n_samples"],
    "A time history is asked for only when rho_max = T·|fastest pole| ≤ 1.6e6 (sub-step budget).",
);

/// The L2 objective's Hessian has a Cholesky factor (`OBJECTIVE_SINGULAR`).
pub const OBJECTIVE_SINGULAR_RULE: CrossRule = CrossRule::not_converged(
    "OBJECTIVE_SINGULAR",
    &["/optimize/objective"],
    "The min_accel_l2 / min_jerk_l2 objective's Hessian is numerically positive definite.",
);

/// Every result is finite (`NON_FINITE_RESULT`).
pub const NON_FINITE_RESULT_RULE: CrossRule = CrossRule::infeasible(
    "NON_FINITE_RESULT",
    &["/system", "/outputs/sensitivity/stiffness_factors/*"],
    "Every computed quantity is finite in f64 (inputs at the extremes of their ranges, or a \
     stiffness factor whose k·f underflows to 0, can overflow).",
);

/// The work fits the request's time budget (`DEADLINE_EXCEEDED`).
pub const DEADLINE_RULE: CrossRule = CrossRule::too_large(
    "DEADLINE_EXCEEDED",
    &["/time_limit_ms"],
    "The computation finishes within the request's time budget.",
);

impl From<BezierMotionError> for CalcFailure {
    fn from(e: BezierMotionError) -> Self {
        let detail = e.to_string();
        match e {
            BezierMotionError::RhoTooLarge { pointer, .. } => {
                RHO_TOO_LARGE_RULE.fail(pointer, detail)
            }
            BezierMotionError::HistoryTooLarge { .. } => {
                HISTORY_TOO_LARGE_RULE.fail("/outputs/time_history/n_samples", detail)
            }
            BezierMotionError::ObjectiveSingular { .. } => {
                OBJECTIVE_SINGULAR_RULE.fail("/optimize/objective", detail)
            }
            BezierMotionError::NonFinite { .. } => NON_FINITE_RESULT_RULE.fail_general(detail),
            BezierMotionError::Deadline { .. } => DEADLINE_RULE.fail_general(detail),
        }
    }
}
