//! The one place that builds the wire responses of `POST /v1/bus-fuel-economy` (per motor × cycle
//! results, comparison, motor maps, echo, report) and `POST /v1/bus-fuel-economy/motor-map` from
//! the domain output, the merge rule of sharded comparisons, and the estimates of the answers'
//! sizes checked before computing.

use std::collections::BTreeMap;

use super::compute::{
    self, BusFuelEconomyOutput, ComparisonData, Histogram, MapData, RunResult, fuel_economy,
};
use super::cycles;
use super::input::{BusFuelEconomyInput, OutputKind};
use super::ipmsm::{self, rad_s_to_rpm};
use super::motor::{self, MotorInput};
use super::sim::{Mode, SimOutcome};
use super::wire::{
    BusFuelEconomyResponse, Comparison, CycleResult, Desirability, Echo, LossBreakdown,
    LossComponentMaps, ModalBin, MotorMapData, MotorMapResponse, OpHistogram, Traces,
};
use crate::calc::common::ResponseSize;
use crate::numerics::{Budget, SolverReport, StopReason};

/// J → kWh.
const J_PER_KWH: f64 = 3.6e6;

/// Builds the response of the motor-map endpoint from the validated motor and its map.
#[must_use]
pub fn respond_motor_map(m: &MotorInput, data: MapData, budget: &Budget) -> MotorMapResponse {
    let mut warnings = m.warnings.clone();
    if data.fallbacks > 0 {
        warnings.push(format!(
            "{} grid points could not be solved inside the envelope; the envelope point's loss was used there",
            data.fallbacks
        ));
    }
    let components = data.parts.as_ref().map(|parts| {
        type Point = (ipmsm::LossSplit, ipmsm::Currents);
        let pick = |f: &dyn Fn(&Point) -> f64| -> Vec<Vec<Option<f64>>> {
            parts
                .iter()
                .map(|row| row.iter().map(|x| x.as_ref().map(f)).collect())
                .collect()
        };
        LossComponentMaps {
            cu_dc_w: pick(&|x| x.0.cu_dc),
            cu_ac_extra_w: pick(&|x| x.0.cu_ac_extra()),
            iron_w: pick(&|x| x.0.iron),
            mech_w: pick(&|x| x.0.mech),
            i_d_a: pick(&|x| x.1.i_d),
            i_q_a: pick(&|x| x.1.i_q),
            mode: parts
                .iter()
                .map(|row| {
                    row.iter()
                        .map(|x| x.as_ref().map(|x| x.1.mode.as_str().to_owned()))
                        .collect()
                })
                .collect(),
        }
    });
    let evaluations = data.evaluations;
    MotorMapResponse {
        motor: m.id.clone(),
        speed_rpm: data.speed_rpm.clone(),
        torque_nm: data.torque.clone(),
        t_max_nm: data.t_max.clone(),
        loss_w: data.loss,
        efficiency: data.eff,
        components,
        warnings,
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations: u64::try_from(data.speed.len()).unwrap_or(u64::MAX),
            evaluations,
            elapsed_ms: budget.elapsed_ms(),
        },
    }
}

/// Upper estimate of the motor-map answer's size (checked before computing): the map's points on
/// `grid` times the series per point (loss and efficiency, plus 7 component maps with
/// `include_components`).
#[must_use]
pub fn motor_map_size(m: &MotorInput, grid: (f64, f64), include_components: bool) -> ResponseSize {
    let series = if include_components { 9 } else { 2 };
    ResponseSize::fixed(8 * 1024).numbers("/grid", map_points(m, grid).saturating_mul(series))
}

fn kwh(j: f64) -> f64 {
    j / J_PER_KWH
}

