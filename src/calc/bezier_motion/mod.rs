//! Bezier motion laws with minimum residual vibration for a compliant servo drive
//! (`POST /v1/bezier-motion-law`, spec `shared/specs/bezier_motion.md`).
//!
//! # References
//! G. Incerti, "Dynamic optimization of industrial servomechanisms using motion laws based on
//! Bezier curves", WASET IJMME 3(10), 2009 (paper issues resolved as spec §3.11 lists: basis
//! exponent `n−i`, boundary table reconstructed, ωn = 53.357 rad/s, m = 2 / p = 3 assumed, the
//! state-space form instead of the ξ < 1-only Eqs. 7, 26–29).
//!
//! # Method
//! * [`law`]: the rest-to-rest Bezier law (first/last `m+1` ordinates pinned, `p` free), its
//!   derivative polygons and de Casteljau evaluation (never the monomial basis).
//! * [`plant`]: the joint `ψ'' + 2ξωn ψ' + ωn² ψ = −z φ''`; the transition matrix `e^{Ac t}` in
//!   closed form for every ξ ≥ 0 (power series for `|ωn²(1−ξ²)t²| < 1e-2`, so no 0/0 at ξ = 1;
//!   both exponentials of the over-damped branch formed directly, so nothing overflows); the
//!   response matrix `x(T) = H·A` by integration by parts when `r = 2N/rho_min ≤ 1`, else by
//!   composite Gauss–Legendre with the node rule of spec §3.5b — except strongly over-damped
//!   drives (ξ ≥ 1.25, more than two panels), whose two real modes are integrated separately
//!   (the fast one by parts, the slow one by parts or by a few Gauss–Legendre nodes), where the
//!   uniform panels spent hundreds of panels on the fast mode's boundary layer. A stiffness
//!   sweep never forms `H`: the law's end derivatives are computed once and each factor's end
//!   state is O(N) (IBP) or O(N) per node (Gauss–Legendre).
//! * [`optimize`]: the residual is affine in γ, so `E = ‖r0 + Rγ‖²`; the optimum is one
//!   equality-constrained least-norm solve (Cholesky of `Hq`, pseudo-inverse of the 2×2 — or 6×6
//!   robust — `Kc`), with the secondary objective `min_deviation` (default), `min_accel_l2` or
//!   `min_jerk_l2`. No iterative optimiser, no ODE integrator on the default path. The L2
//!   objectives are assembled exactly: integer Gram numerators over one common denominator
//!   (`C(n,i)C(n,j)/C(2n,i+j) = C(i+j,i)C(2n−i−j,n−i)/C(2n,n)`), integer difference stencils,
//!   each entry rounded once, the positive scale left out of the solve.
//! * [`shaper`]: the optional comparison with input shapers (ZV, ZVD, EI on a trapezoidal or
//!   cycloidal baseline of the same total move time), in closed form (Van Loan matrix
//!   exponentials of the plant augmented with its forcing, exact peaks).
//! * [`kinematics`], [`history`]: optional peaks (dense sampling + golden section) and the
//!   sampled response (exact transition + Gauss–Legendre per step).
//!
//! # Validity and accuracy
//! * Input range: spec §2 (bounds in [`wire`]); `N = 2m+p−1 ≤ 30`; the Gauss–Legendre path
//!   accepts `rho_max = T|p_fast| ≤ 2e5`, a time history `rho_max ≤ 1.6e6`; beyond: typed 422.
//! * Accuracy (measured, `tests/it/paper_bezier_motion.rs`): the spec's V1–V8 values are met to
//!   their tolerances (x(T), E to ≤ 1e-10 relative on the IBP and GL paths; optimum ordinates to
//!   1e-9; E at the optimum ≤ 1e-20 J); the closed-form end state agrees with a 20 000-step RK4
//!   integration of the same plant to the RK4 truncation level (≤ 1e-9 relative).
//! * Independent check over the whole §7 range (`tests/slow/stress_bezier_motion.rs`): random
//!   `(m, p)` with N ≤ 30, ωnT ∈ [0.05, 1e4], ξ ∈ [0, 10] (ξ = 0 and ξ ≈ 1 weighted in): the
//!   production end state agrees with an adaptive Dormand–Prince 5(4) integration (rtol 1e-12,
//!   1e-13 beyond ωnT = 1e3) to ≤ 1e-9 in the energy norm relative to `|z|·max|A|/ωn` (at
//!   rtol 1e-12 the integrator's own phase drift on an undamped drive reaches 4.3e-9 at
//!   ωnT = 1e4, hence the tighter rtol there); the GL path at rho_max = 2e5 agrees to the same
//!   level. IBP and GL agree to ≤ 1e-13 for ωnT ≲ 300; beyond,
//!   the GL sum's own phase round-off (≈ 16 ε·ωnT, 1.2e-11 at ωnT = 1e4, the same size as GL
//!   against GL with twice the panels) dominates — the production path there is IBP.
//! * Hazards (same file): E and x(T) are continuous across ξ = 1 (|x(1 ± d) − x(1)| ≤ 1.5 × the
//!   true slope × d for d = 1e-12, 1e-9, 1e-6, on both paths); every admissible `(m, p)` and
//!   objective gives finite numbers with E ≤ 1e-20·E_ref or at the §3.6 floor; ξ ≫ 1 with r ≤ 1
//!   drops one constraint (rank 1, `exact_zero = false`, LEAST_SQUARES_COMPROMISE); the corners of
//!   every documented range give finite numbers or RHO_TOO_LARGE / NON_FINITE_RESULT (a stiffness
//!   factor that underflows k·f to 0). The optimum's accuracy is backward-stable: E* ≲
//!   (64 ε cond(Kc))²·E_ref, which is below 1e-20·E_ref for cond(Kc) ≲ 1e5 (property tests).
//! * Issue 27 (`tests/it/paper_bezier_motion.rs`): the L2 optima agree with 80-digit references
//!   (`tests/fixtures/bezier_motion/`, the mpmath script beside them) to ≤ 1e-5 of max|γ*| up to
//!   cond(Hq) = 5.3e12 (N = 30); the modal end state agrees with Gauss–Legendre at twice the
//!   panels to ≤ 1e-11 (energy norm over `|z|·max|A|/ωn`); the sweep's end state equals `H·A`
//!   to ≤ 1e-13.
//! * Shaper comparison (same file): every row's E(T) (nominal and on k·f) agrees with an RK4
//!   integration of the definitions restarted at every breakpoint to 1e-8 relative; ZV and
//!   ZVD leave E(T) ≤ 1e-12 of the unshaped baseline's at the design stiffness; the peaks are
//!   exact (breakpoints and quarter periods). For ξ ≥ 1 the comparison is omitted with a warning;
//!   a shaper as long as the move gives a `null` row and a warning.
//! * Outside the range: a typed error ([`BezierMotionError`]), never NaN.
//! * Cost (`benches/bezier_motion.rs`, `benches/RESULTS.md`): x(T) by the closed form 0.24 µs at
//!   2.7e-14 (≈ 1/200 of RK45 at rtol 1e-9); the paper-case optimise request 5.0 µs without and
//!   8.1 µs with the default kinematic peaks (§3.9 sampling at 64(N+1)+1 points per derivative;
//!   `compute` alone 7.5 µs).

