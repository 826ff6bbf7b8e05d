//! The range of a request number: a [`Range`] constant in the module's `wire.rs`, named by the
//! field's `#[rule(range = ..)]` (see [`crate::calc::rules`]), which both the check at the door
//! and the OpenAPI document read.

use std::fmt;

/// A closed, half-open or open interval of admissible values; every admissible value is finite.
///
/// Built with `const` combinators: `Range::FINITE.gt(0.0).max(1e100)` is `0 < x ≤ 1e100`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lower end (−∞ when unbounded below).
    pub lo: f64,
    /// The lower end itself is excluded.
    pub lo_open: bool,
    /// Upper end (+∞ when unbounded above).
    pub hi: f64,
    /// The upper end itself is excluded.
    pub hi_open: bool,
    /// Only whole numbers are admissible (an integer field).
    pub integer: bool,
}

impl Range {
    /// Any finite number.
    pub const FINITE: Self = Self {
        lo: f64::NEG_INFINITY,
        lo_open: false,
        hi: f64::INFINITY,
        hi_open: false,
        integer: false,
    };
    /// Any whole number.
    pub const INTEGER: Self = Self {
        integer: true,
        ..Self::FINITE
    };

    /// `x ≥ lo`.
    #[must_use]
    pub const fn min(mut self, lo: f64) -> Self {
        self.lo = lo;
        self.lo_open = false;
        self
    }

    /// `x > lo`.
    #[must_use]
    pub const fn gt(mut self, lo: f64) -> Self {
        self.lo = lo;
        self.lo_open = true;
        self
    }

    /// `x ≤ hi`.
    #[must_use]
    pub const fn max(mut self, hi: f64) -> Self {
        self.hi = hi;
        self.hi_open = false;
        self
    }

    /// `x < hi`.
    #[must_use]
    pub const fn lt(mut self, hi: f64) -> Self {
        self.hi = hi;
        self.hi_open = true;
        self
    }

    /// `lo ≤ x ≤ hi`.
    #[must_use]
    pub const fn closed(lo: f64, hi: f64) -> Self {
        Self::FINITE.min(lo).max(hi)
    }

    /// Whole numbers `lo ≤ n ≤ hi`.
    #[must_use]
    pub const fn int(lo: i64, hi: i64) -> Self {
        // Integer bounds of request fields are far below 2^53: the conversion is exact.
        Self::INTEGER.min(lo as f64).max(hi as f64)
    }

    /// Whether `x` is admissible (finite, inside, whole when the range is an integer range).
    #[must_use]
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite()
            && (if self.lo_open {
                x > self.lo
            } else {
                x >= self.lo
            })
            && (if self.hi_open {
                x < self.hi
            } else {
                x <= self.hi
            })
            && (!self.integer || x.fract() == 0.0)
    }

    /// Whether the range has a finite lower end.
    #[must_use]
    pub fn has_lo(&self) -> bool {
        self.lo.is_finite()
    }

    /// Whether the range has a finite upper end.
    #[must_use]
    pub fn has_hi(&self) -> bool {
        self.hi.is_finite()
    }
}

/// Writes a bound as people read it, e.g. `> 0 and ≤ 1e100`, `in [0, 1]`, `a finite number`.
impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = if self.integer {
            "an integer"
        } else {
            "a finite number"
        };
        match (self.has_lo(), self.has_hi()) {
            (false, false) => write!(f, "{what}"),
            (true, false) => write!(
                f,
                "{} {}",
                if self.lo_open { ">" } else { "≥" },
                num(self.lo)
            ),
            (false, true) => write!(
                f,
                "{} {}",
                if self.hi_open { "<" } else { "≤" },
                num(self.hi)
            ),
            (true, true) => write!(
                f,
                "{}in {}{}, {}{}",
                if self.integer { "an integer " } else { "" },
                if self.lo_open { '(' } else { '[' },
                num(self.lo),
                num(self.hi),
                if self.hi_open { ')' } else { ']' }
            ),
        }
    }
}

/// A number as the messages and documents print it: plain below 1e6, else in exponent form.
fn num(x: f64) -> String {
    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contains_respects_open_ends() {
        let r = Range::FINITE.gt(0.0).max(1.0);
        assert!(!r.contains(0.0));
        assert!(r.contains(1e-300));
        assert!(r.contains(1.0));
        assert!(!r.contains(1.0 + 1e-15));
        assert!(!r.contains(f64::NAN));
        assert!(!Range::FINITE.contains(f64::INFINITY));
        let n = Range::int(1, 10);
        assert!(n.contains(3.0) && !n.contains(3.5) && !n.contains(0.0));
    }

    #[test]
    fn display_reads_naturally() {
        assert_eq!(Range::FINITE.gt(0.0).to_string(), "> 0");
        assert_eq!(Range::closed(0.0, 1.0).to_string(), "in [0, 1]");
        assert_eq!(
            Range::FINITE.gt(0.0).max(1e100).to_string(),
            "in (0, 1e100]"
        );
        assert_eq!(
            Range::int(16, 100_000).to_string(),
            "an integer in [16, 100000]"
        );
        assert_eq!(Range::FINITE.to_string(), "a finite number");
    }
}
