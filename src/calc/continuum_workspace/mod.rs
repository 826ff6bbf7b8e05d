//! Forward kinematics, stability and workspace of planar parallel continuum manipulators (elastic
//! rods clamped on linear-actuator carriages and pinned to a rigid platform; the planar Keops-Delta).
//! Endpoint `POST /v1/continuum-workspace`. Spec: `shared/specs/continuum_workspace.md`.
//!
//! # Method
//! * Each rod is a planar Kirchhoff rod (optionally axially extensible) integrated in nondimensional
//!   form by fixed-step RK4 together with its exact sensitivities ([`rod`], spec 4.1, paper eq. 8).
//! * FK is Newton's method with backtracking on the full residual (rod closure, pinned-tip moments,
//!   platform force and moment balance, [`model`], [`newton`], paper eqs. 16-19, 22), started by
//!   continuation from the stress-free home or from a given state or assembly mode ([`fk`], 4.3).
//!   The continuation from home is adaptive by default (issue 17; `start.continuation`): tangent
//!   predictor, first step `1/K` of the spec's K, doubled after a step whose chord-Newton
//!   corrector (the last evaluated Jacobian, kept across steps while it converges in <= 2
//!   iterations) reaches 1e-6 in <= 3 iterations, halved when the corrector fails or moves more
//!   than half the predictor step (trust region), at most 1/4 of the path per step, and full
//!   Newton to `solver.tol` at the target. `continuation: fixed` is the spec 4.3 path (K equal
//!   steps, full Newton each), with which the spec's reference values were produced.
//! * Stability: the smallest eigenvalue of the constrained Hessian of a discretised potential
//!   ([`stability`], 4.5), plus the cheap det J sign companion.
//! * Assembly modes ("full FK"): a grid over the closed-form elastica (elliptic integrals, paper
//!   eqs. 12-15 with the branch fix of 4.9-1) refined by Newton ([`modes`], 4.6) — NOT certified.
//! * Workspace: wave propagation over the joint-space grid, one wave per assembly mode, stopping at
//!   unstable, singular or limit-violating nodes ([`sweep`], 4.7), and the derived metrics (union
//!   area of the possibly folded cell map, parasitic angle, stresses; [`area`], 4.8).
//!
//! # Sharding (`shard`, mode `workspace`)
//! The independent items of a sweep are its WAVES, not blocks of grid nodes: a wave spreads
//! breadth-first from its seed and every node is solved from an already accepted neighbour
//! (whose state starts the Newton solve and whose tangent predicts it; the neighbour that
//! reaches a node first decides its branch), so no block of nodes can be computed without the
//! nodes before it. A sweep has one wave per seed: seed kind `all_stable_modes` one per stable
//! assembly mode at the seed node, every other kind exactly one. A single-seed sweep therefore
//! cannot be split: shard 0 of it holds the one wave and shards 1.. are empty. Every shard runs
//! the seed search (the same in each; it gives the number of waves and their seeds), then only
//! the waves `Shard::range(n_waves)`, each exactly as in the whole sweep. A sharded answer
//! ([`wire::WorkspaceShardResponse`]) lists its waves and says which they are (`shard`, with
//! `total` = waves of the sweep). Merge rule: concatenate the `waves` of shards 0..count in
//! order; the first wave overall is the unsharded answer's top-level wave (`seed`, `nodes`,
//! `metrics`, `failures`) and the rest, in order, its `other_waves` (omitted for one wave);
//! `grid` and `preset` are the same in every shard; `warnings` are the union of the shards'
//! warnings in order of first appearance; `timing_ms` and `report` are per shard. Every metric
//! belongs to one wave, so nothing is added up or recomputed. Modes `fk` and `assembly_modes`
//! are one job with nothing to split: a `shard` there is a 422 at `/shard`, as on the other
//! endpoints' modes without a sweep.
//!
//! # References
//! * Planar continuum Keops-Delta workspace paper (`shared/papers/planar-continuum-delta-workspace.txt`):
//!   Kirchhoff rods, shooting FK, elliptic-integral full FK, wave-propagation workspace, parasitic
//!   angle, vertical payload.
//! * B. C. Carlson, Numerical computation of real or complex elliptic integrals, Numer. Algorithms
//!   10 (1995) 13-26 (the elliptic integrals in [`crate::numerics::elliptic`]).
//!
//! # Conventions
//! Plane XY, angles counter-clockwise from +X, `a x b = a_x b_y - a_y b_x`. `n_i` is the force the
//! platform applies to the tip of rod i (the rod pushes the platform with `-n_i`); `theta_EE` is the
//! platform rotation (parasitic angle), reported wrapped to (-180, 180] deg but continuous inside
//! sweeps. Workspace node arrays are row-major `n1 x n2` (index `i * n2 + j`, `i` over `lambda1`).
//!
//! # Validity and accuracy
//! * Inputs: 2..8 rods on 1..4 linear guides (exactly 2 for sweeps), slender rods (L/d >= 20; 5..20
//!   warned, < 5 rejected), loads up to `1e4 EI_ref/L_ref^2`. Presets use ASSUMED geometry (the paper
//!   gives none) and say so in the response.
//! * Achieved error (tests/it/paper_continuum_workspace.rs, benches/RESULTS.md): closed-form elastica
//!   (with the branch fix) vs RK4 shooting agree to 1.6e-12 L on 60 random rods (spec: 1e-9 L);
//!   FK at the default 32 RK4 steps is 2.8e-8 m, 4.3e-6 deg and 1.1e-5 N from the 4096-step
//!   reference (error ~ steps^-4; spec 6.2 tolerances 1e-7 m, 1e-5 deg, 1e-4 N, met on all seven
//!   reference rows); the stability test gives the Euler loads 20.165 / 20.184 (clamped-pinned) and
//!   2.4671 / 2.4673 (clamped-free) at M = 40 / 80 (margin error ~ M^-2, 0.2 % at M = 40);
//!   actuator forces equal the derivative of the potential energy to 3.5e-10 relative; the
//!   symmetric design keeps theta_EE = 0 to 5e-14 deg; the design-1 sweeps reproduce the spec's
//!   node counts, union areas, folded cells and maximum angles (717 vs ~705 nodes, 0.2333 m^2,
//!   35 cells, 3.18 deg); the assembly-mode search finds the spec's 4 solutions (2 stable) of
//!   design 1 at (-0.22, 0.2425) with N_grid 6 / Tol 0.45 and all 10 (5 stable) with the 3-rod
//!   default N_grid 9 / Tol 0.5, stable poses to 1e-6 m.
//! * Adaptive vs fixed continuation from home (benches/RESULTS.md, issue 17): on the spec 9 FK
//!   request (d1, F = (0, -50) N, no stability) the adaptive path takes 9 steps, 38 Newton and
//!   chord iterations and 57 rod-system evaluations against the fixed path's 20 / 40 / 61, about
//!   half the compute (0.45 vs 0.90 ms median of `run()` on the loaded 2-core machine), and the
//!   same pose (1e-16 m apart, 1.6e-9 m from the 4096-step reference for both). Over 300 random
//!   targets in design 1's stable workspace (loads up to 20 N) both land on the same
//!   equilibrium: platform positions 9.5e-12 m apart at worst (criterion 1e-9 L_ref), angles
//!   1.9e-10 rad, scaled unknowns 5.8e-10, rod forces 6.1e-9 N (both end solves stop at
//!   `||g||_inf < 1e-10`, which bounds how closely they can agree); 6.1 steps on average (max 9)
//!   instead of 16.0 (max 26). Where the adaptive walk stalls (the symmetric preset's straight
//!   rods make the Jacobian singular at home; design 1's far row (0.05, 0.0725)) the fixed steps
//!   are walked from the same start and the answer says so (`continuation_fallback`), so an
//!   adaptive request never fails where the fixed one arrives. The six spec 6.2 FK rows meet their tolerances on both paths
//!   (tests/it/paper_continuum_workspace.rs).
//! * Outside the range: nodes/solves that do not converge are reported (`no_convergence`,
//!   `taut_rod i`), straight rods of over-constrained designs give `singular` (forces indeterminate:
//!   not returned; enable `axial_extensibility`), unstable equilibria are flagged and stop the wave.
//!   The assembly-mode list is never certified complete (`complete: false`). The maximum parasitic
//!   angle of a sweep sits on the workspace boundary and does not converge with grid refinement
//!   unless a physical limit (stress, stroke, gap) defines the boundary.

