//! Wire conventions shared by every endpoint, so a client learns them once:
//!
//! * `time_limit_ms` (top level, optional): the request's own wall-clock budget, bounded by
//!   [`TIME_LIMIT_MS`] and capped by the service's `--max-time-budget-ms`;
//! * `report` ([`SolverReport`](crate::numerics::SolverReport), schema `Report`): how the work
//!   stopped and what it cost, on every endpoint with iterative or swept work;
//! * `warnings`: a list of [`Warning`] `{code, message, pointer?}`;
//! * optional outputs are omitted when not requested, never sent as `null`.

use std::time::Duration;

use serde::Serialize;
use utoipa::ToSchema;

use super::bounds::Range;
use super::problem::Validator;

/// Bound of every request's `time_limit_ms` [ms]: from 1 ms to 10 minutes.
pub const TIME_LIMIT_MS: Range = Range::int(1, 600_000);

/// Something the caller should know about an answer that is nevertheless returned.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, ToSchema)]
pub struct Warning {
    /// Stable machine-readable code (e.g. `NEAR_SINGULAR`), from the module's spec.
    pub code: String,
    /// Human-readable explanation naming the quantity and the value.
    pub message: String,
    /// JSON pointer into the request of the field the warning is about, when it is about one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pointer: Option<String>,
}

impl Warning {
    /// A warning not tied to one request field.
    #[must_use]
    pub fn new(code: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            code: code.into(),
            message: message.into(),
            pointer: None,
        }
    }

    /// A warning about the request field at `pointer`.
    #[must_use]
    pub fn at(
        code: impl Into<String>,
        pointer: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            code: code.into(),
            message: message.into(),
            pointer: Some(pointer.into()),
        }
    }
}

/// Validates an optional top-level `time_limit_ms` and converts it.
pub fn time_limit(v: &mut Validator, time_limit_ms: Option<u64>) -> Option<Duration> {
    let ms = time_limit_ms?;
    v.uint("/time_limit_ms", "time_limit_ms", ms, TIME_LIMIT_MS)
        .then(|| Duration::from_millis(ms))
}

/// A request type with the top-level `time_limit_ms` of the wire convention; the HTTP layer reads
/// it before the job is queued, so the budget covers queueing too.
pub trait TimeLimited {
    /// The request's own time limit, if it gives one (unvalidated; out-of-range values are
    /// rejected by the module's validator and only ever shorten the budget here).
    fn time_limit(&self) -> Option<Duration>;
}
