//! `POST /v1/continuum-workspace`: forward kinematics, stability, assembly modes and workspace of
//! planar parallel continuum manipulators (the planar continuum Keops-Delta).

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::continuum_workspace::{
    self, ContinuumWorkspaceRequest, ContinuumWorkspaceResponse, Input,
};

/// Forward kinematics and workspace of a planar parallel continuum manipulator.
///
/// Elastic rods (planar Kirchhoff rods, optionally axially extensible) clamped on linear-actuator
/// carriages and pinned to a rigid platform. `mode = fk`: the equilibrium pose for given inputs and
/// platform load by RK4 shooting and Newton (started from the stress-free home, a warm-start
/// state or an assembly mode), rod forces, base moments, stresses, actuator forces, optional rod
/// shapes and the stability test (smallest constrained eigenvalue of the discretised potential).
/// `mode = assembly_modes`: several equilibria from a grid over the closed-form elastica refined
/// by Newton (never certified complete). `mode = workspace`: wave propagation over a 2-D input
/// grid, one wave per assembly mode, stopping at unstable, singular or limit-violating nodes;
/// reachable points, parasitic-angle map, union area of the (possibly folded) cell map, stresses.
/// Presets (`design.preset`) use ASSUMED geometry and say so. Heavy work honours `time_limit_ms`;
/// a spent budget returns the partial result with `report.stop_reason = deadline`. A sweep with
/// several waves (seed kind `all_stable_modes`) can be split by wave with `shard`; the answers of
/// the shards merge into the unsharded answer as their `shard` says.
#[utoipa::path(
    post,
    path = "/v1/continuum-workspace",
    tag = "continuum-robots",
    operation_id = "solve_continuum_workspace",
    request_body = ContinuumWorkspaceRequest,
    responses(
        (status = 200, description = "FK result, assembly modes or workspace sweep (shape by `mode`; a sharded sweep lists its block of waves)", body = ContinuumWorkspaceResponse),
        ProblemResponses
    )
)]
pub async fn solve(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<ContinuumWorkspaceRequest, Input>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        continuum_workspace::run_valid(&input, budget)
    })
    .await
}
