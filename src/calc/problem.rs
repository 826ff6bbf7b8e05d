//! Failures of a calculation in a transport-neutral form.
//!
//! Every module's error type converts into a [`CalcFailure`]; the HTTP layer turns that into an
//! RFC 9457 `application/problem+json` body. Input validation collects *every* offending field
//! with a [`Validator`] instead of stopping at the first.

use std::fmt::Display;

/// One offending input field: an RFC 6901 JSON pointer into the request body and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldIssue {
    /// JSON pointer into the request body, e.g. `/constraints/t_b`.
    pub pointer: String,
    /// What is wrong, naming the quantity, value and the limit it breaks.
    pub detail: String,
}

/// The class of failure; each class has its own stable problem `type` on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProblemClass {
    /// A field is out of range, inconsistent or malformed (HTTP 422).
    InvalidInput,
    /// The input is well-formed but describes something that cannot exist or be built (HTTP 422).
    Infeasible,
    /// An iterative method did not reach its tolerance (HTTP 422).
    NotConverged,
    /// The requested work exceeds the service's limits (HTTP 422).
    TooLarge,
}

/// A failed calculation: class, stable machine-readable code, human detail and offending fields.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CalcFailure {
    /// Failure class.
    pub class: ProblemClass,
    /// Stable code clients can branch on (e.g. `INVALID_INPUT`, `UNDERCUT`).
    pub code: &'static str,
    /// One-sentence summary.
    pub detail: String,
    /// Offending fields (may be empty for failures that are not tied to one field).
    pub errors: Vec<FieldIssue>,
}

impl CalcFailure {
    /// A failure tied to one field.
    pub fn field(
        class: ProblemClass,
        code: &'static str,
        pointer: impl Into<String>,
        detail: impl Into<String>,
    ) -> Self {
        let detail = detail.into();
        Self {
            class,
            code,
            detail: detail.clone(),
            errors: vec![FieldIssue {
                pointer: pointer.into(),
                detail,
            }],
        }
    }

    /// A failure of the whole request, not tied to one field.
    pub fn general(class: ProblemClass, code: &'static str, detail: impl Into<String>) -> Self {
        Self {
            class,
            code,
            detail: detail.into(),
            errors: Vec::new(),
        }
    }
}

impl Display for CalcFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.code, self.detail)?;
        for e in &self.errors {
            write!(f, "; {} {}", e.pointer, e.detail)?;
        }
        Ok(())
    }
}

impl std::error::Error for CalcFailure {}

/// Collects every validation problem of a request, then fails once with all of them.
///
/// ```
/// use mechcalc::calc::Validator;
/// let mut v = Validator::new();
/// v.finite("/x", f64::NAN);
/// v.in_range("/n", 3.0, 8.0, 200_000.0);
/// let err = v.finish().unwrap_err();
/// assert_eq!(err.errors.len(), 2);
/// ```
#[derive(Debug, Default)]
pub struct Validator {
    issues: Vec<FieldIssue>,
}

impl Validator {
    /// An empty validator.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Record a problem at `pointer`.
    pub fn push(&mut self, pointer: impl Into<String>, detail: impl Into<String>) {
        self.issues.push(FieldIssue {
            pointer: pointer.into(),
            detail: detail.into(),
        });
    }

    /// Record a problem at `pointer` unless `ok`.
    pub fn ensure(
        &mut self,
        ok: bool,
        pointer: impl Into<String>,
        detail: impl FnOnce() -> String,
    ) {
        if !ok {
            self.push(pointer, detail());
        }
    }

    /// Require a finite number; returns whether it was.
    pub fn finite(&mut self, pointer: &str, value: f64) -> bool {
        let ok = value.is_finite();
        if !ok {
            self.push(pointer, format!("must be a finite number, got {value}"));
        }
        ok
    }

    /// Require every element of a slice to be finite (reports the first offending index only,
    /// with a count, so a 200 000-sample array cannot produce 200 000 errors).
    pub fn all_finite(&mut self, pointer: &str, values: &[f64]) -> bool {
        let mut bad = values.iter().enumerate().filter(|(_, v)| !v.is_finite());
        if let Some((i, v)) = bad.next() {
            let more = bad.count();
            let tail = if more > 0 {
                format!(" ({more} more non-finite values follow)")
            } else {
                String::new()
            };
            self.push(
                format!("{pointer}/{i}"),
                format!("must be a finite number, got {v}{tail}"),
            );
            false
        } else {
            true
        }
    }

    /// Require `lo <= value <= hi` (and finite).
    pub fn in_range(&mut self, pointer: &str, value: f64, lo: f64, hi: f64) -> bool {
        if !self.finite(pointer, value) {
            return false;
        }
        let ok = (lo..=hi).contains(&value);
        if !ok {
            self.push(pointer, format!("must be in [{lo}, {hi}], got {value}"));
        }
        ok
    }

    /// Require `value > lo` (and finite).
    pub fn greater_than(&mut self, pointer: &str, value: f64, lo: f64) -> bool {
        if !self.finite(pointer, value) {
            return false;
        }
        let ok = value > lo;
        if !ok {
            self.push(pointer, format!("must be > {lo}, got {value}"));
        }
        ok
    }

    /// Whether no problem has been recorded so far.
    #[must_use]
    pub fn is_clean(&self) -> bool {
        self.issues.is_empty()
    }

    /// `Ok(())` when no problem was recorded, else one [`ProblemClass::InvalidInput`] failure
    /// listing all of them.
    pub fn finish(self) -> Result<(), CalcFailure> {
        if self.issues.is_empty() {
            return Ok(());
        }
        let n = self.issues.len();
        let detail = if n == 1 {
            format!("{} {}", self.issues[0].pointer, self.issues[0].detail)
        } else {
            format!("{n} fields failed validation")
        };
        Err(CalcFailure {
            class: ProblemClass::InvalidInput,
            code: "INVALID_INPUT",
            detail,
            errors: self.issues,
        })
    }
}