fn result_wire(
    input: &BusFuelEconomyInput,
    r: RunResult,
    motor_warnings: &[String],
) -> CycleResult {
    let o = &input.options;
    let s = &r.sim;
    let motor = &input.motors[r.motor];
    let cycle = &input.cycles[r.cycle];
    let fe = fuel_economy(s.distance_m, s.e_in);
    let dist_km = s.distance_m / 1000.0;
    let mut warnings = sim_warnings(o.mode, &r, fe.is_none());
    let (soc_end, flags) = battery_out(s, &mut warnings);
    warnings.extend(motor_warnings.iter().cloned());
    let loss_breakdown = o
        .has(OutputKind::LossBreakdown)
        .then(|| loss_breakdown(motor, s));
    let op_histogram = r.histogram.map(op_histogram);
    let n = s.n_intervals;
    let traces = r.sim.traces.clone().map(|t| Traces {
        t_s: t.t,
        v_mps: t.v,
        omega_rad_s: t.omega,
        torque_demand_nm: t.t_demand,
        torque_motor_nm: t.t_motor,
        p_mech_w: t.p_m,
        p_loss_w: t.p_loss,
        p_in_w: t.p_in,
    });
    CycleResult {
        motor: motor.id.clone(),
        cycle: cycle.name.clone(),
        distance_km: dist_km,
        duration_s: r.duration_s,
        max_speed_kmh: r.max_trace_speed * 3.6,
        n_intervals: n,
        energy_in_kwh: kwh(s.e_in),
        energy_traction_kwh: kwh(s.e_pos),
        energy_regen_kwh: kwh(s.e_neg),
        fe_km_per_kwh: fe,
        consumption_kwh_per_km: if dist_km > 0.0 {
            kwh(s.e_in) / dist_km
        } else {
            0.0
        },
        n_over_envelope: s.n_over,
        // Interval counts are far below 2^53: exact in f64.
        frac_over_envelope: if n > 0 {
            s.n_over as f64 / n as f64
        } else {
            0.0
        },
        n_regen_limited: s.n_regen_limited,
        n_envelope_fallback: s.n_fallback,
        n_loss_clamped: s.n_loss_clamped,
        max_motor_torque_demand_nm: s.max_t_demand,
        max_motor_speed_rpm: rad_s_to_rpm(input.vehicle.motor_speed(s.max_speed)),
        friction_brake_kwh: kwh(s.brake),
        trace_miss_km: (o.mode == Mode::Forward)
            .then(|| (r.trace_distance_m - s.distance_m) / 1000.0),
        battery_soc_end: soc_end,
        battery_flags: flags,
        loss_breakdown,
        op_histogram,
        traces,
        warnings,
    }
}

/// The result's warnings about the simulation, in order: demand over the envelope (worded for
/// the envelope policy `mode`), limited regeneration, envelope fallbacks, unconverged forward
/// intervals and an undefined fuel economy.
fn sim_warnings(mode: Mode, r: &RunResult, fe_undefined: bool) -> Vec<String> {
    let s = &r.sim;
    let mut warnings = Vec::new();
    if s.n_over > 0 {
        warnings.push(match mode {
            Mode::Backward => format!(
                "{} intervals demand more than the motor envelope (mode=backward: trace followed, losses evaluated at the envelope)",
                s.n_over
            ),
            Mode::Clip => format!(
                "{} intervals demand more than the motor envelope (mode=clip: motor torque clipped, {:.6} kWh of wheel traction dropped)",
                s.n_over,
                kwh(s.sums.clipped.value())
            ),
            Mode::Forward => format!(
                "{} intervals demand more than the motor envelope (mode=forward: the bus fell behind, trace miss {:.6} km)",
                s.n_over,
                (r.trace_distance_m - s.distance_m) / 1000.0
            ),
        });
    }
    if s.n_regen_limited > 0 {
        warnings.push(format!(
            "{} braking intervals exceed the motor envelope: generating torque limited to -T_max, the rest goes to the friction brakes",
            s.n_regen_limited
        ));
    }
    if s.n_fallback > 0 {
        warnings.push(format!(
            "{} intervals: the dq operating point could not be solved inside the envelope; the envelope point's loss was used",
            s.n_fallback
        ));
    }
    if s.n_forward_unconverged > 0 {
        warnings.push(format!(
            "{} forward-mode intervals: end speed not converged in 50 iterations; last iterate used",
            s.n_forward_unconverged
        ));
    }
    if fe_undefined {
        warnings.push(
            "net battery energy ≤ 0 (net regeneration): fuel economy undefined (null)".to_owned(),
        );
    }
    warnings
}

/// The battery's end state of charge and flags (ECM battery only), adding their warnings.
fn battery_out(s: &SimOutcome, warnings: &mut Vec<String>) -> (Option<f64>, Option<Vec<String>>) {
    match &s.ecm {
        Some(st) => {
            let mut f = Vec::new();
            if st.n_power_infeasible > 0 {
                f.push("battery_power_infeasible".to_owned());
                warnings.push(format!(
                    "{} intervals demand more power than the battery can deliver (e²/4R0): current clamped",
                    st.n_power_infeasible
                ));
            }
            if st.soc_out_of_range {
                f.push("soc_out_of_range".to_owned());
                warnings.push("battery state of charge left [0, 1]".to_owned());
            }
            (Some(st.soc), Some(f))
        }
        None => (None, None),
    }
}

