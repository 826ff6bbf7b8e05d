//! `POST /v1/vibration-absorber`: an active (PD-controlled electromagnetic) vibration absorber on
//! a cantilever, exact in time and frequency.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::vibration_absorber::{
    self, VibrationAbsorberInput, VibrationAbsorberRequest, VibrationAbsorberResponse,
};

/// Active vibration absorber on a cantilever: gains, eigenvalues, FRF and exact time response.
///
/// Euler–Bernoulli cantilever (n modes) with a tuned mass whose force comes from a voice coil
/// (R–L, force constant, back-EMF) under PD control of the stroke. Always: bare-beam modes, static
/// compliance, absorber stiffness and mass ratio, and (configuration `active`) the PD gains that
/// place two fixed-base absorber roots at ±j2πf_c (paper Eq. (7)(8)). On request (`outputs`):
/// natural frequencies with the absorber, closed-loop eigenvalues and a stability label,
/// absorber-only step responses (exact 2 % settling time) and closed-loop FRF, the coupled
/// receptance on a frequency grid, and the time response to a harmonic, impulse or step force,
/// computed exactly by matrix-exponential stepping of an exosystem-augmented state space (no ODE
/// solver: exact for any output step). Configurations: `none`, `passive` (coil open),
/// `passive_shorted`, `active`. SI units throughout.
#[utoipa::path(
    post,
    path = "/v1/vibration-absorber",
    tag = "vibration",
    operation_id = "analyze_vibration_absorber",
    request_body = VibrationAbsorberRequest,
    responses(
        (status = 200, description = "Modal data, gains and the requested analyses", body = VibrationAbsorberResponse),
        ProblemResponses
    )
)]
pub async fn analyze(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<VibrationAbsorberRequest, VibrationAbsorberInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        vibration_absorber::run_valid(&input, budget)
    })
    .await
}