pub mod compute;
pub mod error;
pub mod history;
pub mod input;
pub mod kinematics;
pub mod law;
pub mod optimize;
pub mod output;
pub mod plant;
pub mod shaper;
pub mod wire;

pub use compute::{BezierOutput, compute};
pub use error::BezierMotionError;
pub use input::BezierInput;
pub use wire::{BezierMotionRequest, BezierMotionResponse};

use crate::calc::CalcFailure;
use crate::numerics::Budget;

/// The job of `POST /v1/bezier-motion-law` once the request passed the door: size check,
/// compute, respond.
///
/// # Errors
/// A [`CalcFailure`] (HTTP 422) for a request beyond the method's limits (the codes of
/// [`input::CROSS_FIELD_RULES`]).
pub fn run_valid(
    input: &BezierInput,
    budget: &Budget,
) -> Result<BezierMotionResponse, CalcFailure> {
    output::response_size(input).check(budget)?;
    let out = compute(input, budget)?;
    Ok(output::respond(input, &out, budget))
}

/// The whole path of `POST /v1/bezier-motion-law` without HTTP (tests, benchmarks, the CLI):
/// the per-field rules, the rules between fields, then [`run_valid`].
///
/// # Errors
/// A [`CalcFailure`] (HTTP 422) for invalid input or a request beyond the method's limits.
pub fn run(req: BezierMotionRequest, budget: &Budget) -> Result<BezierMotionResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&BezierInput::try_from(req)?, budget)
}
