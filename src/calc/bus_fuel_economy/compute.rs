//! Orchestration: motor evaluators, one simulation per motor × cycle, histograms, maps and the
//! comparison (spec §5-§6).

use std::collections::HashMap;

use super::compare::{desirability, overall_desirability};
use super::cycles::{Cycle, discretise};
use super::error::BusFuelEconomyError;
use super::input::{BusFuelEconomyInput, MotorEval, OutputKind};
use super::ipmsm::{Currents, Ipmsm, LossSplit, rad_s_to_rpm, rpm_to_rad_s};
use super::motor::{
    IpmsmMap, MotorEvaluator, MotorInput, MotorKind, build_ipmsm_map, grid_axes, grid_size,
};
use super::sim::{SimOutcome, SimSettings, simulate};
use crate::calc::common::Shard;
use crate::numerics::Budget;

/// Most points of one motor map (keeps map building within ~1 s and the response bounded).
pub const MAX_MAP_POINTS: f64 = 250_000.0;
/// Most bins of one operating-point histogram (bounds the response size).
pub const MAX_HIST_BINS: f64 = 100_000.0;
/// Torque tolerance of "inside the envelope" in maps [N·m].
const MAP_ENVELOPE_TOL: f64 = 1e-9;
/// Bisection steps locating the highest speed with torque left (error message only).
const LIMIT_BISECT_ITERS: usize = 50;

/// One motor × cycle result in domain form.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// Motor index.
    pub motor: usize,
    /// Cycle index.
    pub cycle: usize,
    /// The simulation outcome.
    pub sim: SimOutcome,
    /// Trace distance (of the cycle, not achieved) \[m\].
    pub trace_distance_m: f64,
    /// Duration \[s\].
    pub duration_s: f64,
    /// Highest trace speed [m/s].
    pub max_trace_speed: f64,
    /// Histogram (if requested).
    pub histogram: Option<Histogram>,
}

/// Operating-point histogram.
#[derive(Debug, Clone)]
pub struct Histogram {
    /// Speed edges \[rpm\].
    pub speed_edges: Vec<f64>,
    /// Torque edges [N·m].
    pub torque_edges: Vec<f64>,
    /// share[speed bin][torque bin].
    pub share: Vec<Vec<f64>>,
    /// (speed bin, torque bin, share) of the modal bin.
    pub modal: Option<(usize, usize, f64)>,
}

/// ipmsm loss split and currents per grid point (None outside the envelope).
pub type PartsGrid = Vec<Vec<Option<(LossSplit, Currents)>>>;

/// A motor map on a grid.
#[derive(Debug, Clone)]
pub struct MapData {
    /// Speeds \[rpm\].
    pub speed_rpm: Vec<f64>,
    /// Speeds [rad/s].
    pub speed: Vec<f64>,
    /// Torques [N·m].
    pub torque: Vec<f64>,
    /// T_max at the speeds [N·m].
    pub t_max: Vec<f64>,
    /// Loss \[W\] (None outside the envelope).
    pub loss: Vec<Vec<Option<f64>>>,
    /// Efficiency (None outside the envelope; 0 at zero power).
    pub eff: Vec<Vec<Option<f64>>>,
    /// ipmsm loss split, currents and mode (if requested).
    pub parts: Option<PartsGrid>,
    /// Grid points that needed the envelope fallback.
    pub fallbacks: u64,
    /// Model evaluations.
    pub evaluations: u64,
}

/// Comparison of motors.
#[derive(Debug, Clone)]
pub struct ComparisonData {
    /// fe_change\[motor\]\[cycle\] [%] (None where an FE is undefined); index 0 is the reference.
    pub fe_change_pct: Vec<Vec<Option<f64>>>,
    /// d\[motor\]\[cycle\].
    pub d: Vec<Vec<f64>>,
    /// Overall D per motor.
    pub overall: Vec<f64>,
}

