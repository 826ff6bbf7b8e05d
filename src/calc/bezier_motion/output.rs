//! The one place that builds the response of `POST /v1/bezier-motion-law`.

use std::f64::consts::TAU;

use super::compute::{BezierOutput, BezierWarning, FactorResult, GAMMA_WARN, Residual};
use super::history::History;
use super::input::BezierInput;
use super::optimize::Objective;
use super::plant::{EndStateMethod, Plant};
use super::shaper::{Comparison, Shaper};
use super::wire::{
    BezierMotionResponse, BezierRowOut, EndState, FactorEnergyOut, HistoryOut, ImpulseOut,
    KinematicsOut, LawOut, MethodOut, ObjectiveIn, OptimizerOut, ReferenceOut, ResidualOut,
    SensitivityRow, ShaperComparisonOut, ShaperRowOut, SystemOut,
};
use crate::calc::common::{ResponseSize, Warning};
use crate::numerics::{Budget, SolverReport, StopReason};

/// Upper estimate of the answer's size from the validated request (checked before computing):
/// fixed fields and the law's polygons (8 arrays of at most 2m + p + 2 ordinates), the time
/// history (10 series per sample) and the sensitivity rows (5 numbers and their names each).
#[must_use]
pub fn response_size(input: &BezierInput) -> ResponseSize {
    let ordinates = (2 * input.m + input.p + 2) as u64;
    let mut size = ResponseSize::fixed(16 * 1024 + 8 * 25 * ordinates);
    if let Some(h) = &input.history {
        size = size
            .numbers("/outputs/time_history/n_samples", 10 * h.n_samples as u64)
            .numbers("/outputs/time_history/n_after", 10 * h.n_after as u64);
    }
    if let Some(f) = &input.sensitivity {
        size = size.bytes(
            "/outputs/sensitivity/stiffness_factors",
            f.len() as u64 * (5 * 25 + 100),
        );
    }
    if let Some(s) = &input.shapers {
        // Per row: 5 numbers and 3 impulses with their names; per factor and row (and the law's
        // row): 2 numbers and their names.
        let rows = s.shapers.len() as u64;
        let factors = input.sensitivity.as_ref().map_or(0, Vec::len) as u64;
        size = size.bytes(
            "/outputs/shaper_comparison",
            512 + rows * 600 + (rows + 1) * factors * (2 * 25 + 30),
        );
    }
    size
}

/// Builds the response.
#[must_use]
pub fn respond(input: &BezierInput, out: &BezierOutput, budget: &Budget) -> BezierMotionResponse {
    let plant = &input.plant;
    let law = &out.law;
    let phi = input.phi;
    let steps = out
        .history
        .as_ref()
        .map_or(0, |h| (h.substeps * h.t.len()) as u64);
    BezierMotionResponse {
        mode: input.mode,
        system: system_out(plant, input.t),
        method: method_out(out),
        law: LawOut {
            gamma_rad: out.gamma.clone(),
            gamma_over_phi: out.gamma.iter().map(|g| g / phi).collect(),
            s_rad: law.s.clone(),
            v_rad_s: law.v.clone(),
            a_rad_s2: law.a.clone(),
            j_rad_s3: law.j.clone(),
            degree: law.degree() as u64,
        },
        residual: residual_out(plant, &out.residual),
        reference: out.optimizer.as_ref().map(|o| ReferenceOut {
            gamma_rad: o.reference_gamma.clone(),
            residual: residual_out(plant, &o.reference),
        }),
        optimizer: out.optimizer.as_ref().map(|o| {
            let e = out.residual.energy;
            let e_ref = o.reference.energy;
            let gmax = out.gamma.iter().fold(0.0_f64, |m, g| m.max(g.abs())) / phi.abs();
            let finite = |x: f64| x.is_finite().then_some(x);
            OptimizerOut {
                objective: match o.objective {
                    Objective::MinDeviation => ObjectiveIn::MinDeviation,
                    Objective::MinAccelL2 => ObjectiveIn::MinAccelL2,
                    Objective::MinJerkL2 => ObjectiveIn::MinJerkL2,
                },
                n_constraints: o.n_constraints as u64,
                rank: o.rank as u64,
                free_dimensions: input.p.saturating_sub(o.rank) as u64,
                exact_zero: o.rank == o.n_constraints,
                energy_ratio_to_reference: (e_ref > 0.0).then(|| e / e_ref).and_then(finite),
                reduction_db: (e_ref > 0.0)
                    .then(|| 10.0 * (e_ref / e.max(out.residual.floor)).log10())
                    .and_then(finite),
                max_abs_gamma_over_phi: gmax,
            }
        }),
        robust: out
            .robust
            .as_ref()
            .map(|r| r.iter().map(factor_row).collect()),
        kinematics: out.kinematics.map(|k| KinematicsOut {
            peak_velocity_rad_s: k.peak_velocity.0,
            t_peak_velocity_s: k.peak_velocity.1,
            peak_accel_rad_s2: k.peak_accel.0,
            t_peak_accel_s: k.peak_accel.1,
            peak_jerk_rad_s3: k.peak_jerk.0,
            t_peak_jerk_s: k.peak_jerk.1,
            min_velocity_rad_s: k.min_velocity.0,
            t_min_velocity_s: k.min_velocity.1,
            motion_reversal: k.motion_reversal,
            hull_velocity_rad_s: k.hull[0],
            hull_accel_rad_s2: k.hull[1],
            hull_jerk_rad_s3: k.hull[2],
        }),
        sensitivity: out
            .sensitivity
            .as_ref()
            .map(|r| r.iter().map(factor_row).collect()),
        time_history: out
            .history
            .as_ref()
            .filter(|h| !h.t.is_empty())
            .map(|h| history_out(h, input.t)),
        shaper_comparison: out.shapers.as_ref().map(comparison_out),
        warnings: out.warnings.iter().map(warning_out).collect(),
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations: out.matrices,
            evaluations: out.matrices + steps,
            elapsed_ms: budget.elapsed_ms(),
        },
    }
}

