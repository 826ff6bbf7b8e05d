//! What both IREFC endpoints share on the input side: the validator with the IREFC codes and the
//! rules between fields that carry the spec's codes. Every per-field range (r2, Z2, χ, rb, the
//! materials, ...) is a `#[rule]` on the wire types with the spec code `BAD_RANGE`, checked at
//! the door.
//!
//! The failure's class follows its code ([`class_of`]: `GRID_TOO_FINE` and `SWEEP_TOO_LARGE` are
//! too-large), and when problems with different codes are listed together each detail starts
//! with its own code.

use super::error::{BAD_RANGE, MISSING_FIELD, class_of};
use crate::calc::rules::rule;
use crate::calc::{CrossRule, Validator};

/// A validator with the IREFC codes (`BAD_RANGE` by default, classes from [`class_of`]).
#[must_use]
pub fn validator() -> Validator {
    Validator::coded(BAD_RANGE, class_of)
}

crate::calc::rules::cross_rules! {
    /// The design is buildable: no undercut (found on the geometry).
    infeasible UNDERCUT(super::error::UNDERCUT) ["/rb_mm", "/r2_mm", "/Z2", "/chi"]
        "rb < rb_undercut(r2, Z2, χ): the cam and crown profiles have no cusp or undercut.";
    /// The rolling elements do not overlap (found on the geometry).
    infeasible ELEMENT_OVERLAP(super::error::ELEMENT_OVERLAP) ["/rb_mm", "/r2_mm", "/Z2", "/chi"]
        "rb < rb_overlap = χ·r2·sin(π/Z2): neighbouring rolling elements do not overlap.";
    /// Every reported number is finite (found while computing).
    infeasible NON_FINITE(super::error::NON_FINITE) ["/r2_mm", "/rb_mm", "/torque_Nm"]
        "Every reported number is finite in f64 (extreme scales overflow).";
    /// The work fits the time budget (found while computing).
    not_converged DEADLINE(super::error::DEADLINE) ["/time_limit_ms"]
        "The calculation ends within the request's time limit.";
}

/// Record a missing required field (`MISSING_FIELD`, a rule of `rule`).
pub fn missing(v: &mut Validator, rule: &CrossRule, pointer: &str, what: &str) {
    debug_assert_eq!(rule.code, MISSING_FIELD);
    rule!(v, rule, pointer; "{what} is required");
}

/// Z2 as a count (its range 3..=1000 is checked at the door, so the conversion is exact).
#[must_use]
pub fn z2(n: i64) -> Option<u32> {
    u32::try_from(n).ok()
}