/// Everything [`compute`] produces.
#[derive(Debug, Clone)]
pub struct BusFuelEconomyOutput {
    /// Results, motor-major.
    pub results: Vec<RunResult>,
    /// Motor warnings (conversion, map fallbacks), per motor.
    pub motor_warnings: Vec<Vec<String>>,
    /// Efficiency maps (if requested) with their motor's index: every motor, or with a shard
    /// the motors whose first cycle is in the shard's block.
    pub maps: Option<Vec<(usize, MapData)>>,
    /// Comparison (≥ 2 motors).
    pub comparison: Option<ComparisonData>,
    /// Intervals simulated.
    pub intervals: u64,
    /// Motor-model evaluations.
    pub evaluations: u64,
}

/// FE [km/kWh] from distance \[m\] and energy \[J\]; None when E ≤ 0 (spec §8 item 9).
#[must_use]
pub fn fuel_economy(distance_m: f64, e_in_j: f64) -> Option<f64> {
    (e_in_j > 0.0).then(|| (distance_m / 1000.0) / (e_in_j / 3.6e6))
}

/// Highest speed ≤ `w_hi` with positive torque left (for the error message).
fn reachable_limit(m: &Ipmsm, w_hi: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, w_hi);
    for _ in 0..LIMIT_BISECT_ITERS {
        let mid = 0.5 * (lo + hi);
        if m.t_max(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Largest envelope torque of a motor (top of the map torque axis).
pub(crate) fn t_top(m: &MotorInput) -> f64 {
    match &m.kind {
        MotorKind::Constant { envelope, .. } | MotorKind::Map { envelope, .. } => envelope.peak(),
        MotorKind::Ipmsm(im) => im.t_max(0.0),
    }
}

/// Build the envelope / loss / efficiency map of one motor on a grid (direct evaluation).
///
/// # Errors
/// [`BusFuelEconomyError::MapTooLarge`] above [`MAX_MAP_POINTS`], [`BusFuelEconomyError::Deadline`].
pub fn motor_map(
    m: &MotorInput,
    grid: (f64, f64),
    with_parts: bool,
    budget: &Budget,
) -> Result<MapData, BusFuelEconomyError> {
    let top = t_top(m);
    let points = grid_size(m.n_max_rpm, top, grid.0, grid.1);
    if points > MAX_MAP_POINTS {
        return Err(BusFuelEconomyError::MapTooLarge {
            motor: m.id.clone(),
            points,
            limit: MAX_MAP_POINTS,
        });
    }
    let (speed_rpm, torque) = grid_axes(m.n_max_rpm, top, grid.0, grid.1);
    let speed: Vec<f64> = speed_rpm.iter().map(|&n| rpm_to_rad_s(n)).collect();
    let mut ev = evaluator_direct(m);
    let mut data = MapData {
        speed_rpm,
        speed: speed.clone(),
        torque: torque.clone(),
        t_max: Vec::with_capacity(speed.len()),
        loss: Vec::with_capacity(speed.len()),
        eff: Vec::with_capacity(speed.len()),
        parts: with_parts.then(Vec::new),
        fallbacks: 0,
        evaluations: 0,
    };
    for &w in &speed {
        if budget.expired() {
            return Err(BusFuelEconomyError::Deadline {
                elapsed_ms: budget.elapsed_ms(),
            });
        }
        let tm = ev.t_max(w);
        data.t_max.push(tm);
        let mut lrow = Vec::with_capacity(torque.len());
        let mut erow = Vec::with_capacity(torque.len());
        let mut prow = Vec::with_capacity(torque.len());
        for &t in &torque {
            if t.abs() > tm + MAP_ENVELOPE_TOL {
                lrow.push(None);
                erow.push(None);
                prow.push(None);
                continue;
            }
            data.evaluations += 1;
            let (loss, part) = match &m.kind {
                MotorKind::Ipmsm(im) => {
                    let (s, c, fb) = im.evaluate(w, t, tm);
                    data.fallbacks += u64::from(fb);
                    (s.total, Some((s, c)))
                }
                _ => (ev.loss(w, t, t, tm, false).loss, None),
            };
            let p = (t * w).abs();
            lrow.push(Some(loss));
            erow.push(Some(if p > 0.0 { p / (p + loss) } else { 0.0 }));
            prow.push(part);
        }
        data.loss.push(lrow);
        data.eff.push(erow);
        if let Some(parts) = data.parts.as_mut() {
            parts.push(prow);
        }
    }
    Ok(data)
}

/// Direct evaluator of a motor (no precomputed map).
fn evaluator_direct(m: &MotorInput) -> MotorEvaluator<'_> {
    match &m.kind {
        MotorKind::Constant { eta, envelope } => MotorEvaluator::Constant {
            eta: *eta,
            envelope,
            omega_max: m.omega_max,
        },
        MotorKind::Map { loss, envelope } => MotorEvaluator::Map {
            loss,
            envelope,
            omega_max: m.omega_max,
        },
        MotorKind::Ipmsm(im) => MotorEvaluator::IpmsmDirect {
            motor: im,
            cache: HashMap::new(),
        },
    }
}

/// Operating-point histogram of moving intervals (time-weighted).
fn histogram(
    samples: &[(f64, f64, f64)],
    bins: (f64, f64),
) -> Result<Histogram, BusFuelEconomyError> {
    let (bn, bt) = bins;
    let max_rpm = samples
        .iter()
        .map(|s| rad_s_to_rpm(s.0))
        .fold(0.0, f64::max);
    let t_lo_data = samples.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
    let t_hi_data = samples
        .iter()
        .map(|s| s.1)
        .fold(f64::NEG_INFINITY, f64::max);
    let (t_lo_data, t_hi_data) = if t_lo_data.is_finite() {
        (t_lo_data, t_hi_data)
    } else {
        (0.0, 0.0)
    };
    let ns_f = (max_rpm / bn).floor() + 1.0;
    let t_lo = (t_lo_data / bt).floor() * bt;
    let nt_f = ((t_hi_data - t_lo) / bt).floor() + 1.0;
    let bins_total = ns_f * nt_f;
    if !bins_total.is_finite() || bins_total > MAX_HIST_BINS {
        return Err(BusFuelEconomyError::HistogramTooLarge {
            bins: bins_total,
            limit: MAX_HIST_BINS,
        });
    }
    // Both counts are ≥ 1 and their product ≤ MAX_HIST_BINS, so the conversions are exact.
    let (ns, nt) = (ns_f as usize, nt_f as usize);
    let mut share = vec![vec![0.0; nt]; ns];
    let total: f64 = samples.iter().map(|s| s.2).sum();
    for &(w, t, dt) in samples {
        let i = ((rad_s_to_rpm(w) / bn).floor().max(0.0) as usize).min(ns - 1);
        let j = (((t - t_lo) / bt).floor().max(0.0) as usize).min(nt - 1);
        share[i][j] += dt;
    }
    let mut modal: Option<(usize, usize, f64)> = None;
    for (i, row) in share.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            if total > 0.0 {
                *x /= total;
            }
            if *x > 0.0 && modal.is_none_or(|(_, _, s)| *x > s) {
                modal = Some((i, j, *x));
            }
        }
    }
    let speed_edges = (0..=ns).map(|i| i as f64 * bn).collect();
    let torque_edges = (0..=nt).map(|j| (j as f64).mul_add(bt, t_lo)).collect();
    Ok(Histogram {
        speed_edges,
        torque_edges,
        share,
        modal,
    })
}