/// Derived system quantities (spec §3.1).
#[must_use]
pub fn system_out(plant: &Plant, t: f64) -> SystemOut {
    let wd = plant.omega_d();
    let (slow, fast) = plant.pole_magnitudes();
    SystemOut {
        j_eq_kgm2: plant.j_eq,
        omega_n_rad_s: plant.wn,
        xi: plant.xi,
        omega_d_rad_s: wd,
        f_n_hz: plant.wn / TAU,
        eta: wd
            .map(|wd| {
                let r = plant.z / wd;
                0.5 * plant.j_eq * r * r
            })
            .filter(|x| x.is_finite()),
        periods_in_move: plant.wn * t / TAU,
        rho_min: t * slow,
        rho_max: t * fast,
    }
}

fn method_out(out: &BezierOutput) -> MethodOut {
    let (end_state, panels, nodes) = match out.h.method {
        EndStateMethod::ClosedFormIbp => (EndState::ClosedFormIbp, None, None),
        EndStateMethod::GaussLegendre { panels, nodes } => (
            EndState::GaussLegendre,
            Some(panels as u64),
            Some(nodes as u64),
        ),
        EndStateMethod::Modal { panels, nodes } => (
            EndState::ModalClosedForm,
            (panels > 0).then_some(panels as u64),
            (nodes > 0).then_some(nodes as u64),
        ),
    };
    MethodOut {
        end_state,
        ibp_ratio: out.h.ratio,
        panels,
        nodes,
    }
}

fn residual_out(plant: &Plant, r: &Residual) -> ResidualOut {
    let finite = |x: f64| x.is_finite().then_some(x);
    ResidualOut {
        psi_t_rad: r.x[0],
        dpsi_t_rad_s: r.x[1],
        e_t_j: r.energy,
        q: r.q.and_then(finite),
        residual_amplitude_rad: r.amplitude.and_then(finite),
        residual_accel_envelope_rad_s2: r
            .amplitude
            .map(|a| plant.wn * (plant.wn * a))
            .and_then(finite),
        e_floor_j: r.floor,
        at_numerical_floor: r.energy <= r.floor,
    }
}

fn factor_row(f: &FactorResult) -> SensitivityRow {
    SensitivityRow {
        stiffness_factor: f.factor,
        omega_n_rad_s: f.plant.wn,
        xi: f.plant.xi,
        e_t_j: f.residual.energy,
        residual_amplitude_rad: f.residual.amplitude.filter(|x| x.is_finite()),
    }
}

fn history_out(h: &History, t_end: f64) -> HistoryOut {
    let peak = |v: &[f64], during: bool| {
        h.t.iter()
            .zip(v)
            .filter(|(t, _)| (**t <= t_end) == during)
            .fold(0.0_f64, |m, (_, x)| m.max(x.abs()))
    };
    HistoryOut {
        t_s: h.t.clone(),
        phi_rad: h.phi.clone(),
        dphi_rad_s: h.dphi.clone(),
        ddphi_rad_s2: h.ddphi.clone(),
        alpha_rad: h.alpha.clone(),
        beta_rad: h.beta.clone(),
        dbeta_rad_s: h.dbeta.clone(),
        ddbeta_rad_s2: h.ddbeta.clone(),
        psi_rad: h.psi.clone(),
        joint_torque_nm: h.torque.clone(),
        peak_joint_torque_move_nm: peak(&h.torque, true),
        peak_ddbeta_move_rad_s2: peak(&h.ddbeta, true),
        peak_ddbeta_after_rad_s2: peak(&h.ddbeta, false),
        substeps_per_sample: h.substeps as u64,
        nodes_per_substep: h.nodes as u64,
    }
}

