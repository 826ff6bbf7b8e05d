//! Validation shared by both IREFC endpoints: the four initial parameters (r2, Z2, χ, rb) and the
//! materials, checked against the bounds of [`super::wire`] with the crate's one
//! [`Validator`].
//!
//! Every range problem has the spec code `BAD_RANGE`; the failure's class follows its code
//! ([`class_of`]: `GRID_TOO_FINE` and `SWEEP_TOO_LARGE` are too-large), and when problems with
//! different codes are listed together each detail starts with its own code.

use super::error::{BAD_RANGE, MISSING_FIELD, class_of};
use super::wire::{CHI, E_MPA, Material, NU, R2_MM, RB_MM, Z2};
use crate::calc::Validator;

/// A validator with the IREFC codes (`BAD_RANGE` for range problems, classes from [`class_of`]).
#[must_use]
pub fn validator() -> Validator {
    Validator::coded(BAD_RANGE, class_of)
}

/// Validate r2 (mm) at `pointer`; returns it when valid.
pub fn r2(v: &mut Validator, pointer: &str, x: f64) -> Option<f64> {
    v.range(pointer, "cage pitch radius r2_mm", x, R2_MM)
        .then_some(x)
}

/// Validate Z2 at `pointer`; returns it when valid.
pub fn z2(v: &mut Validator, pointer: &str, n: i64) -> Option<u32> {
    // Every i64 converts to a whole f64; values beyond 2^53 are far outside the range either way.
    let ok = v.range(pointer, "number of rolling elements Z2", n as f64, Z2);
    ok.then(|| u32::try_from(n).ok()).flatten()
}

/// Validate χ at `pointer`; returns it when valid.
pub fn chi(v: &mut Validator, pointer: &str, x: f64) -> Option<f64> {
    v.range(pointer, "displacement coefficient chi", x, CHI)
        .then_some(x)
}

/// Validate rb (mm) at `pointer` (buildability is checked on the geometry); returns it when valid.
pub fn rb(v: &mut Validator, pointer: &str, x: f64) -> Option<f64> {
    v.range(pointer, "rolling element radius rb_mm", x, RB_MM)
        .then_some(x)
}

/// Validate E and ν of a material under `pointer`.
pub fn material(v: &mut Validator, pointer: &str, m: &Material) {
    v.range(
        &format!("{pointer}/E_MPa"),
        "Young's modulus E_MPa",
        m.e_mpa,
        E_MPA,
    );
    v.range(&format!("{pointer}/nu"), "Poisson's ratio nu", m.nu, NU);
}

/// Record a missing required field (`MISSING_FIELD`).
pub fn missing(v: &mut Validator, pointer: &str, what: &str) {
    v.push_code(MISSING_FIELD, pointer, format!("{what} is required"));
}