/// The energy breakdown of one result \[kWh\] (motor loss parts for an IPMSM only).
fn loss_breakdown(motor: &MotorInput, s: &SimOutcome) -> LossBreakdown {
    let b = &s.sums;
    let parts = matches!(motor.kind, motor::MotorKind::Ipmsm(_)).then_some(b.parts);
    let part = |k: usize| parts.map(|p| kwh(p[k].value()));
    let den = b.abs_pm_loss.value();
    LossBreakdown {
        wheel_kwh: kwh(b.wheel.value()),
        gear_kwh: kwh(b.gear.value()),
        friction_brake_kwh: kwh(s.brake),
        motor_charged_kwh: kwh(b.motor_charged.value()),
        motor_model_kwh: kwh(b.motor_model.value()),
        motor_cu_dc_kwh: part(0),
        motor_cu_ac_extra_kwh: part(1),
        motor_iron_kwh: part(2),
        motor_mech_kwh: part(3),
        inverter_kwh: kwh(b.inverter.value()),
        battery_kwh: kwh(b.battery.value()),
        aux_kwh: kwh(b.aux.value()),
        clipped_traction_kwh: kwh(b.clipped.value()),
        mean_motor_efficiency: (den > 0.0).then(|| b.abs_pm.value() / den),
    }
}

/// Wire form of the operating-point histogram.
fn op_histogram(h: Histogram) -> OpHistogram {
    OpHistogram {
        modal_bin: h.modal.map(|(i, j, share)| ModalBin {
            rpm: [h.speed_edges[i], h.speed_edges[i + 1]],
            nm: [h.torque_edges[j], h.torque_edges[j + 1]],
            share,
        }),
        speed_edges_rpm: h.speed_edges,
        torque_edges_nm: h.torque_edges,
        share: h.share,
    }
}

fn map_wire(id: &str, m: MapData) -> MotorMapData {
    MotorMapData {
        motor: id.to_owned(),
        speed_rpm: m.speed_rpm,
        torque_nm: m.torque,
        t_max_nm: m.t_max,
        efficiency: m.eff,
    }
}

/// Points of a motor's map on `grid` (speed × torque axes), saturated.
fn map_points(m: &MotorInput, grid: (f64, f64)) -> u64 {
    let points = motor::grid_size(m.n_max_rpm, compute::t_top(m), grid.0, grid.1);
    // Validated steps give a finite count; a larger map is refused by the computation with
    // its own code (MAP_TOO_LARGE), so the estimate stops at its limit.
    points.clamp(0.0, compute::MAX_MAP_POINTS) as u64
}

/// Bytes of one result's scalar fields, names and warnings at most.
const RESULT_BYTES: u64 = 4096;

/// Upper estimate of the answer's size from the validated request (checked before computing):
/// per motor × cycle a result record, its traces (8 series per simulated interval) and its
/// operating-point histogram (speed bins up to the cycle's top motor speed × torque bins over
/// ± the envelope's top torque, at most `MAX_HIST_BINS`), and per motor its efficiency map.
/// The histogram's torque range is the envelope's: a histogram of torques beyond it (motoring
/// demand over the envelope in `backward` mode) can exceed the estimate and is then caught by
/// the service's check of the encoded answer.
#[must_use]
pub fn response_size(input: &BusFuelEconomyInput) -> ResponseSize {
    let o = &input.options;
    let motors = input.motors.len() as u64;
    let mut size = ResponseSize::fixed(16 * 1024 + motors * 2048)
        .bytes("/motors", motors * input.cycles.len() as u64 * RESULT_BYTES);
    for c in &input.cycles {
        let intervals = (c.time_s.len().saturating_sub(1) * o.k()) as u64;
        if o.has(OutputKind::Traces) {
            size = size.numbers("/options/outputs", motors * 8 * intervals);
        }
        if o.has(OutputKind::OpHistogram) {
            let rpm = rad_s_to_rpm(input.vehicle.motor_speed(c.max_speed_mps()));
            for m in &input.motors {
                let speed_bins = (rpm / o.op_histogram.speed_bin_rpm).floor() + 2.0;
                let torque_bins =
                    2.0 * (compute::t_top(m) / o.op_histogram.torque_bin_nm).ceil() + 3.0;
                let bins = (speed_bins * torque_bins).clamp(0.0, compute::MAX_HIST_BINS) as u64;
                size = size.numbers("/options/op_histogram", bins + 64);
            }
        }
    }
    if o.has(OutputKind::EfficiencyMap) {
        for m in &input.motors {
            size = size.numbers(
                "/options/loss_map_grid",
                map_points(m, o.loss_map_grid.steps()) + 64,
            );
        }
    }
    size
}

