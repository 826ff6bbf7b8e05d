//! Errors of the IREFC computations, the spec codes and the problem class of each code.

use thiserror::Error;

use super::geometry::{Infeasibility, Wheel};
use crate::calc::{CalcFailure, FieldIssue, ProblemClass};

/// A field is out of its valid range (spec code `BAD_RANGE`).
pub const BAD_RANGE: &str = "BAD_RANGE";
/// A field required by the chosen mode is missing.
pub const MISSING_FIELD: &str = "MISSING_FIELD";
/// Both `power_W` and `input_torque_Nm` were given.
pub const AMBIGUOUS_LOAD: &str = "AMBIGUOUS_LOAD";
/// 180/step_deg exceeds the grid limit.
pub const GRID_TOO_FINE: &str = "GRID_TOO_FINE";
/// The sweep has too many combinations or too much total work.
pub const SWEEP_TOO_LARGE: &str = "SWEEP_TOO_LARGE";
/// rb ≥ rb_undercut, or a cusp was met during the scan.
pub const UNDERCUT: &str = "UNDERCUT";
/// rb ≥ rb_overlap.
pub const ELEMENT_OVERLAP: &str = "ELEMENT_OVERLAP";
/// A result overflowed f64 (absurd scales, e.g. lb = 1e-300 mm).
pub const NON_FINITE: &str = "NON_FINITE";
/// The time or evaluation budget ran out before a single design was finished.
pub const DEADLINE: &str = "DEADLINE";

/// Problem class of each code.
#[must_use]
pub fn class_of(code: &str) -> ProblemClass {
    match code {
        GRID_TOO_FINE | SWEEP_TOO_LARGE => ProblemClass::TooLarge,
        UNDERCUT | ELEMENT_OVERLAP | NON_FINITE => ProblemClass::Infeasible,
        DEADLINE => ProblemClass::NotConverged,
        _ => ProblemClass::InvalidInput,
    }
}

/// Failure of an IREFC computation after validation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IrefcError {
    /// The design cannot be built (undercut and/or element overlap), undercut listed first.
    #[error("{}", .0.first().map_or_else(String::new, Infeasibility::message))]
    Infeasible(Vec<Infeasibility>),
    /// A profile cusp was met at φ2 during the scan (rb at the undercut limit within round-off).
    #[error("the {} profile has a cusp at phi2 = {phi_deg} deg (rb at the undercut limit)", wheel.name())]
    Cusp {
        /// Wheel with the cusp.
        wheel: Wheel,
        /// Element angle \[deg\].
        phi_deg: f64,
    },
    /// A result is not a finite number (inputs at absurd scales).
    #[error("{quantity} is not finite{}; the inputs are outside the scales f64 can represent", .phi_deg.map_or_else(String::new, |p| format!(" at phi2 = {p} deg")))]
    NonFinite {
        /// Offending quantity.
        quantity: &'static str,
        /// Element angle where it happened \[deg\], if tied to one.
        phi_deg: Option<f64>,
    },
    /// The budget ran out before a single design was finished.
    #[error("time budget exhausted after {evaluations} evaluations; use a coarser step_deg")]
    Deadline {
        /// Evaluations performed.
        evaluations: u64,
    },
}

impl IrefcError {
    /// Stable code.
    #[must_use]
    pub fn code(&self) -> &'static str {
        match self {
            Self::Infeasible(v) => v.first().map_or(UNDERCUT, Infeasibility::code),
            Self::Cusp { .. } => UNDERCUT,
            Self::NonFinite { .. } => NON_FINITE,
            Self::Deadline { .. } => DEADLINE,
        }
    }
}

impl From<IrefcError> for CalcFailure {
    fn from(e: IrefcError) -> Self {
        let code = e.code();
        let class = class_of(code);
        match &e {
            IrefcError::Infeasible(list) => Self {
                class,
                code,
                detail: e.to_string(),
                errors: list
                    .iter()
                    .map(|i| FieldIssue {
                        pointer: "/rb_mm".to_owned(),
                        detail: format!("{}: {}", i.code(), i.message()),
                    })
                    .collect(),
            },
            IrefcError::Cusp { .. } => Self::field(class, code, "/rb_mm", e.to_string()),
            _ => Self::general(class, code, e.to_string()),
        }
    }
}
