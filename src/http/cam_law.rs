//! `POST /v1/cam-law/evaluate`: a cam motion law evaluated at given abscissae.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::cam_law::{self, EvaluateInput, wire::EvaluateRequest, wire::EvaluateResponse};

/// Evaluate a cam motion law: s, v, a, jerk at given abscissae, knots, exact peaks and jumps.
///
/// The law is either the general 7-segment modified-trapezoidal law (7 duration coefficients, any
/// end velocity and acceleration) or a classic law of the catalogue by name. Units are the
/// caller's: the abscissa x is time or cam angle, displacement has unit U, velocity U/x,
/// acceleration U/x², jerk U/x³. Closed form: no solver, microseconds per request.
#[utoipa::path(
    post,
    path = "/v1/cam-law/evaluate",
    tag = "cam-law",
    operation_id = "evaluate_cam_law",
    request_body = EvaluateRequest,
    responses(
        (status = 200, description = "The law, its knots, peaks and the requested curves", body = EvaluateResponse),
        ProblemResponses
    )
)]
pub async fn evaluate(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<EvaluateRequest, EvaluateInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        cam_law::run_valid(&input, budget)
    })
    .await
}