pub mod area;
pub mod closed_form;
pub mod compute;
pub mod error;
pub mod fk;
pub mod input;
pub mod model;
pub mod modes;
pub mod newton;
pub mod output;
pub mod presets;
pub mod rod;
pub mod stability;
pub mod sweep;
pub mod wire;

use std::time::Duration;

pub use error::ContinuumError;
pub use input::Input;
pub use wire::{ContinuumWorkspaceRequest, ContinuumWorkspaceResponse};

use crate::calc::CalcFailure;
use crate::numerics::Budget;

/// Compute and build the answer of `POST /v1/continuum-workspace` for a request that passed the
/// door (per-field rules, then the rules between fields in [`Input::try_from`]), within the
/// request's own time limit.
///
/// # Errors
/// `RESPONSE_TOO_LARGE` before computing when the answer would exceed the budget's limit;
/// `ASSEMBLY_MODE_NOT_FOUND` for an assembly mode index beyond the modes the search found.
/// Non-convergence and a spent budget are not errors: they are reported in the answer.
pub fn run_valid(
    input: &Input,
    budget: &Budget,
) -> Result<ContinuumWorkspaceResponse, CalcFailure> {
    output::response_size(input).check(budget)?;
    let budget = match input.time_limit {
        Some(t) => budget.clone().capped(t),
        None => budget.clone(),
    };
    let out = compute::compute(input, &budget)?;
    Ok(output::respond(input, out, &budget))
}

/// The whole path of a request without HTTP (tests, benchmarks): the per-field rules, the rules
/// between fields, then [`run_valid`].
///
/// # Errors
/// As the endpoint: every offending field with its JSON pointer, or the calculation's failure.
pub fn run(
    req: ContinuumWorkspaceRequest,
    budget: &Budget,
) -> Result<ContinuumWorkspaceResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&Input::try_from(&req)?, budget)
}

/// The request's own time limit (`time_limit_ms`, capped at the service maximum).
#[must_use]
pub fn time_limit(req: &ContinuumWorkspaceRequest) -> Option<Duration> {
    req.time_limit_ms
        .map(|ms| Duration::from_millis(ms.clamp(1, input::MAX_TIME_LIMIT_MS)))
}
