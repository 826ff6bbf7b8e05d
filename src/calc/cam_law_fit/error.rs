//! Errors of the fit computation (validation errors are collected in `input.rs`).

use crate::calc::cam_law::law::LawError;
use crate::calc::{CalcFailure, ProblemClass};

/// Why a validated fit could not produce a response.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The fitted (or initial) law could not be built: the boundary conditions overflow f64 for
    /// every candidate the optimizer reached.
    #[error("the fitted law cannot be represented in f64: {source}")]
    Law {
        /// The evaluator's reason.
        #[from]
        source: LawError,
    },
    /// A reported number is not finite (values too large for f64 after the fit).
    #[error("the fitted law's {quantity} is not finite: rescale the units of the data")]
    NonFinite {
        /// Which output overflowed.
        quantity: &'static str,
    },
}

impl From<FitError> for CalcFailure {
    fn from(e: FitError) -> Self {
        match e {
            FitError::Law { source } => {
                let mut f = Self::from(source);
                f.detail = format!("the fitted law cannot be represented in f64: {}", f.detail);
                f
            }
            FitError::NonFinite { .. } => {
                Self::general(ProblemClass::TooLarge, "RESULT_OVERFLOW", e.to_string())
            }
        }
    }
}
