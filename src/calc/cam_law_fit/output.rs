//! The one place that builds the wire response of `POST /v1/fit-cam-law` from the fitted law:
//! the objective and optimizer report, the optional outputs the request asked for (omitted
//! otherwise), warning codes and the echoed unit labels.

use super::compute::{ChannelErrors as Errors, FitOutput};
use super::input::{FitInput, MetricKind};
use super::wire::{
    ChannelErrors, Classification, ErrorTable, FitCamLawResponse, MetricName, ObjectiveOut,
    OptimizerReport,
};
use crate::calc::cam_law::output::warnings;
use crate::calc::cam_law::wire::Curves;
use crate::numerics::Budget;

fn error_table([s, v, a]: [Option<Errors>; 3]) -> ErrorTable {
    let wire = |e: Option<Errors>| {
        e.map(|e| ChannelErrors {
            euclidean: e.euclidean,
            dtw: e.dtw,
        })
    };
    ErrorTable {
        displacement: wire(s),
        velocity: wire(v),
        acceleration: wire(a),
    }
}

/// Builds the response (`wall_ms` from the budget's clock).
#[must_use]
pub fn respond(input: &FitInput, out: FitOutput, budget: &Budget) -> FitCamLawResponse {
    let objective = &input.objective;
    let dtw = objective.metric == MetricKind::Dtw;
    FitCamLawResponse {
        coefficients: out.coefficients,
        durations: out.durations,
        knots: out.knots,
        peaks: out.peaks,
        acceleration_jumps: out.jumps,
        objective: ObjectiveOut {
            metric: if dtw {
                MetricName::Dtw
            } else {
                MetricName::Euclidean
            },
            quantity: objective.on,
            dtw_window: dtw.then_some(objective.dtw_window as u64),
            initial: out.objective.initial,
            final_value: out.objective.final_value,
        },
        error_table: out.error_table.map(error_table),
        classification: out
            .classification
            .map(|(nearest, max_coef_diff)| Classification {
                nearest,
                max_coef_diff,
            }),
        curves: out.curves.map(Curves::from),
        history: out.history,
        optimizer_report: OptimizerReport {
            method: input.settings.method,
            seed: input.settings.seed,
            evaluations: out.stats.evaluations,
            iterations: out.stats.iterations,
            cpu_ms: out.stats.cpu_ms,
            wall_ms: budget.elapsed_ms(),
            stop_reason: out.stats.stop,
            starts_used: out.stats.starts_used,
            snapped_segments: out.stats.snapped,
        },
        warnings: warnings(&out.warnings),
        units: input.units.clone(),
    }
}
