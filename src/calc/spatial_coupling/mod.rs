//! Kinematics of the RP1PR coupling between crossed shafts, in closed form
//! (`POST /v1/spatial-coupling`).
//!
//! Two shafts with crossed axes (common normal 2a, axis angle 180° − 2α) are joined by one body
//! that forms a planar pair with each shaft and touches a fixed support plane P0 (orientation β)
//! at the centre B of a sphere. Given the input angle θ1 and speed ω1: the output angle θ2 (both
//! assembly modes), the transmission ratio and its derivative, the contact point B and its
//! velocity, the motion of B and the rotation of the intermediate body relative to both shafts,
//! the frames and transforms, paths of points of the intermediate body; sweeps over θ1 with
//! unwrapped angles and summaries; the Cardan-equivalence verdict and the support-plane test.
//!
//! Spec: `shared/specs/spatial_coupling.md` (errata of the paper in its §3.6).
//!
//! # References
//! * "A New RP1PR Type Coupling for Shafts with Crossed Axes", Mathematics 2023, 11(9), 2025
//!   (`shared/papers/rp1pr-spatial-coupling.txt`): frames, closure condition, contact point,
//!   relative motions; several equations repaired as the spec's §3.6 records.
//! * The Hooke (Cardan) joint law: tan θ2 · tan θ1 = cos 2α is the Cardan law with bend 2α and
//!   input angle 90° − θ1.
//!
//! # Method
//! All closed form, no iteration (spec §3): θ2 = atan2(σ cos2α c1, σ s1); i12 = −cos2α/(s1² +
//! cos²2α c1²) (cancellation-free denominator); r_B = −a·N/D with the branch-free N, D of §3.3 and
//! its analytic derivative; x, z of B in the shaft frames by projection (frame-rotation terms
//! vanish because B lies in both planes); θ31 = atan2(−σ sin2α s1, σ cos2α) and
//! θ32 = atan2(−sin2α c1, −σρ) (exact reductions of atan2(k3·i1, k3·k1), atan2(k3·i2, k3·k2)), with
//! the analytic rates of §3.4. Input angles are reduced modulo 360° in degrees before any trig
//! (exact at multiples of 90°). Along a sweep θ2 is continued analytically over any number of
//! revolutions, θ31 and θ32 about the centre of their oscillation (swing ≤ 90°), so unwrapping
//! never depends on the sweep's step. See [`kinematics`].
//!
//! # Validity and accuracy
//! * Input range: α ∈ (−90°, 90°) with |cos 2α| ≥ 1e-9, β ∈ (−90°, 90°], 0 < a ≤ 1e6 m,
//!   |ω1| ≤ 1e6 rad/s, any finite θ1; sweeps of 2…10⁶ points need the support plane to pass
//!   cos(α−β)·cos 2α·cos(α+β) > 0 with min|D|/max|D| above round-off (64ε).
//! * Accuracy (measured, tests/it/paper_spatial_coupling.rs): the spec's golden points (§6) agree
//!   with an independent vector implementation of §3.1–3.4 to ≤ 8.3e-16 (relative to max(1, |x|),
//!   lengths over a) on every quantity, and with the spec's printed digits; the seven loop-closure
//!   equations of spec §4, rebuilt in the test from the returned angles, point and frames, hold to
//!   ≤ 2.1e-15·max(a, |rB|) over 2000 random configurations (the module's own `check` ≤ 8.9e-16);
//!   analytic rates agree with central differences (h = 1e-5 rad) of the returned positions to
//!   ≤ 1e-8 on the spec's cases and ≤ 7.9e-8 (relative to the rate's scale) over 200 random
//!   configurations with |cos 2α| ≥ 0.05 and min|D|/max|D| ≥ 1e-3 — the differences' own
//!   truncation error, which grows like 1/|cos 2α|³ toward the dead points.
//! * The rate ω32 is −σ·sin2α·s1/ρ, the rate of the returned θ32: the spec's §3.4 prints it
//!   without σ ("does not depend on σ"), which holds for the vector ω32·j2 but not for the signed
//!   rate about j2 (central differences and the two chains of body 3's angular velocity decide).
//! * Outside the range: a typed 422 (`INVALID_INPUT`, `PERPENDICULAR_SHAFTS`,
//!   `SUPPORT_PLANE_INVALID` for a sweep, `DEADLINE_EXCEEDED`); single points where D is zero to
//!   round-off (64ε·max|D|) answer `{"error": {"code": "CONTACT_AT_INFINITY", …}}`. Warnings:
//!   `NEAR_PERPENDICULAR_SHAFTS` (|cos 2α| < 0.1), `CONTACT_ILL_CONDITIONED` (min|D|/max|D| <
//!   1e-3), `CONTACT_POINT_FAR` (|rB| > 1e3·a), `SUPPORT_PLANE_INVALID` (points-only requests),
//!   `LARGE_ANGLE` (|θ1| > 8e9°).

pub mod compute;
pub mod error;
pub mod input;
pub mod kinematics;
pub mod output;
pub mod wire;

use crate::calc::CalcFailure;
use crate::numerics::Budget;

pub use compute::{SpatialCouplingOutput, compute};
pub use error::SpatialCouplingError;
pub use input::SpatialCouplingInput;
pub use wire::{SpatialCouplingRequest, SpatialCouplingResponse};

/// Compute and respond for a request that passed the door (the per-field rules, then
/// [`SpatialCouplingInput::try_from`]).
///
/// # Errors
/// A [`CalcFailure`] (HTTP 422) for a sweep with an invalid support plane or an exhausted budget.
pub fn run_valid(
    input: &SpatialCouplingInput,
    budget: &Budget,
) -> Result<SpatialCouplingResponse, CalcFailure> {
    let out = compute(input, budget)?;
    Ok(output::respond(input, &out, budget))
}

/// The whole path of a request without HTTP (tests, benchmarks): the per-field rules, the rules
/// between fields, then [`run_valid`].
///
/// # Errors
/// A [`CalcFailure`] (HTTP 422) for invalid input, a sweep with an invalid support plane, or an
/// exhausted budget.
pub fn run(
    req: SpatialCouplingRequest,
    budget: &Budget,
) -> Result<SpatialCouplingResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&SpatialCouplingInput::try_from(req)?, budget)
}