/// The wire form of a comparison of motors `ids` over `cycles` (also the merge of sharded
/// answers, `crate::merge`).
pub fn comparison_wire(
    ids: &[String],
    cycles: Vec<String>,
    weights: &[f64],
    c: &ComparisonData,
) -> Comparison {
    let mut fe_change_pct = BTreeMap::new();
    let mut desirability = BTreeMap::new();
    for (mi, id) in ids.iter().enumerate() {
        if mi > 0 {
            let row: BTreeMap<String, Option<f64>> = cycles
                .iter()
                .cloned()
                .zip(c.fe_change_pct[mi].iter().copied())
                .collect();
            fe_change_pct.insert(id.clone(), row);
        }
        desirability.insert(
            id.clone(),
            Desirability {
                d: c.d[mi].clone(),
                overall: c.overall[mi],
            },
        );
    }
    Comparison {
        reference_motor: ids.first().cloned().unwrap_or_default(),
        cycles,
        weights: weights.to_vec(),
        fe_change_pct,
        desirability,
    }
}

/// The comparison of the merged `results` of every shard (motor-major, as in the unsharded
/// answer), with the request's normalised desirability `weights` (one per cycle): the merge
/// rule of sharded answers, equal to the unsharded answer's `comparison`. `None` with fewer
/// than 2 motors, or when `results` is not a full motor × cycle table.
#[must_use]
pub fn merged_comparison(results: &[CycleResult], weights: &[f64]) -> Option<Comparison> {
    let first = results.first()?;
    let n_c = results
        .iter()
        .take_while(|r| r.motor == first.motor)
        .count();
    if n_c == 0 || !results.len().is_multiple_of(n_c) || weights.len() != n_c {
        return None;
    }
    let n_m = results.len() / n_c;
    let ids: Vec<String> = results
        .iter()
        .step_by(n_c)
        .map(|r| r.motor.clone())
        .collect();
    let cycle_names: Vec<String> = results[..n_c].iter().map(|r| r.cycle.clone()).collect();
    let fe: Vec<Option<f64>> = results.iter().map(|r| r.fe_km_per_kwh).collect();
    let energy: Vec<f64> = results.iter().map(|r| r.energy_in_kwh).collect();
    (n_m >= 2).then(|| {
        let c = compute::compare(&fe, &energy, n_m, n_c, weights);
        comparison_wire(&ids, cycle_names, weights, &c)
    })
}

/// Builds the response: results in motor-major order, comparison, motor maps, shard, echo and
/// report.
#[must_use]
pub fn respond(
    input: &BusFuelEconomyInput,
    out: BusFuelEconomyOutput,
    budget: &Budget,
) -> BusFuelEconomyResponse {
    let o = &input.options;
    let ids: Vec<String> = input.motors.iter().map(|m| m.id.clone()).collect();
    let cycle_names: Vec<String> = input.cycles.iter().map(|c| c.name.clone()).collect();
    let comparison = out
        .comparison
        .as_ref()
        .map(|c| comparison_wire(&ids, cycle_names, &input.weights, c));
    let motor_maps = out.maps.map(|maps| {
        maps.into_iter()
            .map(|(mi, m)| map_wire(&input.motors[mi].id, m))
            .collect()
    });
    let results = out
        .results
        .into_iter()
        .map(|r| {
            let w = out.motor_warnings.get(r.motor).cloned().unwrap_or_default();
            result_wire(input, r, &w)
        })
        .collect();
    let pairs = input.motors.len() * input.cycles.len();
    BusFuelEconomyResponse {
        results,
        comparison,
        motor_maps,
        shard: input.shard.map(|s| s.out(pairs)),
        echo: Echo {
            mode: o.mode,
            power_convention: o.power_convention,
            substeps: o.substeps,
            motor_eval: o.eval(),
            regen: o.regen,
            regen_limit: o.regen_limit,
            cycle_data_version: cycles::CYCLE_DATA_VERSION.to_owned(),
        },
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations: out.intervals,
            evaluations: out.evaluations,
            elapsed_ms: budget.elapsed_ms(),
        },
    }
}
