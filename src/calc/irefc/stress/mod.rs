//! `POST /v1/irefc-stress`: element forces and Hertz contact stresses of one IREFC design, or the paper's
//! "structured array" sweep over Z2 × χ (× rb × r2). Spec `irefc_stress.md`; paper
//! `irefc-force-stress.txt` (Mathematics 2023, 11, 993, eqs 12–18).

pub mod compute;
pub mod input;
pub mod output;
pub mod wire;

use std::time::Instant;

use compute::{GridTrig, compute_design, compute_sweep};
use input::{StressInput, StressJob};
use wire::{IrefcStressRequest, IrefcStressResponse};

use crate::calc::CalcFailure;
use crate::calc::common::Shard;
use crate::numerics::Budget;

/// Validate, compute and build the response of `POST /v1/irefc-stress` (run on the blocking pool).
///
/// # Errors
/// `BAD_RANGE`/`MISSING_FIELD` (every offending field), `GRID_TOO_FINE`, `SWEEP_TOO_LARGE`, and for mode
/// "single" `UNDERCUT`/`ELEMENT_OVERLAP`, `NON_FINITE` (absurd scales) or `DEADLINE`. Infeasible sweep
/// combinations are records with `valid: false`, not errors. `shard` (mode "sweep" only) runs one
/// block of the combinations; `RESPONSE_TOO_LARGE` (before computing) when the estimated answer
/// exceeds the service's response limit.
pub fn run_stress(
    req: IrefcStressRequest,
    budget: &Budget,
) -> Result<IrefcStressResponse, CalcFailure> {
    crate::calc::rules::check(&req)?;
    run_valid(&StressJob::try_from(req)?, budget)
}

/// Compute and respond for a request that passed the door (the per-field rules, then
/// [`StressJob::try_from`]).
///
/// # Errors
/// `RESPONSE_TOO_LARGE` before computing; `UNDERCUT`/`ELEMENT_OVERLAP`/`NON_FINITE`/`DEADLINE`
/// of a single design.
pub fn run_valid(job: &StressJob, budget: &Budget) -> Result<IrefcStressResponse, CalcFailure> {
    match &job.input {
        StressInput::Single(s) => {
            output::single_size(s).check(budget)?;
            let t0 = Instant::now();
            let r = compute_design(
                &s.design,
                &s.params,
                GridTrig::OnTheFly,
                s.curves_stride,
                Some(budget),
            )?;
            let resp = output::respond_single(s, &r, t0)?;
            Ok(IrefcStressResponse::Single(Box::new(resp)))
        }
        StressInput::Sweep(s) => {
            let shard = job.shard.unwrap_or(Shard::WHOLE);
            output::sweep_size(s, shard).check(budget)?;
            let items = shard.range(s.len());
            let t0 = Instant::now();
            let offset = items.start;
            let res = compute_sweep(s, items, budget);
            let shard_out = job.shard.map(|_| shard.out(s.len()));
            Ok(IrefcStressResponse::Sweep(output::respond_sweep(
                s, offset, &res, shard_out, t0,
            )))
        }
    }
}
