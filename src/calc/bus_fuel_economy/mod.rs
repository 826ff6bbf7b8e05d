//! Drive-cycle energy and fuel economy of a battery-electric bus with an AC-copper-loss-aware
//! traction-motor model.
//!
//! Method: the paper "Multi-objective design of an MSO-coil IPMSM for a 12 m electric bus"
//! (`shared/papers/ebus-motor-fuel-economy.txt`: FE = D/E_in over Manhattan, HWFET and HDUDDS,
//! eq. 1-6 and 11-15); spec `shared/specs/bus_fuel_economy.md` with the paper's ambiguities
//! resolved there:
//!
//! * backward-facing longitudinal model on the interval scheme (§5.1) with the inertia term the
//!   paper's eq. 4 omits (ambiguity 1) and the gear loss in both power directions (ambiguity 2);
//! * the envelope policies `backward` (follow the trace, count exceedances), `clip` and `forward`
//!   (trace miss) — never a silent clip (§5.4);
//! * motor models: constant η, user loss map, user efficiency map (converted to losses at its own
//!   grid points before interpolation, §8 item 2) and a parametric dq IPMSM with MTPA / flux
//!   weakening and separate DC copper, extra AC copper (Dowell or table k_AC), iron and mechanical
//!   losses (§5.5), evaluated directly or through a precomputed loss map;
//! * the power chain of eq. 1-3 (`paper` convention) or additive losses, a constant-efficiency or
//!   2RC battery (§5.6), and the comparison of motors with the paper's desirability (§5.7).
//!
//! The three built-in cycles (ADVISOR CYC_MANHATTAN, CYC_HWFET, CYC_UDDSHDV) are embedded in the
//! binary from `data/bus_fuel_economy/`.
//!
//! Conventions: SI inside; motor torque positive when motoring; the bus never reverses. At rest
//! (v̄ = 0) the brakes hold the bus and the drive is idle (no motor torque, no motor loss; the
//! auxiliary load still runs). A custom cycle's `grade` array replaces the vehicle's constant
//! grade; an interval's slope is the mean of its end samples.
//!
//! # Validity and accuracy
//! * Inputs: the ranges of spec §3 (enforced; every violation is reported with its JSON pointer)
//!   plus service limits that keep every number finite: trace speed ≤ 200 m/s, time steps in
//!   [1 ms, 60 s], gear ratio ≥ 0.01, gear / inverter / battery / constant-motor efficiency ≥ 0.01,
//!   efficiency-map values ≥ 1e-6, IPMSM inductances ≤ 1 H and ψ_m ≤ 100 Wb; ≤ 200 000 samples
//!   per cycle, ≤ 10⁶ intervals after sub-stepping, ≤ 250 000 map points, ≤ 100 000 histogram bins.
//! * Achieved error against the spec's reference implementation (tests/it/paper_bus_fuel_economy.rs):
//!   the lossless identity E_in = road-load energy to 1e-9 (V2); every printed reference value
//!   (V2-V5, V9: FE, energies, distances, brake energy, SOC) within 5e-7 relative, i.e. at its
//!   6-digit print; envelope counts exact; the demo IPMSM's envelope, loss points and k_AC (V5)
//!   at their printed digits; the §9 accuracy table and the §10 example to their printed digits.
//! * Discretisation: the default (loss map 250 rpm × 50 N·m, 1 substep) is within 1e-3 of the
//!   fine reference (direct, 16 substeps): −8.6e-4 / +1.2e-4 / +4.5e-4 on Manhattan / HWFET /
//!   HDUDDS; see `benches/RESULTS.md` for the error-vs-time table.
//! * Outside validity: demand above the envelope is counted and reported (never clipped
//!   silently); a cycle above a motor's speed limit, or beyond the speed where an IPMSM has torque
//!   left, is rejected (HTTP 422); net regenerating cycles give `fe_km_per_kwh: null`.
//!
//! # Deviations from the spec's text (each reproduces the spec's own reference numbers)
//! * Paper convention beyond the envelope: η = |P_m| / (|P_m| + P_loss(T_max)) with the delivered
//!   P_m (spec §5.5 literally), i.e. P_el = P_m + P_loss(T_max) when motoring over the envelope.
//! * `loss_map` evaluation of an IPMSM: T_max is still solved exactly per distinct speed, and the
//!   map is looked up at the delivered torque; the map's grid points beyond the envelope hold the
//!   envelope loss of their speed, which is how the clamp of §5.4 enters (§9 table, §10 example).
//! * The Dowell series carries a third term so that series and closed form agree to 1e-10 at
//!   ξ = 0.3 (spec §7.3); with the spec's two terms F2 differs by 3e-10 there.

pub mod ac_factor;
pub mod battery;
pub mod compare;
pub mod compute;
pub mod cycles;
pub mod error;
pub mod input;
pub mod ipmsm;
pub mod maps;
pub mod motor;
pub mod output;
pub mod sim;
pub mod wire;

pub use error::BusFuelEconomyError;
pub use output::merged_comparison;
pub use wire::{BusFuelEconomyRequest, BusFuelEconomyResponse, MotorMapRequest, MotorMapResponse};

use self::compute::{compute, motor_map};
pub use self::input::{BusFuelEconomyInput, MotorMapInput};
use crate::calc::CalcFailure;
use crate::numerics::Budget;

/// What runs in the job of `POST /v1/bus-fuel-economy`, on a request that passed the door: the
/// answer's size, the simulation of every motor over every cycle, the response.
///
/// # Errors
/// The computation's failure (unreachable motor speed, oversized map or histogram or answer,
/// exhausted time budget).
pub fn run_valid(
    input: &BusFuelEconomyInput,
    budget: &Budget,
) -> Result<BusFuelEconomyResponse, CalcFailure> {
    output::response_size(input).check(budget)?;
    let out = compute(input, budget)?;
    Ok(output::respond(input, out, budget))
}

/// `POST /v1/bus-fuel-economy` without HTTP (tests, benchmarks): the per-field rules, the rules
/// between fields, then [`run_valid`].
///
/// # Errors
/// As the endpoint: every offending field with its JSON pointer, or the computation's failure.
pub fn run(
    req: BusFuelEconomyRequest,
    budget: &Budget,
) -> Result<BusFuelEconomyResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&BusFuelEconomyInput::try_from(&req)?, budget)
}

/// What runs in the job of `POST /v1/bus-fuel-economy/motor-map`: the answer's size, the maps.
///
/// # Errors
/// An oversized grid or answer, or an exhausted budget.
pub fn run_motor_map_valid(
    input: &MotorMapInput,
    budget: &Budget,
) -> Result<MotorMapResponse, CalcFailure> {
    let (m, grid) = (&input.motor, input.grid);
    output::motor_map_size(m, grid, input.include_components).check(budget)?;
    let data = motor_map(m, grid, input.include_components, budget).map_err(|e| {
        let mut f = CalcFailure::from(e);
        for issue in &mut f.errors {
            issue.pointer = "/grid".to_owned();
        }
        f
    })?;
    Ok(output::respond_motor_map(m, data, budget))
}

/// `POST /v1/bus-fuel-economy/motor-map` without HTTP: the per-field rules, the motor's rules
/// between fields, then [`run_motor_map_valid`].
///
/// # Errors
/// Every offending field, an oversized grid or an exhausted budget.
pub fn run_motor_map(
    req: MotorMapRequest,
    budget: &Budget,
) -> Result<MotorMapResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_motor_map_valid(&MotorMapInput::try_from(req)?, budget)
}
