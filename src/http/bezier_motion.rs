//! `POST /v1/bezier-motion-law`: Bezier servo motion laws with zero residual vibration.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::bezier_motion::{self, BezierInput, BezierMotionRequest, BezierMotionResponse};

/// Bezier motion law of a servo move through a compliant joint: residual vibration in closed form,
/// and the zero-vibration law.
///
/// A rest-to-rest motor move of angle Phi in time T follows a Bezier law whose first and last
/// m+1 ordinates are pinned and whose p interior ordinates γ are free; the load sits behind a
/// reducer (ratio z) and a spring-damper joint (k, c, J_eq). `mode = simulate` returns the end
/// state ψ(T), ψ'(T) and the residual energy E(T) of the given law (closed-form transition
/// matrix for every damping ratio ξ ≥ 0, integration by parts or Gauss–Legendre by the spec's
/// rule). `mode = optimize` returns the law with E(T) = 0 (or least, for p = 1 or a rank-deficient
/// case) by one direct linear solve, made unique by a secondary objective, beside the reference
/// law; an optional robust variant also zeros E at k(1±δ). Kinematic peaks (on by default), the
/// sampled time history and a stiffness sensitivity sweep are optional outputs. Microseconds of
/// compute for the paper's case.
#[utoipa::path(
    post,
    path = "/v1/bezier-motion-law",
    tag = "motion-laws",
    operation_id = "solve_bezier_motion_law",
    request_body = BezierMotionRequest,
    responses(
        (status = 200, description = "The law, its residual vibration and the requested outputs", body = BezierMotionResponse),
        ProblemResponses
    )
)]
pub async fn solve(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<BezierMotionRequest, BezierInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        bezier_motion::run_valid(&input, budget)
    })
    .await
}
