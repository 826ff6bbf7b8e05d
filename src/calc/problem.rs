//! Failures of a calculation in a transport-neutral form.
//!
//! Every module's error type converts into a [`CalcFailure`]; the HTTP layer turns that into an
//! RFC 9457 `application/problem+json` body. Input validation collects *every* offending field
//! with a [`Validator`] instead of stopping at the first.

use std::fmt::Display;

use super::bounds::Range;
use super::rules::CrossRule;

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

/// The code of a validation failure that has no more specific code of its module.
pub const INVALID_INPUT: &str = "INVALID_INPUT";

/// Collects every validation problem of a request, then fails once with all of them: the one
/// validator of the crate, so that messages, codes and pointers come from one place.
///
/// Each problem carries a JSON pointer, a message naming the quantity, the value and the broken
/// limit, and a code (`INVALID_INPUT` unless the module's spec names another, e.g.
/// `NON_POSITIVE_LENGTH`). Range checks take a [`Range`] constant: the same constant the module's
/// field's `#[rule]` writes into the OpenAPI document.
///
/// ```
/// use mechcalc::calc::{Range, Validator};
/// let mut v = Validator::new();
/// v.finite("/x", f64::NAN);
/// v.range("/n", "n", 3.0, Range::int(8, 200_000));
/// let err = v.finish().unwrap_err();
/// assert_eq!(err.errors.len(), 2);
/// assert_eq!(err.errors[1].detail, "n must be an integer in [8, 200000], got 3");
/// ```
#[derive(Debug)]
pub struct Validator {
    issues: Vec<(&'static str, Option<ProblemClass>, FieldIssue)>,
    /// The code of the plain checks (`push`, `ensure`, `finite`, `all_in`, `range`, `uint`).
    code: &'static str,
    /// The failure's class from its code; `None`: always [`ProblemClass::InvalidInput`].
    class_of: Option<fn(&str) -> ProblemClass>,
}

impl Default for Validator {
    fn default() -> Self {
        Self::new()
    }
}

impl Validator {
    /// An empty validator: plain checks record `INVALID_INPUT`, the failure is `InvalidInput`.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            issues: Vec::new(),
            code: INVALID_INPUT,
            class_of: None,
        }
    }

    /// An empty validator for a module whose spec gives validation problems its own codes:
    /// the plain checks (`push`, `ensure`, `finite`, `all_in`, `range`, `uint`) record `code`
    /// (e.g. IREFC's `BAD_RANGE`), the failure's class follows its code (`class_of`, e.g. a size
    /// limit is [`ProblemClass::TooLarge`]), and when problems with different codes are listed
    /// together each detail starts with its own code (`"MISSING_FIELD: r2_mm is required"`), so
    /// a client still sees every problem's code.
    ///
    /// ```
    /// use mechcalc::calc::{ProblemClass, Range, Validator};
    /// let class = |c: &str| if c == "TOO_FINE" { ProblemClass::TooLarge } else { ProblemClass::InvalidInput };
    /// let mut v = Validator::coded("BAD_RANGE", class);
    /// v.range("/step", "step", 0.0, Range::FINITE.gt(0.0));
    /// v.push_code("TOO_FINE", "/n", "n is too fine");
    /// let err = v.finish().unwrap_err();
    /// assert_eq!((err.code, err.class), ("BAD_RANGE", ProblemClass::InvalidInput));
    /// assert_eq!(err.errors[0].detail, "BAD_RANGE: step must be > 0, got 0");
    /// ```
    #[must_use]
    pub const fn coded(code: &'static str, class_of: fn(&str) -> ProblemClass) -> Self {
        Self {
            issues: Vec::new(),
            code,
            class_of: Some(class_of),
        }
    }

    /// Record a problem at `pointer` with the validator's code (`INVALID_INPUT` unless
    /// [`Validator::coded`] named another).
    pub fn push(&mut self, pointer: impl Into<String>, detail: impl Into<String>) {
        self.push_code(self.code, pointer, detail);
    }

    /// Record a problem at `pointer` with a module-specific code.
    pub fn push_code(
        &mut self,
        code: &'static str,
        pointer: impl Into<String>,
        detail: impl Into<String>,
    ) {
        self.issues.push((
            code,
            None,
            FieldIssue {
                pointer: pointer.into(),
                detail: detail.into(),
            },
        ));
    }

    /// Record a failure of a rule between fields ([`CrossRule`]) at `pointer`: its code, its class.
    pub fn rule(
        &mut self,
        rule: &CrossRule,
        pointer: impl Into<String>,
        detail: impl Into<String>,
    ) {
        self.issues.push((
            rule.code,
            Some(rule.class),
            FieldIssue {
                pointer: pointer.into(),
                detail: detail.into(),
            },
        ));
    }

    /// Record a failure of `rule` at `pointer` unless `ok`; returns `ok`.
    pub fn ensure_rule(
        &mut self,
        ok: bool,
        rule: &CrossRule,
        pointer: impl Into<String>,
        detail: impl FnOnce() -> String,
    ) -> bool {
        if !ok {
            self.rule(rule, pointer, detail());
        }
        ok
    }

    /// Record a problem at `pointer` unless `ok`; returns `ok`.
    pub fn ensure(
        &mut self,
        ok: bool,
        pointer: impl Into<String>,
        detail: impl FnOnce() -> String,
    ) -> bool {
        if !ok {
            self.push(pointer, detail());
        }
        ok
    }

    /// Like [`Validator::ensure`], with a module-specific code.
    pub fn ensure_code(
        &mut self,
        ok: bool,
        code: &'static str,
        pointer: impl Into<String>,
        detail: impl FnOnce() -> String,
    ) -> bool {
        if !ok {
            self.push_code(code, pointer, detail());
        }
        ok
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
        self.all_in(pointer, "", values, Range::FINITE)
    }

    /// Require every element of a slice to lie in `range` (reports the first offending index
    /// only, with a count).
    pub fn all_in(&mut self, pointer: &str, name: &str, values: &[f64], range: Range) -> bool {
        let mut bad = values
            .iter()
            .enumerate()
            .filter(|(_, v)| !range.contains(**v));
        if let Some((i, v)) = bad.next() {
            let more = bad.count();
            let tail = if more > 0 {
                format!(" ({more} more values out of range follow)")
            } else {
                String::new()
            };
            let name = if name.is_empty() {
                String::new()
            } else {
                format!("{name}[{i}] ")
            };
            self.push(
                format!("{pointer}/{i}"),
                format!("{name}must be {range}, got {v}{tail}"),
            );
            false
        } else {
            true
        }
    }

    /// Require `value` in `range` (finite, and whole for an integer range), with the validator's
    /// code (`INVALID_INPUT` unless [`Validator::coded`] named another).
    /// `name` (may be empty) starts the message: `"a must be > 0, got -1"`.
    pub fn range(&mut self, pointer: &str, name: &str, value: f64, range: Range) -> bool {
        self.range_code(self.code, pointer, name, value, range)
    }

    /// Like [`Validator::range`], with a module-specific code.
    pub fn range_code(
        &mut self,
        code: &'static str,
        pointer: &str,
        name: &str,
        value: f64,
        range: Range,
    ) -> bool {
        let ok = range.contains(value);
        if !ok {
            let sep = if name.is_empty() { "" } else { " " };
            self.push_code(
                code,
                pointer,
                format!("{name}{sep}must be {range}, got {value}"),
            );
        }
        ok
    }

    /// Require an unsigned integer in `range`.
    pub fn uint(&mut self, pointer: &str, name: &str, value: u64, range: Range) -> bool {
        // Request integers beyond 2^53 are far outside every range; the rounding cannot admit one.
        let x = value as f64;
        self.range(pointer, name, x, range)
    }

    /// Require `lo <= value <= hi` (and finite).
    pub fn in_range(&mut self, pointer: &str, value: f64, lo: f64, hi: f64) -> bool {
        self.range(pointer, "", value, Range::closed(lo, hi))
    }

    /// Require `value > lo` (and finite).
    pub fn greater_than(&mut self, pointer: &str, value: f64, lo: f64) -> bool {
        self.range(pointer, "", value, Range::FINITE.gt(lo))
    }

    /// Whether no problem has been recorded so far.
    #[must_use]
    pub fn is_clean(&self) -> bool {
        self.issues.is_empty()
    }

    /// The problems recorded so far.
    pub fn issues(&self) -> impl Iterator<Item = &FieldIssue> {
        self.issues.iter().map(|(_, _, i)| i)
    }

    /// Move every problem of `other` into this validator.
    pub fn absorb(&mut self, other: Self) {
        self.issues.extend(other.issues);
    }

    /// Fail now with every problem recorded so far (exactly as [`Validator::finish`] would), else
    /// go on collecting: for checks that need the fields checked so far to be valid.
    pub fn checkpoint(&mut self) -> Result<(), CalcFailure> {
        let so_far = Self {
            issues: std::mem::take(&mut self.issues),
            code: self.code,
            class_of: self.class_of,
        };
        so_far.finish()
    }

    /// `Ok(())` when no problem was recorded, else one failure listing all of them. Its code is
    /// the code shared by all problems, else the first problem's code; its class is
    /// [`ProblemClass::InvalidInput`] (or, for a [`Validator::coded`] validator, the class of
    /// that code).
    pub fn finish(self) -> Result<(), CalcFailure> {
        let Some(&(code, class, _)) = self.issues.first() else {
            return Ok(());
        };
        let n = self.issues.len();
        let detail = if n == 1 {
            format!("{} {}", self.issues[0].2.pointer, self.issues[0].2.detail)
        } else {
            format!("{n} fields failed validation")
        };
        let tag = self.issues.iter().any(|(c, _, _)| *c != code);
        Err(CalcFailure {
            class: class.unwrap_or_else(|| {
                self.class_of
                    .map_or(ProblemClass::InvalidInput, |f| f(code))
            }),
            code,
            detail,
            errors: self
                .issues
                .into_iter()
                .map(|(c, _, mut issue)| {
                    if tag {
                        issue.detail = format!("{c}: {}", issue.detail);
                    }
                    issue
                })
                .collect(),
        })
    }
}