/// Run every motor over every cycle (with `input.shard`: only the shard's block of the
/// motor × cycle pairs, motor-major; the comparison, which needs every pair, is then omitted).
///
/// # Errors
/// Deadline, unreachable speed of an ipmsm (checked for every motor, also in a shard),
/// oversized map or histogram.
pub fn compute(
    input: &BusFuelEconomyInput,
    budget: &Budget,
) -> Result<BusFuelEconomyOutput, BusFuelEconomyError> {
    let n_c = input.cycles.len();
    let pairs = input
        .shard
        .unwrap_or(Shard::WHOLE)
        .range(input.motors.len() * n_c);
    let o = &input.options;
    let intervals: Vec<Vec<_>> = input
        .cycles
        .iter()
        .map(|c| discretise(c, o.k(), input.grade))
        .collect();
    let settings = SimSettings {
        mode: o.mode,
        convention: o.power_convention,
        regen: o.regen,
        regen_limit: o.regen_limit,
        inverter_eff: input.inverter_eff,
        breakdown: o.has(OutputKind::LossBreakdown),
        histogram: o.has(OutputKind::OpHistogram),
        traces: o.has(OutputKind::Traces),
    };
    let mut results = Vec::with_capacity(input.motors.len() * input.cycles.len());
    let mut motor_warnings = Vec::with_capacity(input.motors.len());
    let mut maps = o.has(OutputKind::EfficiencyMap).then(Vec::new);
    let (mut n_iv, mut n_eval) = (0u64, 0u64);
    for (mi, m) in input.motors.iter().enumerate() {
        let mut warnings = m.warnings.clone();
        check_reachable(input, mi, m)?;
        let mine = (mi * n_c).max(pairs.start)..((mi + 1) * n_c).min(pairs.end);
        if mine.is_empty() {
            motor_warnings.push(warnings);
            continue;
        }
        let ipmsm_map: Option<IpmsmMap> = match (&m.kind, o.eval()) {
            (MotorKind::Ipmsm(im), MotorEval::LossMap) => {
                let map = ipmsm_loss_map(m, im, o.loss_map_grid.steps(), budget)?;
                n_eval += map.evaluations;
                if map.fallbacks > 0 {
                    warnings.push(format!(
                        "{} loss-map grid points could not be solved inside the envelope; the envelope point's loss was used there",
                        map.fallbacks
                    ));
                }
                Some(map)
            }
            _ => None,
        };
        let cycles_of_shard = input
            .cycles
            .iter()
            .enumerate()
            .take(mine.end - mi * n_c)
            .skip(mine.start - mi * n_c);
        for (ci, c) in cycles_of_shard {
            let mut ev = match (&ipmsm_map, &m.kind) {
                (Some(map), MotorKind::Ipmsm(im)) => MotorEvaluator::IpmsmMap {
                    map,
                    motor: im,
                    cache: HashMap::new(),
                },
                _ => evaluator_direct(m),
            };
            let sim = simulate(
                &input.vehicle,
                &mut ev,
                &input.battery,
                &intervals[ci],
                &settings,
                budget,
            )?;
            n_iv += sim.n_intervals;
            n_eval += sim.evaluations;
            let histogram = if o.has(OutputKind::OpHistogram) {
                Some(histogram(&sim.hist_samples, o.hist_bins())?)
            } else {
                None
            };
            results.push(run_result(mi, ci, c, sim, histogram));
        }
        if let Some(maps) = maps.as_mut().filter(|_| pairs.contains(&(mi * n_c))) {
            let md = motor_map(m, o.loss_map_grid.steps(), false, budget)?;
            n_eval += md.evaluations;
            maps.push((mi, md));
        }
        motor_warnings.push(warnings);
    }
    let comparison = (input.motors.len() >= 2 && input.shard.is_none()).then(|| {
        let fe: Vec<Option<f64>> = results
            .iter()
            .map(|r| fuel_economy(r.sim.distance_m, r.sim.e_in))
            .collect();
        // f_i = energy drawn over cycle i [kWh].
        let energy: Vec<f64> = results.iter().map(|r| r.sim.e_in / 3.6e6).collect();
        compare(&fe, &energy, input.motors.len(), n_c, &input.weights)
    });
    Ok(BusFuelEconomyOutput {
        results,
        motor_warnings,
        maps,
        comparison,
        intervals: n_iv,
        evaluations: n_eval,
    })
}

