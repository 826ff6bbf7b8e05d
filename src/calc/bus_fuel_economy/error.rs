//! Failures of the bus fuel-economy computation (after validation).

use crate::calc::{CalcFailure, CrossRule};

/// Why a validated request could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BusFuelEconomyError {
    /// The time budget ran out.
    #[error("time budget exhausted after {elapsed_ms:.0} ms")]
    Deadline {
        /// Elapsed time \[ms\].
        elapsed_ms: f64,
    },
    /// An ipmsm cannot produce torque at a speed the cycle needs (finite maximum speed,
    /// ψ_m/L_d > I_pk, spec §8 item 5).
    #[error(
        "motor '{motor}' has no torque left at {rpm:.1} rpm needed by cycle '{cycle}' (voltage limit; reachable up to about {limit_rpm:.1} rpm)"
    )]
    SpeedUnreachable {
        /// Index of the motor in the request.
        motor_index: usize,
        /// Motor id.
        motor: String,
        /// Cycle name.
        cycle: String,
        /// Speed needed \[rpm\].
        rpm: f64,
        /// Highest speed with positive torque found \[rpm\].
        limit_rpm: f64,
    },
    /// The operating-point histogram would have too many bins.
    #[error("op_histogram would have {bins} bins (limit {limit}); use wider bins")]
    HistogramTooLarge {
        /// Bins requested.
        bins: f64,
        /// Limit.
        limit: f64,
    },
    /// A motor map would have too many grid points.
    #[error(
        "the map of motor '{motor}' would have {points} grid points (limit {limit}); use a coarser loss_map_grid"
    )]
    MapTooLarge {
        /// Motor id.
        motor: String,
        /// Points requested.
        points: f64,
        /// Limit.
        limit: f64,
    },
}

/// The simulation finishes within the request's time budget.
pub const DEADLINE_RULE: CrossRule = CrossRule::too_large(
    "DEADLINE_EXCEEDED",
    &["/time_limit_ms"],
    "The simulation finishes within the request's time_limit_ms (capped by the service).",
);
/// Every ipmsm produces torque at every speed a cycle needs.
pub const SPEED_UNREACHABLE_RULE: CrossRule = CrossRule::infeasible(
    "MOTOR_SPEED_UNREACHABLE",
    &["/motors/*/n_max_rpm", "/cycles"],
    "Each ipmsm motor has torque left (voltage limit) at the top motor speed of every cycle.",
);
/// The operating-point histogram stays within its bin limit.
pub const HISTOGRAM_TOO_LARGE_RULE: CrossRule = CrossRule::too_large(
    "HISTOGRAM_TOO_LARGE",
    &["/options/op_histogram"],
    "The op_histogram's speed × torque bins over the motors' ranges stay within the service's bin limit.",
);
/// A motor map stays within its grid-point limit.
pub const MAP_TOO_LARGE_RULE: CrossRule = CrossRule::too_large(
    "MAP_TOO_LARGE",
    &["/options/loss_map_grid", "/grid"],
    "A motor's loss or efficiency map on the grid steps stays within the service's grid-point limit.",
);

impl From<BusFuelEconomyError> for CalcFailure {
    fn from(e: BusFuelEconomyError) -> Self {
        let detail = e.to_string();
        match e {
            BusFuelEconomyError::Deadline { .. } => DEADLINE_RULE.fail_general(detail),
            BusFuelEconomyError::SpeedUnreachable { motor_index, .. } => {
                SPEED_UNREACHABLE_RULE.fail(format!("/motors/{motor_index}/n_max_rpm"), detail)
            }
            BusFuelEconomyError::HistogramTooLarge { .. } => {
                HISTOGRAM_TOO_LARGE_RULE.fail("/options/op_histogram", detail)
            }
            BusFuelEconomyError::MapTooLarge { .. } => {
                MAP_TOO_LARGE_RULE.fail("/options/loss_map_grid", detail)
            }
        }
    }
}
