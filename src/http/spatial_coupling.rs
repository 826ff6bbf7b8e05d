//! `POST /v1/spatial-coupling`: kinematics of the RP1PR coupling between crossed shafts.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::spatial_coupling::{
    self, SpatialCouplingInput, SpatialCouplingRequest, SpatialCouplingResponse,
};

/// Kinematics of the RP1PR coupling between crossed shafts, in closed form.
///
/// Two shafts with crossed axes (common normal 2a, axis angle 180° − 2α) joined by one body that
/// forms a planar pair with each shaft and touches a support plane (orientation β) at a sphere
/// centre B. Returns the output angle θ2 (assembly mode σ), the transmission ratio i12 and its
/// derivative, and, when asked, the contact point B and its velocity, the motion of B and the
/// rotation of the intermediate body relative to both shafts, frames and transforms, paths of
/// points of the intermediate body and closure residuals; sweeps over θ1 with unwrapped angles
/// and summaries (ratio range, fluctuation, amplitudes, lemniscate box). `configuration` gives
/// the Cardan equivalence (bend 2α; homokinetic only for α = 0) and the support-plane validity
/// test. Angles in degrees, lengths in m, rates in rad/s. Closed form: well under a microsecond
/// per point.
#[utoipa::path(
    post,
    path = "/v1/spatial-coupling",
    tag = "spatial-linkages",
    operation_id = "evaluate_spatial_coupling",
    request_body = SpatialCouplingRequest,
    responses(
        (status = 200, description = "Configuration verdicts, the requested points and the sweep's summary and series", body = SpatialCouplingResponse),
        ProblemResponses
    )
)]
pub async fn evaluate(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<SpatialCouplingRequest, SpatialCouplingInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        spatial_coupling::run_valid(&input, budget)
    })
    .await
}