/// An ipmsm must have torque left at every speed the cycles need (spec §8 item 5).
fn check_reachable(
    input: &BusFuelEconomyInput,
    mi: usize,
    m: &MotorInput,
) -> Result<(), BusFuelEconomyError> {
    if let MotorKind::Ipmsm(im) = &m.kind {
        for c in &input.cycles {
            let w_need = input.vehicle.motor_speed(c.max_speed_mps());
            if im.t_max(w_need) <= 0.0 {
                return Err(BusFuelEconomyError::SpeedUnreachable {
                    motor_index: mi,
                    motor: m.id.clone(),
                    cycle: c.name.clone(),
                    rpm: rad_s_to_rpm(w_need),
                    limit_rpm: rad_s_to_rpm(reachable_limit(im, w_need)),
                });
            }
        }
    }
    Ok(())
}

/// The precomputed loss map of an ipmsm evaluated with `motor_eval = loss_map`, on `grid`
/// (speed, torque steps), refused above [`MAX_MAP_POINTS`].
fn ipmsm_loss_map(
    m: &MotorInput,
    im: &Ipmsm,
    grid: (f64, f64),
    budget: &Budget,
) -> Result<IpmsmMap, BusFuelEconomyError> {
    let points = grid_size(m.n_max_rpm, im.t_max(0.0), grid.0, grid.1);
    if points > MAX_MAP_POINTS {
        return Err(BusFuelEconomyError::MapTooLarge {
            motor: m.id.clone(),
            points,
            limit: MAX_MAP_POINTS,
        });
    }
    build_ipmsm_map(im, m.n_max_rpm, grid.0, grid.1, budget).ok_or(BusFuelEconomyError::Deadline {
        elapsed_ms: budget.elapsed_ms(),
    })
}

