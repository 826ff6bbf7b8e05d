//! Errors of the cam-law module: why a 7-segment law cannot be built ([`LawError`], shared with
//! the fit) and why an evaluation cannot be answered ([`EvaluateError`]).

use super::law::EMPTY_PULSE_TOL;
use crate::calc::{CalcFailure, ProblemClass};

/// Why a 7-segment law cannot be built.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum LawError {
    /// A coefficient is NaN or infinite.
    #[error("coefficient {index} must be finite, got {value}")]
    NonFiniteCoefficient {
        /// Index 0..6.
        index: usize,
        /// Offending value.
        value: f64,
    },
    /// A coefficient is negative.
    #[error("coefficient {index} must be >= 0, got {value}")]
    NegativeCoefficient {
        /// Index 0..6.
        index: usize,
        /// Offending value.
        value: f64,
    },
    /// The first pulse (c0, c1, c2) is empty or near-empty: A1 would be infinite.
    #[error(
        "the first acceleration pulse (c0, c1, c2) is empty: normalized area {area:e} < {EMPTY_PULSE_TOL:e}"
    )]
    EmptyFirstPulse {
        /// Normalized pulse area `P/Δt`.
        area: f64,
    },
    /// The second pulse (c4, c5, c6) is empty or near-empty: A2 would be infinite.
    #[error(
        "the second acceleration pulse (c4, c5, c6) is empty: normalized area {area:e} < {EMPTY_PULSE_TOL:e}"
    )]
    EmptySecondPulse {
        /// Normalized pulse area `Q/Δt`.
        area: f64,
    },
    /// `t_b <= t_a`.
    #[error("t_b must be greater than t_a, got t_a = {t_a}, t_b = {t_b}")]
    IntervalNotIncreasing {
        /// Segment start.
        t_a: f64,
        /// Segment end.
        t_b: f64,
    },
    /// `Δt` is too small relative to `|t_a|, |t_b|` to place knots in f64.
    #[error(
        "t_b - t_a = {dt:e} is too short to resolve knots at this offset (must exceed {min:e})"
    )]
    IntervalTooShort {
        /// `t_b - t_a`.
        dt: f64,
        /// Smallest accepted value.
        min: f64,
    },
    /// A boundary value is NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NonFiniteBoundary {
        /// Field name (`t_a`, ..., `a_b`).
        name: &'static str,
        /// Offending value.
        value: f64,
    },
    /// A boundary value exceeds the accepted magnitude (spec §6 item 9).
    #[error("|{name}| must be <= {limit:e}, got {value}")]
    MagnitudeTooLarge {
        /// Field name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Accepted magnitude.
        limit: f64,
    },
    /// A derived quantity (peak acceleration, knot velocity, jerk) overflows f64.
    #[error("the law's {quantity} overflows f64 (interval too short for this rise or end rates)")]
    Overflow {
        /// Which quantity overflowed.
        quantity: &'static str,
    },
}

impl From<LawError> for CalcFailure {
    fn from(e: LawError) -> Self {
        let (class, code) = match e {
            LawError::EmptyFirstPulse { .. } | LawError::EmptySecondPulse { .. } => {
                (ProblemClass::InvalidInput, "EMPTY_PULSE")
            }
            LawError::Overflow { .. } => (ProblemClass::TooLarge, "LAW_OVERFLOW"),
            _ => (ProblemClass::InvalidInput, "INVALID_INPUT"),
        };
        Self::general(class, code, e.to_string())
    }
}

/// Why a validated `/v1/cam-law/evaluate` request cannot be answered.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum EvaluateError {
    /// The law cannot be built (e.g. its peaks overflow f64).
    #[error(transparent)]
    Law(#[from] LawError),
    /// A reported number is not finite.
    #[error(
        "the law's {name} overflow f64 for these boundary conditions (interval too short for this rise or these end rates)"
    )]
    NonFiniteResult {
        /// Which output group overflowed (`peaks`, `curves.a`, ...).
        name: &'static str,
    },
}

impl From<EvaluateError> for CalcFailure {
    fn from(e: EvaluateError) -> Self {
        match e {
            EvaluateError::Law(l) => Self::from(l),
            EvaluateError::NonFiniteResult { .. } => {
                Self::general(ProblemClass::TooLarge, "NON_FINITE_RESULT", e.to_string())
            }
        }
    }
}
