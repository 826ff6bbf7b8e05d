//! `POST /v1/cognates`: the two Roberts–Chebyshev cognates of a four-bar linkage.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::cognates::{self, CognatesInput, wire::CognatesRequest, wire::CognatesResponse};

/// Roberts–Chebyshev cognates: two other four-bars that trace the same coupler curve.
///
/// Given a four-bar (ground pivots A, B; crank, coupler, rocker) and a coupler point P, returns the
/// third ground pivot C and both cognates with their physical link roles, the paper's
/// similarity-ordered coupler sides, Grashof/Barker class, feasible input range and toggles, the
/// same pose in all three mechanisms (own input angle and branch) and the timing map. Optional,
/// computed only when asked in `options`: circuit-aware coupler curves, a numerical certificate
/// that the curves coincide, 1:1 geared five-bar equivalents and comparison metrics. Lengths in
/// any consistent unit (returned in the same unit), angles in degrees. Closed form: microseconds
/// without curves.
#[utoipa::path(
    post,
    path = "/v1/cognates",
    tag = "linkages",
    operation_id = "construct_cognates",
    request_body = CognatesRequest,
    responses(
        (status = 200, description = "The original and its two cognates, with the requested optional outputs", body = CognatesResponse),
        ProblemResponses
    )
)]
pub async fn construct(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<CognatesRequest, CognatesInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        cognates::run_valid(&input, budget)
    })
    .await
}
