//! `POST /v1/irefc-stress` and `POST /v1/irefc-efficiency`: contact stresses (one design or the
//! structured-array sweep) and mesh efficiency of the IREFC cycloid gear.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::irefc::efficiency::input::EfficiencyInput;
use crate::calc::irefc::stress::input::StressJob;
use crate::calc::irefc::{
    self, IrefcEfficiencyRequest, IrefcEfficiencyResponse, IrefcStressRequest, IrefcStressResponse,
};

/// IREFC cycloid gear: element forces and Hertz contact stresses, one design or a sweep.
///
/// Gear with intermediate rolling elements and a free cage (cam with Z2 − 1 lobes, Z2 rolling elements,
/// crown with Z2 + 1 lobes). Mode "single": the torque is shared over the loaded elements (rigid bodies,
/// force ∝ lever arm; the paper's phase-0 sharing or the exact cage phase), the Hertz line-contact pressure
/// at the cam and crown contacts is scanned over the element angle φ2 and each maximum is refined; the
/// response gives the maxima with the state there, the element table and, on request, curves and profile
/// point sets. Mode "sweep": the same for every combination of Z2 × χ (× rb × r2 lists), run in parallel
/// within the time budget; infeasible combinations are records with `valid: false` and the reason
/// (`UNDERCUT`, `ELEMENT_OVERLAP`), and the best and worst feasible designs are indexed. A design that cannot
/// be built is a 422 with code `UNDERCUT` or `ELEMENT_OVERLAP`; oversized grids and sweeps are
/// `GRID_TOO_FINE` / `SWEEP_TOO_LARGE`.
#[utoipa::path(
    post,
    path = "/v1/irefc-stress",
    tag = "irefc",
    operation_id = "compute_irefc_stress",
    request_body = IrefcStressRequest,
    responses(
        (status = 200, description = "Maximum contact stresses of the design, or one record per sweep combination", body = IrefcStressResponse),
        ProblemResponses
    )
)]
pub async fn stress(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<IrefcStressRequest, StressJob>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        irefc::stress::run_valid(&input, budget)
    })
    .await
}

/// IREFC cycloid gear: slip speeds, friction power and mesh efficiency.
///
/// Carrier input, crown fixed, cam output. For every loaded rolling element: pitch-point distances, slip
/// speed at the cam contact, rolling speed, friction power at both contacts and the element efficiency;
/// totals as the product of element efficiencies (the paper) and as the energy balance. Models:
/// "paper_table" (the paper's equations as printed; reproduces its Table 1), "paper_abs" (|Vs|, as the
/// paper's text says) and "rigid_body" (NOT in the paper: physically consistent relative speeds). Optional
/// average over the cage phase. Bearings, churning and seals are outside the model.
#[utoipa::path(
    post,
    path = "/v1/irefc-efficiency",
    tag = "irefc",
    operation_id = "compute_irefc_efficiency",
    request_body = IrefcEfficiencyRequest,
    responses(
        (status = 200, description = "Per-element losses and the mesh efficiency", body = IrefcEfficiencyResponse),
        ProblemResponses
    )
)]
pub async fn efficiency(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<IrefcEfficiencyRequest, EfficiencyInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        irefc::efficiency::run_valid(&input, budget)
    })
    .await
}