/// The wire form of a domain warning: the spec's code, a message naming the quantity and value,
/// and the request field it is about.
#[must_use]
pub fn warning_out(w: &BezierWarning) -> Warning {
    match *w {
        BezierWarning::RobustIgnored => Warning::at(
            "ROBUST_IGNORED",
            "/optimize/robust_stiffness_rel",
            "robust_stiffness_rel applies to mode = optimize; ignored in simulate",
        ),
        BezierWarning::LeastSquaresCompromise {
            rank,
            n_constraints,
            p,
        } => Warning::new(
            "LEAST_SQUARES_COMPROMISE",
            format!(
                "only {rank} of {n_constraints} zero-vibration conditions can be met (p = {p}): \
                 the law is the least-squares compromise, not exactly vibration-free"
            ),
        ),
        BezierWarning::FragilePolygon { gamma_over_phi } => Warning::new(
            "FRAGILE_POLYGON",
            format!(
                "max |γ|/|Phi| = {gamma_over_phi:.4e} > {GAMMA_WARN}: a strongly oscillating \
                 control polygon (numerically fragile even though the curve is smooth)"
            ),
        ),
        BezierWarning::MotionReversal => Warning::new(
            "MOTION_REVERSAL",
            "the motor velocity changes sign during the move (the law reverses)",
        ),
        BezierWarning::VelocityPolygonNegative => Warning::new(
            "VELOCITY_POLYGON_NEGATIVE",
            "the velocity control polygon has an ordinate against the direction of motion; the \
             curve itself does not reverse",
        ),
        BezierWarning::NotOscillatory { xi } => Warning::new(
            "NOT_OSCILLATORY",
            format!(
                "ξ = {xi:.6} ≥ 1: the joint does not oscillate; ωd, η, Q and amplitude outputs are \
                 omitted"
            ),
        ),
        BezierWarning::ShaperNotOscillatory { xi } => Warning::at(
            "SHAPER_COMPARISON_NOT_OSCILLATORY",
            "/outputs/shaper_comparison",
            format!(
                "ξ = {xi:.6} ≥ 1: the drive has no damped period to design input shapers for; the \
                 shaper comparison is omitted"
            ),
        ),
        BezierWarning::ShaperTooLong {
            index,
            shaper,
            t_last,
            t,
        } => Warning::at(
            "SHAPER_TOO_LONG",
            format!("/outputs/shaper_comparison/shapers/{index}"),
            format!(
                "the {} shaper's last impulse is at {t_last:.6e} s ≥ T = {t:.6e} s: no time is left \
                 for the baseline move (T0 ≤ 0); its row is null",
                shaper_name(shaper)
            ),
        ),
    }
}

/// The request's name of a shaper.
fn shaper_name(s: Shaper) -> &'static str {
    match s {
        Shaper::None => "none",
        Shaper::Zv => "zv",
        Shaper::Zvd => "zvd",
        Shaper::Ei => "ei",
    }
}

fn factor_energies(s: Option<&Vec<(f64, f64)>>) -> Option<Vec<FactorEnergyOut>> {
    s.map(|v| {
        v.iter()
            .map(|&(factor, e_t_j)| FactorEnergyOut { factor, e_t_j })
            .collect()
    })
}

fn comparison_out(c: &Comparison) -> ShaperComparisonOut {
    ShaperComparisonOut {
        baseline: c.spec.baseline,
        ei_tolerance: c.spec.ei_tolerance,
        damped_period_s: c.td,
        rows: c
            .rows
            .iter()
            .map(|r| {
                r.as_ref().map(|r| ShaperRowOut {
                    shaper: r.shaper,
                    baseline_time_s: r.motion.t0,
                    e_t_j: r.energy,
                    peak_accel_rad_s2: r.peak_accel,
                    peak_vel_rad_s: r.peak_vel,
                    impulses: r
                        .motion
                        .impulses
                        .iter()
                        .map(|i| ImpulseOut {
                            t_s: i.t,
                            amplitude: i.amplitude,
                        })
                        .collect(),
                    sensitivity: factor_energies(r.sensitivity.as_ref()),
                })
            })
            .collect(),
        bezier: BezierRowOut {
            e_t_j: c.law.energy,
            peak_accel_rad_s2: c.law.peak_accel,
            peak_vel_rad_s: c.law.peak_vel,
            sensitivity: factor_energies(c.law.sensitivity.as_ref()),
        },
    }
}
