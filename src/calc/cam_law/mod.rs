//! Cam motion laws: the general 7-segment modified-trapezoidal law with arbitrary end rates
//! (Tiboni, Amici, Bussola, "Cam Mechanisms Reverse Engineering Based on Evolutionary Algorithms",
//! Electronics 2021, 10, 3073, Appendix A), the classic laws of the spec's Appendix A, and the
//! `/v1/cam-law/evaluate` computation. Spec: `shared/specs/cam_law_fit.md` (§3.2, §4, §8b,
//! Appendix A; errata of §3.7 applied).
//!
//! * [`law`]: [`law::SevenSegmentLaw`] — `A1, A2` by the impulse/centroid form, knots, exact
//!   peaks and acceleration jumps, allocation-free evaluation over a sample grid (the fit's
//!   inner loop).
//! * [`catalogue`]: the Appendix-A laws in closed form ([`catalogue::NamedLaw`]), their peak
//!   factors, and the Table-3 vectors ([`catalogue::TABLE3`], [`catalogue::nearest`]).
//! * [`wire`] → [`input`] → [`compute`](mod@compute) → [`output`] (errors in [`error`]): the evaluate
//!   endpoint; the HTTP layer calls [`run`].
//!
//! # Validity and accuracy
//!
//! * Input range: boundary values finite with magnitude ≤ 1e12 (spec §6 item 9),
//!   `t_b − t_a > 1e-12·max(|t_a|, |t_b|)`, coefficients ≥ 0 with both pulses of normalized area
//!   ≥ 1e-9. Normalized coefficients below 1e-15 are treated as exactly zero (shorter than the
//!   knot rounding). Up to 200 000 abscissae per evaluate request.
//! * Accuracy: every quantity is evaluated in closed form relative to its segment start; the
//!   boundary conditions hold to ~1e-15 relative to the law's scale (plus the rounding of the
//!   abscissa, ulp(max(|t_a|, |t_b|)) × slope, when `t_a` is far from 0). The spec's golden
//!   values (§5.2, printed to 10 decimals) are met to their printed precision (≤ 5e-11 absolute
//!   on s, v, a; ≤ 3.1e-10 relative on jerk); the class members of Appendix A match their
//!   closed forms to 6e-16 (scaled); Cramer and centroid forms of `A1, A2` agree to 1e-12
//!   relative (property tests).
//! * Outside the range: a typed error ([`LawError`], [`EvaluateError`] → 422), never NaN; a law whose values
//!   would overflow f64 (e.g. a rise of 1e12 over 1e-300) is rejected with `LAW_OVERFLOW`.
//!   Jerk in segments shorter than 1e-9·Δt is evaluated but excluded from
//!   `jerk_max_abs_finite` (it acts as a jump, spec §6 item 2).

pub mod catalogue;
pub mod compute;
pub mod error;
pub mod input;
pub mod law;
pub mod output;
pub mod wire;

pub use compute::{EvaluateOutput, compute};
pub use error::{EvaluateError, LawError};
pub use input::EvaluateInput;
pub use wire::{EvaluateRequest, EvaluateResponse};

use crate::calc::CalcFailure;
use crate::numerics::Budget;

/// Compute and build the wire response of `POST /v1/cam-law/evaluate` for a request that passed
/// the door (per-field rules, then the rules between fields in [`EvaluateInput::try_from`]).
///
/// # Errors
/// `RESPONSE_TOO_LARGE` before computing when the answer would exceed the budget's limit;
/// `LAW_OVERFLOW` / `NON_FINITE_RESULT` when the law's values would overflow f64.
pub fn run_valid(input: &EvaluateInput, budget: &Budget) -> Result<EvaluateResponse, CalcFailure> {
    output::response_size(input).check(budget)?;
    let out = compute(input, budget)?;
    Ok(output::respond(input, out))
}

/// The whole path of a request without HTTP (tests, benchmarks): the per-field rules, the rules
/// between fields, then [`run_valid`].
///
/// # Errors
/// As the endpoint: every offending field with its JSON pointer, or the calculation's failure.
pub fn run(req: EvaluateRequest, budget: &Budget) -> Result<EvaluateResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&EvaluateInput::try_from(req)?, budget)
}
