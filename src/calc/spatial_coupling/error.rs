//! Failures of the spatial-coupling computation. Field-level validation problems are collected
//! in `input.rs`; the errors here concern the configuration as a whole or the budget.

use thiserror::Error;

use crate::calc::{CalcFailure, ProblemClass};

/// Error of [`super::compute::compute`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SpatialCouplingError {
    /// A sweep was requested with a support plane that fails the validity test (spec §2, §7.2):
    /// the contact point B goes to infinity where D(θ1) = 0.
    #[error(
        "support plane invalid for a sweep: cos(α−β)·cos 2α·cos(α+β) must be > 0 (B finite at every \
         θ1), got D(0) = cos(α−β)·cos 2α = {d0:e} and D(90°) = cos(α+β) = {d90:e}, min|D|/max|D| = \
         {min_over_max:e}; D = 0 (to round-off) at θ1 = {roots:?}° (B at infinity). Choose β with \
         the same sign of D(0) and D(90°), or ask for single points (theta1_deg) only"
    )]
    SupportPlaneInvalid {
        /// D(0).
        d0: f64,
        /// D(90°).
        d90: f64,
        /// min|D|/max|D| over a revolution.
        min_over_max: f64,
        /// Input angles in [0°, 360°) where D = 0.
        roots: Vec<f64>,
    },
    /// The time budget ran out during the evaluation.
    #[error("time budget exhausted after {points} of {total} points")]
    Deadline {
        /// Points evaluated.
        points: u64,
        /// Points requested.
        total: u64,
    },
}

impl From<SpatialCouplingError> for CalcFailure {
    fn from(e: SpatialCouplingError) -> Self {
        let detail = e.to_string();
        match e {
            SpatialCouplingError::SupportPlaneInvalid { .. } => CalcFailure::field(
                ProblemClass::Infeasible,
                "SUPPORT_PLANE_INVALID",
                "/beta_deg",
                detail,
            ),
            SpatialCouplingError::Deadline { .. } => {
                CalcFailure::general(ProblemClass::TooLarge, "DEADLINE_EXCEEDED", detail)
            }
        }
    }
}
