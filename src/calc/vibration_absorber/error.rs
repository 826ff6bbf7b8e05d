//! Failures of the vibration-absorber computation. Field problems are collected in `input.rs`;
//! these arise from the model as a whole.

use thiserror::Error;

use crate::calc::{CalcFailure, CrossRule};

/// Error of [`super::compute::compute`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum VibrationAbsorberError {
    /// A matrix exponential or the response overflowed (an unstable design over a long horizon,
    /// or extreme unit scales): no finite answer exists in double precision.
    #[error("the {stage} is not finite in double precision ({detail})")]
    NonFinite {
        /// What was being computed.
        stage: &'static str,
        /// Why.
        detail: String,
    },
    /// The QR iteration for the eigenvalues did not converge.
    #[error("eigenvalues of the {size}×{size} state matrix did not converge")]
    EigenNotConverged {
        /// State size.
        size: usize,
    },
    /// The time budget ran out.
    #[error("time budget exhausted during the {stage} after {done} of {total} steps")]
    Deadline {
        /// What was running.
        stage: &'static str,
        /// Steps done.
        done: u64,
        /// Steps asked.
        total: u64,
    },
}

/// The response stays finite in double precision.
pub const NON_FINITE_RULE: CrossRule = CrossRule::infeasible(
    "NON_FINITE_RESPONSE",
    &[
        "/beam",
        "/absorber",
        "/actuator",
        "/control",
        "/outputs/time_response/t_end_s",
    ],
    "The model's matrices, exponentials and responses stay finite in double precision (an \
     unstable design over a long horizon or extreme unit scales overflow).",
);
/// The eigenvalue iteration converges.
pub const EIGEN_NOT_CONVERGED_RULE: CrossRule = CrossRule::not_converged(
    "EIGEN_NOT_CONVERGED",
    &["/outputs/eigenvalues"],
    "The QR iteration for the eigenvalues of the coupled state matrix converges.",
);
/// The work finishes within the request's time budget.
pub const DEADLINE_RULE: CrossRule = CrossRule::too_large(
    "DEADLINE_EXCEEDED",
    &["/time_limit_ms"],
    "The analyses finish within the request's time_limit_ms (capped by the service).",
);

impl From<VibrationAbsorberError> for CalcFailure {
    fn from(e: VibrationAbsorberError) -> Self {
        let detail = e.to_string();
        match e {
            VibrationAbsorberError::NonFinite { .. } => NON_FINITE_RULE.fail_general(detail),
            VibrationAbsorberError::EigenNotConverged { .. } => {
                EIGEN_NOT_CONVERGED_RULE.fail_general(detail)
            }
            VibrationAbsorberError::Deadline { .. } => DEADLINE_RULE.fail_general(detail),
        }
    }
}
