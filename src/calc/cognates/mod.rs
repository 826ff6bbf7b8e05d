//! Roberts–Chebyshev cognates of a planar four-bar linkage (`POST /v1/cognates`).
//!
//! Given a four-bar (ground pivots A, B; crank a, coupler b, rocker c) and a coupler point P rigidly
//! attached to the coupler, returns the two other four-bars that trace exactly the same coupler curve,
//! each with its pivots, physical link roles, Grashof/Barker class, feasible input range, toggles and
//! the configuration matching a requested pose of the original; optionally circuit-aware sampled
//! curves, a numerical certificate that the curves coincide, the 1:1 geared five-bar equivalents and
//! comparison metrics.
//!
//! Spec: `shared/specs/cognates.md` (errata of the paper resolved in its §4.12).
//!
//! # References
//! * The mechanism-synthesis paper of the spec (four-bar modelling, Grashof check, construction of the
//!   two cognates, MATLAB implementation, one numeric example in its Table 1),
//!   `shared/papers/mechanism-synthesis-cognates.txt`.
//! * S. Roberts (1875), P. L. Chebyshev (1878): the triple generation of coupler curves; Hartenberg &
//!   Denavit, *Kinematic Synthesis of Linkages* (1964), §6 (Cayley diagram, geared five-bars).
//! * F. Grashof (1883); C. R. Barker, "A complete classification of planar four-bar linkages",
//!   Mech. Mach. Theory 20 (1985) 535–554 (types GCCC…RRR4).
//!
//! # Method
//! Closed form throughout: `C = A + k·(B − A)` with the complex coupler ratio `k` (`P = D + k·(E − D)`);
//! cognate 1 = (A, C, |k|·b, |k|·a, |k|·c, 1/k), cognate 2 = (C, B, |1−k|·a, |1−k|·c, |1−k|·b, k/(k−1));
//! the same pose in all three by `D1 = A + (P − D)`, `E1 = A + k(E − A)`, `D2 = C + (1 − k)(D − A)`,
//! `E2 = B + (P − E)`; position analysis with the factored dyad height (no cancellation at toggles);
//! feasible ranges by the half-angle formula (no `acos` near ±1). See [`geometry`].
//!
//! # Validity and accuracy
//! * Input range: lengths in (0, 1e100], coordinates within ±1e100, the longest link shorter than
//!   the sum of the other three (by more than 1e-12 of it), no link below 1e-12 × the largest length
//!   L, P farther than 1e-9·b from both coupler joints. Scale does not matter: the computation runs
//!   in a frame normalised by an exact power of two (tested from 1e-90 to 1e90).
//! * Geometry (C, cognate lengths, ranges, toggles, pose map, timing) is closed form and exact to
//!   rounding: the spec's Table-1 and closed-form cases agree with an independent recomputation to
//!   1e-12 and with the spec's printed 6-decimal values (tests/it/paper_cognates.rs).
//! * The cognates trace the original's points: constraint residuals ≤ 1e-13·L and independent
//!   re-solve ≤ 1e-12·L where the cognate is away from its toggles (h/b ≥ 1e-2) on 3 000 random
//!   linkages over 6 decades of scale; toward a toggle the re-solve is ill-conditioned (error
//!   ~ε·L²/h, up to 1.3e-7·L observed at toggles of near-deltoid linkages). The sextic distance of
//!   the cognates' own traced points is ≤ 1e-12·L (measured ≤ 2e-13·L).
//! * Curve sampling: chord error O(N⁻²) with `auto` spacing (4.4e-6 at N = 1024 on the paper
//!   example, L = 3.1; ≤ 106·L/N² on 20 random linkages); `uniform` spacing is O(N⁻¹) on
//!   limited-range circuits. Positions exactly at toggles carry ~sqrt(ε)·L rounding.
//! * Outside the range: a typed 422 (`NON_POSITIVE_LENGTH`, `COINCIDENT_PIVOTS`,
//!   `COUPLER_TRIANGLE_INVALID`, `COUPLER_POINT_AT_JOINT`, `NOT_ASSEMBLABLE`, `TOO_MANY_POINTS`,
//!   `DEADLINE_EXCEEDED`, `INVALID_INPUT`); degenerate but valid shapes (change point,
//!   parallelogram, deltoid, collinear coupler point, snapshot at a toggle, extreme aspect ratio,
//!   P near a joint) return results plus warnings. An input angle outside the feasible range returns
//!   `status: not_assemblable` with the ranges.

pub mod compute;
pub mod error;
pub mod geometry;
pub mod input;
pub mod output;
pub mod sampling;
pub mod verify;
pub mod wire;

use std::time::Instant;

use crate::calc::CalcFailure;
use crate::numerics::Budget;

pub use compute::{CognatesOutput, compute};
pub use error::CognatesError;
pub use input::CognatesInput;
pub use wire::{CognatesRequest, CognatesResponse};

/// Compute and respond for a request that passed the door (the per-field rules, then the rules
/// between fields in [`CognatesInput::try_from`]).
///
/// # Errors
/// A [`CalcFailure`] (HTTP 422) for an impossible linkage, too many points or an exhausted
/// budget.
pub fn run_valid(input: &CognatesInput, budget: &Budget) -> Result<CognatesResponse, CalcFailure> {
    let start = Instant::now();
    let out = compute(input, budget)?;
    Ok(output::respond(input, &out, start))
}

/// The whole path of a request without HTTP (tests, benchmarks): the per-field rules, the rules
/// between fields, then [`run_valid`].
///
/// # Errors
/// A [`CalcFailure`] (HTTP 422) for invalid input, an impossible linkage, too many points or an
/// exhausted budget.
pub fn run(req: CognatesRequest, budget: &Budget) -> Result<CognatesResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&CognatesInput::try_from(req)?, budget)
}
