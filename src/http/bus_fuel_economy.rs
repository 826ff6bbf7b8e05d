//! `POST /v1/bus-fuel-economy` and `POST /v1/bus-fuel-economy/motor-map`: drive-cycle energy of
//! a battery-electric bus with an AC-loss-aware traction-motor model, and the maps of one motor.

use axum::extract::State;
use axum::response::Response;

use super::{ApiError, AppState, ProblemResponses, Valid, run_calc};
use crate::calc::bus_fuel_economy::{
    self, BusFuelEconomyInput, BusFuelEconomyRequest, BusFuelEconomyResponse, MotorMapInput,
    MotorMapRequest, MotorMapResponse,
};

/// Energy and fuel economy of an electric bus over drive cycles, for 1..8 traction motors.
///
/// Backward-facing longitudinal model (road load with inertia, single gear in both power
/// directions, inverter, constant-efficiency or 2RC battery) over built-in cycles (`manhattan`,
/// `hwfet`, `hdudds`) or custom traces. Motors: constant efficiency, loss or efficiency map
/// (converted to losses before interpolation), or a parametric dq IPMSM with MTPA / field
/// weakening and separate DC copper, AC copper increment (Dowell or k_AC table), iron and
/// mechanical losses. Demand beyond the motor envelope is counted and reported under the chosen
/// policy (`backward`, `clip`, `forward` with trace miss), never clipped silently. With two or
/// more motors: FE change against the first and the paper's desirability score. Costly outputs
/// (loss breakdown, operating-point histogram, traces, efficiency maps) only on request.
#[utoipa::path(
    post,
    path = "/v1/bus-fuel-economy",
    tag = "bus-fuel-economy",
    operation_id = "compute_bus_fuel_economy",
    request_body = BusFuelEconomyRequest,
    responses(
        (status = 200, description = "Energy, FE and envelope counts per motor × cycle, the comparison and the echo of the settings", body = BusFuelEconomyResponse),
        ProblemResponses
    )
)]
pub async fn compute(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<BusFuelEconomyRequest, BusFuelEconomyInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        bus_fuel_economy::run_valid(&input, budget)
    })
    .await
}

/// Envelope, loss map and efficiency map of one traction motor on a speed × torque grid.
///
/// Any motor model of `POST /v1/bus-fuel-economy`; speeds 0..n_max, torques at multiples of the
/// step covering ±T_max(0). Points outside the envelope are null. For an IPMSM the loss split
/// (DC copper, AC copper increment, iron, mechanical), the dq currents and the operating mode
/// are returned with `include_components`.
#[utoipa::path(
    post,
    path = "/v1/bus-fuel-economy/motor-map",
    tag = "bus-fuel-economy",
    operation_id = "compute_bus_motor_map",
    request_body = MotorMapRequest,
    responses(
        (status = 200, description = "Envelope, loss and efficiency maps of the motor", body = MotorMapResponse),
        ProblemResponses
    )
)]
pub async fn motor_map(
    State(state): State<AppState>,
    Valid { input, limit, .. }: Valid<MotorMapRequest, MotorMapInput>,
) -> Result<Response, ApiError> {
    run_calc(&state, limit, move |budget| {
        bus_fuel_economy::run_motor_map_valid(&input, budget)
    })
    .await
}
