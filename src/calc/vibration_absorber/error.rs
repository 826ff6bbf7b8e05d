//! Failures of the vibration-absorber computation. Field problems are collected in `input.rs`;
//! these arise from the model as a whole.

use thiserror::Error;

use crate::calc::{CalcFailure, ProblemClass};

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

impl From<VibrationAbsorberError> for CalcFailure {
    fn from(e: VibrationAbsorberError) -> Self {
        let detail = e.to_string();
        match e {
            VibrationAbsorberError::NonFinite { .. } => {
                CalcFailure::general(ProblemClass::Infeasible, "NON_FINITE_RESPONSE", detail)
            }
            VibrationAbsorberError::EigenNotConverged { .. } => {
                CalcFailure::general(ProblemClass::NotConverged, "EIGEN_NOT_CONVERGED", detail)
            }
            VibrationAbsorberError::Deadline { .. } => {
                CalcFailure::general(ProblemClass::TooLarge, "DEADLINE_EXCEEDED", detail)
            }
        }
    }
}
