//! Identification of a cam's motion law from sampled motion: the 7 duration coefficients of the
//! general modified-trapezoidal law (`POST /v1/fit-cam-law`).
//!
//! Reference: Tiboni, Amici, Bussola, "Cam Mechanisms Reverse Engineering Based on Evolutionary
//! Algorithms", Electronics 2021, 10, 3073. Spec: `shared/specs/cam_law_fit.md` (errata of §3.7
//! applied; the law itself is [`crate::calc::cam_law::law::SevenSegmentLaw`]).
//!
//! * [`crate::numerics::grid`]: abscissa grid and the numpy-equivalent derivative for a missing
//!   channel (§3.3).
//! * [`objective`]: the paper's Euclidean norm (Eq. 7) and its DTW as the spec pins it (L1
//!   local cost, Sakoe–Chiba band w, no normalization; §3.4), and the evaluation context that
//!   counts evaluations and enforces the budget.
//! * [`optim`]: least squares (`levenberg-marquardt` crate, x² parametrization), the paper's GA
//!   (§3.5.1), scipy-style DE and a small CMA-ES with IPOP restarts.
//! * [`compute`](mod@compute): the `auto` pipeline (§3.5.2: multi-start least squares, zero-snap, DTW
//!   CMA-ES polish + IPOP) and the reported law (§3.6, §4); no wire types.
//! * [`wire`] → [`input`] → [`compute`](mod@compute) → [`output`] (errors in [`error`]): the endpoint; the
//!   HTTP layer calls [`run`].
//!
//! # Validity and accuracy
//!
//! * Input range: 8..200 000 samples, strictly increasing abscissae inside `[t_a, t_b]` (±1e-9·Δt,
//!   clamped), finite values of magnitude ≤ 1e12, budgets 1..10⁷ evaluations and 1..600 000 ms,
//!   cost estimate `max_evaluations·N·(2w+1)` ≤ 2·10¹⁰ cell operations.
//! * Achieved error (tests/it/paper_cam_law_fit.rs, benches/RESULTS.md): `auto` recovers every
//!   Table-3 law from noiseless samples (N = 300, acceleration and velocity, EN and DTW) to
//!   ≤ 5e-14 coefficient error in 45–210 evaluations (0.4–1.7 ms on one core); the Table-1 law
//!   with end rates to ≤ 1e-14 from any channel; the polynomial laws to the spec's best-known
//!   objectives (EN within 1e-3, DTW within 2 %; 3-4-5 displacement DTW is reached by 5 of 6
//!   seeds, the others stop at the symmetric local minimum 0.033247). The spec guarantees only
//!   `1/(N−1)` where a knot sits next to a sampled acceleration jump (§6 item 4; warning
//!   `segment_below_resolution`). Table 6 distances reproduce the reference to its printed
//!   digits (one documented exception of 1.2e-5).
//! * Outside the range: a 422 with the offending field's pointer and what to change; a spent
//!   budget returns the best-so-far with `stop_reason` `deadline` or `max_evaluations` and the
//!   warning `budget_exhausted`; noisy data give the least-squares optimum of the data, which
//!   may be far from the generating law (spec §6 item 7) — reported, not corrected. A law whose
//!   pulses are nearly cancelled by the end rates (|A| ≪ |Δs|/Δt²) is poorly determined: the
//!   fit matches the data but the coefficients of that pulse may differ.

pub mod compute;
pub mod error;
pub mod input;
pub mod objective;
pub mod optim;
pub mod output;
pub mod wire;

use std::time::Duration;

use crate::calc::CalcFailure;
use crate::numerics::Budget;

pub use compute::{FitOutput, compute};
pub use error::FitError;
pub use input::FitInput;
pub use wire::{FitCamLawRequest, FitCamLawResponse};

/// Fit and build the response of `POST /v1/fit-cam-law` for a request that passed the door (the
/// per-field rules, then the rules between fields in [`FitInput::try_from`]).
///
/// # Errors
/// `LAW_OVERFLOW` / `EMPTY_PULSE` / `RESULT_OVERFLOW` when the fitted law cannot be represented.
pub fn run_valid(input: &FitInput, budget: &Budget) -> Result<FitCamLawResponse, CalcFailure> {
    let out = compute(input, budget)?;
    Ok(output::respond(input, out, budget))
}

/// The whole path of a request without HTTP (tests, benchmarks): the per-field rules, the rules
/// between fields, then [`run_valid`].
///
/// # Errors
/// A [`CalcFailure`] (HTTP 422) for invalid input (every offending field with its pointer),
/// a request whose cost estimate is too large, end conditions no law of this duration can meet
/// in f64, or the calculation's failure.
pub fn run(req: FitCamLawRequest, budget: &Budget) -> Result<FitCamLawResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&FitInput::try_from(req)?, budget)
}

/// The request's own wall-clock limit: the top-level `time_limit_ms` of the wire convention and
/// `optimizer.time_limit_ms` (the spec's place for it) both limit the run, so the smaller applies;
/// 10 000 ms when neither is given.
#[must_use]
pub fn time_limit(req: &FitCamLawRequest) -> Option<Duration> {
    let ms = match (req.time_limit_ms, req.optimizer.time_limit_ms) {
        (Some(a), Some(b)) => a.min(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => input::DEFAULT_TIME_LIMIT_MS,
    }
    .clamp(1, input::MAX_TIME_LIMIT_MS);
    Some(Duration::from_millis(ms))
}
