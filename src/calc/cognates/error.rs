//! Failures of the cognates computation (spec §3 rejections). Field-level validation problems are
//! collected in `input.rs` and returned directly as a [`CalcFailure`]; the errors here arise from
//! the linkage as a whole.

use thiserror::Error;

use crate::calc::{CalcFailure, ProblemClass};

/// A length is not positive (or a coordinate/angle not finite), or is zero next to the largest
/// length (spec §3).
pub const NON_POSITIVE_LENGTH: &str = "NON_POSITIVE_LENGTH";
/// The ground pivots coincide: |B − A| ≤ 1e-12·L (spec §3).
pub const COINCIDENT_PIVOTS: &str = "COINCIDENT_PIVOTS";
/// The coupler triangle (b, d, e) violates the triangle inequality (spec §3).
pub const COUPLER_TRIANGLE_INVALID: &str = "COUPLER_TRIANGLE_INVALID";
/// The coupler point P sits on a coupler joint: |k| or |1 − k| ≤ 1e-9 (spec §3).
pub const COUPLER_POINT_AT_JOINT: &str = "COUPLER_POINT_AT_JOINT";

/// Error of [`super::compute::compute`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CognatesError {
    /// The longest of (l, a, b, c) is not shorter than the sum of the other three: no input angle
    /// assembles a movable linkage.
    #[error(
        "not assemblable: the longest link ({longest_name} = {longest}) must be shorter than the sum of the \
         other three ({others}); no input angle works"
    )]
    NotAssemblable {
        /// Name of the longest link.
        longest_name: &'static str,
        /// Its length [input unit].
        longest: f64,
        /// Sum of the other three [input unit].
        others: f64,
    },
    /// The requested curves exceed the server's point cap.
    #[error(
        "too many curve points: {requested} (3 mechanisms × circuits × points_per_circuit) exceed the cap {cap}"
    )]
    TooManyPoints {
        /// Points the request would produce.
        requested: u64,
        /// Server cap.
        cap: u64,
    },
    /// The time budget ran out during sampling or verification.
    #[error("time budget exhausted during {stage} after {samples} samples")]
    Deadline {
        /// What was running.
        stage: &'static str,
        /// Samples done.
        samples: u64,
    },
}

impl From<CognatesError> for CalcFailure {
    fn from(e: CognatesError) -> Self {
        let detail = e.to_string();
        match e {
            CognatesError::NotAssemblable { .. } => {
                CalcFailure::general(ProblemClass::Infeasible, "NOT_ASSEMBLABLE", detail)
            }
            CognatesError::TooManyPoints { .. } => CalcFailure::field(
                ProblemClass::TooLarge,
                "TOO_MANY_POINTS",
                "/options/points_per_circuit",
                detail,
            ),
            CognatesError::Deadline { .. } => {
                CalcFailure::general(ProblemClass::TooLarge, "DEADLINE_EXCEEDED", detail)
            }
        }
    }
}