fn run_result(
    motor: usize,
    cycle: usize,
    c: &Cycle,
    sim: SimOutcome,
    histogram: Option<Histogram>,
) -> RunResult {
    RunResult {
        motor,
        cycle,
        sim,
        trace_distance_m: c.distance_m(),
        duration_s: c.duration_s(),
        max_trace_speed: c.max_speed_mps(),
        histogram,
    }
}

/// FE change relative to the first motor and desirability per cycle (spec §5.7), from the fuel
/// economy [km/kWh] and the energy drawn \[kWh\] of every motor × cycle pair (motor-major) — the
/// `fe_km_per_kwh` and `energy_in_kwh` of the results, so that merged shards can recompute it.
#[must_use]
pub fn compare(
    fe_all: &[Option<f64>],
    energy_all: &[f64],
    n_m: usize,
    n_c: usize,
    weights: &[f64],
) -> ComparisonData {
    let fe = |m: usize, c: usize| fe_all.get(m * n_c + c).copied().flatten();
    let fe_change_pct = (0..n_m)
        .map(|m| {
            (0..n_c)
                .map(|c| fe(m, c).zip(fe(0, c)).map(|(a, b)| (a / b - 1.0) * 100.0))
                .collect()
        })
        .collect();
    let energy = |m: usize, c: usize| energy_all.get(m * n_c + c).copied().unwrap_or(0.0);
    let mut d = vec![vec![0.0; n_c]; n_m];
    for c in 0..n_c {
        let f_min = (0..n_m).map(|m| energy(m, c)).fold(f64::INFINITY, f64::min);
        let f_max = (0..n_m)
            .map(|m| energy(m, c))
            .fold(f64::NEG_INFINITY, f64::max);
        for (m, row) in d.iter_mut().enumerate() {
            row[c] = desirability(energy(m, c), f_min, f_max);
        }
    }
    let overall = d
        .iter()
        .map(|row| overall_desirability(row, weights))
        .collect();
    ComparisonData {
        fe_change_pct,
        d,
        overall,
    }
}
