//! Failures of the machining-size computations. The rules between fields are checked in
//! `input.rs` (each with its own code, `MODEL_INVALID` / `UNSUPPORTED_MODEL` for model
//! documents) and returned directly as a [`CalcFailure`]; the errors here arise while computing.

use thiserror::Error;

use crate::calc::{CalcFailure, ProblemClass};

/// Code of a model document that is malformed or hostile (structure, numbers, limits).
pub const MODEL_INVALID: &str = "MODEL_INVALID";
/// Code of a model document that is well-formed but outside v1 (objective, booster, outputs).
pub const UNSUPPORTED_MODEL: &str = "UNSUPPORTED_MODEL";
/// Code of a request whose work exceeds the documented limits.
pub const TOO_LARGE: &str = "TOO_LARGE";
/// Code of a SMOGN relevance that marks every sample rare, or none.
pub const SMOGN_DEGENERATE_RELEVANCE: &str = "SMOGN_DEGENERATE_RELEVANCE";
/// Code of a GRA series that cannot be normalised by its mean.
pub const GRA_ZERO_MEAN: &str = "GRA_ZERO_MEAN";
/// Code of a spent budget before an answer that cannot be partial.
pub const DEADLINE_EXCEEDED: &str = "DEADLINE_EXCEEDED";

/// Error of the module's `compute` functions.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MachiningSizeError {
    /// SMOGN's relevance marks every sample rare, or none (spec §8 hazard 6).
    #[error(
        "SMOGN relevance marks {rare} of {n} samples as rare: it needs both rare and normal \
         samples (adjust the control points or the threshold)"
    )]
    SmognDegenerate {
        /// Rare samples.
        rare: usize,
        /// Samples.
        n: usize,
        /// Pointer of the SMOGN options.
        pointer: &'static str,
    },
    /// GRA normalisation by a zero mean (spec §8 hazard 7).
    #[error(
        "grey relational analysis: `{series}` has a mean of 0 (or too small against its values) \
         and cannot be normalised by it; use normalise \"none\""
    )]
    GraZeroMean {
        /// The series (feature name or `target`).
        series: String,
    },
    /// The time budget ran out before an answer that cannot be partial (SHAP, analysis).
    #[error("time budget exhausted during {stage} after {done} of {total} items")]
    Deadline {
        /// What was running.
        stage: &'static str,
        /// Items finished.
        done: u64,
        /// Items in all.
        total: u64,
    },
}

impl From<MachiningSizeError> for CalcFailure {
    fn from(e: MachiningSizeError) -> Self {
        let detail = e.to_string();
        match e {
            MachiningSizeError::SmognDegenerate { pointer, .. } => CalcFailure::field(
                ProblemClass::Infeasible,
                SMOGN_DEGENERATE_RELEVANCE,
                format!("{pointer}/relevance"),
                detail,
            ),
            MachiningSizeError::GraZeroMean { .. } => CalcFailure::field(
                ProblemClass::Infeasible,
                GRA_ZERO_MEAN,
                "/gra/normalise",
                detail,
            ),
            MachiningSizeError::Deadline { .. } => {
                CalcFailure::general(ProblemClass::TooLarge, DEADLINE_EXCEEDED, detail)
            }
        }
    }
}
