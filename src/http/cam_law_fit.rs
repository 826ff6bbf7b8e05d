//! `POST /v1/fit-cam-law`: identify a cam's 7-segment motion law from sampled motion.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::cam_law_fit::{self, FitCamLawRequest, FitCamLawResponse, FitInput};

/// Identify a cam motion law: the 7 segment coefficients of the general modified-trapezoidal law
/// that best reproduce measured motion.
///
/// Give the follower's sampled displacement, velocity and/or acceleration (against time or cam
/// angle) and the segment's boundary conditions; get back the normalized coefficients, knots,
/// exact peaks, acceleration jumps and the fit quality. Objectives: Euclidean norm or the paper's
/// DTW (L1 cost, Sakoe–Chiba band). Optimizers: `auto` (deterministic multi-start least squares
/// with zero-snapping, the default), the paper's GA, DE, CMA-ES, `lsq`. Runs on the compute pool
/// within `optimizer.time_limit_ms` and `optimizer.max_evaluations`; a spent budget returns the
/// best-so-far with `stop_reason` `deadline` or `max_evaluations`.
#[utoipa::path(
    post,
    path = "/v1/fit-cam-law",
    tag = "cam-law",
    operation_id = "fit_cam_law",
    request_body = FitCamLawRequest,
    responses(
        (status = 200, description = "The identified law, its fit quality and the optimizer report", body = FitCamLawResponse),
        ProblemResponses
    )
)]
pub async fn fit(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<FitCamLawRequest, FitInput>,
) -> Result<Response, ApiError> {
    // `limit`: the smaller of `time_limit_ms` and `optimizer.time_limit_ms` (TimeLimited).
    run_calc(&state, limit, move |budget| {
        cam_law_fit::run_valid(&input, budget)
    })
    .await
}
