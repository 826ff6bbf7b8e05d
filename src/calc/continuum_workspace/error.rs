//! Failures of the computation that are not validation problems.

use crate::calc::{CalcFailure, ProblemClass};

/// Code of an assembly mode index beyond the modes the search found.
pub const ASSEMBLY_MODE_NOT_FOUND: &str = "ASSEMBLY_MODE_NOT_FOUND";

/// Errors of [`super::compute::compute`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ContinuumError {
    /// The assembly-mode search returned fewer solutions than the requested index.
    #[error(
        "assembly mode {index} was requested but the (non-certified) search found {found} solution(s)"
    )]
    AssemblyModeNotFound {
        /// Requested index.
        index: usize,
        /// Solutions found.
        found: usize,
        /// JSON pointer of the index field.
        pointer: &'static str,
    },
}

impl From<ContinuumError> for CalcFailure {
    fn from(e: ContinuumError) -> Self {
        match &e {
            ContinuumError::AssemblyModeNotFound { pointer, .. } => CalcFailure::field(
                ProblemClass::NotConverged,
                ASSEMBLY_MODE_NOT_FOUND,
                *pointer,
                format!("{e}; raise assembly_modes.n_grid or tol, or pick a lower index"),
            ),
        }
    }
}
