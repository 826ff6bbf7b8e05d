//! `POST /v1/irefc-efficiency`: slip speeds, friction power and mesh efficiency of an IREFC gear driven by its
//! carrier with the crown fixed and the cam as output. Spec `irefc_efficiency.md`; paper
//! `irefc-efficiency.txt` (Mathematics 2024, 12, 873, eqs 7–23). Element forces come from
//! [`super::stress::compute::element_forces`] (the force paper's rigid load sharing), geometry from
//! [`super::geometry`].

pub mod compute;
pub mod input;
pub mod output;
pub mod wire;

use std::time::Instant;

use input::EfficiencyInput;
use wire::{IrefcEfficiencyRequest, IrefcEfficiencyResponse};

use crate::calc::CalcFailure;
use crate::numerics::Budget;

/// Configuration label of the response.
pub const CONFIGURATION: &str = "carrier_in/crown_fixed/cam_out";

/// Validate, compute and build the response of `POST /v1/irefc-efficiency`.
///
/// # Errors
/// `BAD_RANGE`/`MISSING_FIELD`/`AMBIGUOUS_LOAD` (every offending field), `UNDERCUT`/`ELEMENT_OVERLAP`,
/// `NON_FINITE` (absurd scales), `DEADLINE` (phase average longer than the budget).
pub fn run_efficiency(
    req: IrefcEfficiencyRequest,
    budget: &Budget,
) -> Result<IrefcEfficiencyResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&EfficiencyInput::try_from(req)?, budget)
}

/// Compute and respond for a request that passed the door (the per-field rules, then
/// [`EfficiencyInput::try_from`]).
///
/// # Errors
/// `NON_FINITE` / `DEADLINE` from the calculation.
pub fn run_valid(
    input: &EfficiencyInput,
    budget: &Budget,
) -> Result<IrefcEfficiencyResponse, CalcFailure> {
    let t0 = Instant::now();
    let out = compute::compute(input, budget)?;
    output::respond(input, &out, t0).map_err(CalcFailure::from)
}
