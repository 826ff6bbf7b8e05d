//! Backward-facing longitudinal simulation of one motor over one cycle (spec §5.1-5.6).

// Plain products instead of `mul_add`: without FMA hardware in the target (the default x86-64
// baseline) `mul_add` is a libm call, ~10x slower in these per-interval loops, and plain
// arithmetic follows the rounding of the spec's reference implementation.

use super::battery::{Battery, EcmState};
use super::cycles::Interval;
use super::error::BusFuelEconomyError;
use super::motor::MotorEvaluator;
use crate::numerics::Budget;

/// The envelope policy: the request's `mode`.
pub use super::wire::Mode;

/// The power convention: the request's `power_convention`.
pub use super::wire::PowerConvention;

/// Torque margin above T_max before an interval counts as over the envelope (spec §5.4).
pub const OVER_ENVELOPE_TOL: f64 = 1e-9;
/// Below this |P_m| the paper convention charges nothing (0/0 efficiency, spec §8 item 1) \[W\].
pub const ZERO_POWER_W: f64 = 1e-9;
/// Convergence of the forward-mode end speed (spec §5.4) [m/s].
pub const FORWARD_TOL: f64 = 1e-10;
/// Iteration cap of the forward-mode fixed point (spec §5.4).
pub const FORWARD_MAX_ITERS: usize = 50;
/// Intervals between two deadline checks.
const BUDGET_STRIDE: usize = 4096;

/// Vehicle in SI units (spec §3.1).
#[derive(Debug, Clone, Copy)]
pub struct Vehicle {
    /// Total mass m \[kg\].
    pub mass: f64,
    /// Effective (inertial) mass m(1+δ) \[kg\].
    pub mass_eff: f64,
    /// g [m/s²].
    pub gravity: f64,
    /// f_R.
    pub rolling: f64,
    /// ½ ρ C_d A_F [kg/m].
    pub aero: f64,
    /// Wheel radius r \[m\].
    pub wheel_radius: f64,
    /// Gear ratio i_g.
    pub gear_ratio: f64,
    /// Gear efficiency η_T.
    pub gear_eff: f64,
    /// Auxiliary power \[W\].
    pub aux_w: f64,
}

impl Vehicle {
    /// Road resistance F_roll + F_aero + F_grade at mean speed v̄ on slope `grade` (eq. 4) \[N\].
    #[must_use]
    pub fn resistance(&self, vbar: f64, grade: f64) -> f64 {
        let sec = grade.hypot(1.0);
        let (cos_t, sin_t) = (1.0 / sec, grade / sec);
        let mg = self.mass * self.gravity;
        let f_roll = if vbar > 0.0 {
            mg * self.rolling * cos_t
        } else {
            0.0
        };
        f_roll + self.aero * vbar * vbar + mg * sin_t
    }

    /// Motor speed ω_m = v̄ i_g / r [rad/s].
    #[must_use]
    pub fn motor_speed(&self, v: f64) -> f64 {
        v * self.gear_ratio / self.wheel_radius
    }

    /// Motor torque from the wheel force (eq. 5 and its braking branch) [N·m].
    #[must_use]
    pub fn motor_torque(&self, force: f64) -> f64 {
        let tw = force * self.wheel_radius;
        if tw >= 0.0 {
            tw / (self.gear_eff * self.gear_ratio)
        } else {
            tw * self.gear_eff / self.gear_ratio
        }
    }
}

/// Settings of one simulation.
#[derive(Debug, Clone, Copy)]
pub struct SimSettings {
    /// Envelope policy.
    pub mode: Mode,
    /// Power convention.
    pub convention: PowerConvention,
    /// Regeneration allowed.
    pub regen: bool,
    /// Regeneration limited by the envelope.
    pub regen_limit: bool,
    /// η_Inv.
    pub inverter_eff: f64,
    /// Collect the loss breakdown.
    pub breakdown: bool,
    /// Collect the (speed, torque, Δt) samples of moving intervals for the histogram.
    pub histogram: bool,
    /// Collect per-interval traces.
    pub traces: bool,
}

/// Neumaier-compensated sum (spec §8 item 10).
#[derive(Debug, Clone, Copy, Default)]
pub struct Kahan {
    sum: f64,
    c: f64,
}

impl Kahan {
    /// Add a term.
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.c += (self.sum - t) + x;
        } else {
            self.c += (x - t) + self.sum;
        }
        self.sum = t;
    }

    /// The compensated sum.
    #[must_use]
    pub fn value(&self) -> f64 {
        self.sum + self.c
    }
}

/// Energy sums of the loss breakdown \[J\].
#[derive(Debug, Clone, Copy, Default)]
pub struct BreakdownSums {
    /// Delivered wheel energy.
    pub wheel: Kahan,
    /// Gear loss.
    pub gear: Kahan,
    /// Motor loss as charged by the convention.
    pub motor_charged: Kahan,
    /// Motor model loss.
    pub motor_model: Kahan,
    /// DC copper, extra AC copper, iron, mech.
    pub parts: [Kahan; 4],
    /// Inverter loss.
    pub inverter: Kahan,
    /// Battery loss.
    pub battery: Kahan,
    /// Aux energy.
    pub aux: Kahan,
    /// Wheel traction dropped by `clip`.
    pub clipped: Kahan,
    /// Σ|P_m|Δt.
    pub abs_pm: Kahan,
    /// Σ(|P_m| + P_loss)Δt.
    pub abs_pm_loss: Kahan,
}

/// Per-interval traces.
#[derive(Debug, Clone, Default)]
pub struct TraceData {
    /// Interval start \[s\].
    pub t: Vec<f64>,
    /// v̄ [m/s].
    pub v: Vec<f64>,
    /// ω_m [rad/s].
    pub omega: Vec<f64>,
    /// T_M demand [N·m].
    pub t_demand: Vec<f64>,
    /// Delivered motor torque [N·m].
    pub t_motor: Vec<f64>,
    /// P_m \[W\].
    pub p_m: Vec<f64>,
    /// P_loss \[W\].
    pub p_loss: Vec<f64>,
    /// P_in \[W\].
    pub p_in: Vec<f64>,
}

/// Outcome of one motor over one cycle.
#[derive(Debug, Clone, Default)]
pub struct SimOutcome {
    /// Distance (achieved) \[m\].
    pub distance_m: f64,
    /// Net battery energy E_in \[J\].
    pub e_in: f64,
    /// Σ positive P_in Δt \[J\].
    pub e_pos: f64,
    /// Σ negative P_in Δt \[J\].
    pub e_neg: f64,
    /// Friction-brake energy at the wheel \[J\].
    pub brake: f64,
    /// Intervals.
    pub n_intervals: u64,
    /// Motoring demand over the envelope.
    pub n_over: u64,
    /// Generating torque limited to −T_max.
    pub n_regen_limited: u64,
    /// ipmsm envelope fallbacks.
    pub n_fallback: u64,
    /// Moving intervals whose loss was evaluated at the torque clamped to ±T_max (map and ipmsm
    /// models beyond the envelope).
    pub n_loss_clamped: u64,
    /// Forward fixed point not converged in 50 iterations.
    pub n_forward_unconverged: u64,
    /// Largest motor torque demand [N·m].
    pub max_t_demand: f64,
    /// Largest (achieved) sample speed [m/s].
    pub max_speed: f64,
    /// Final SOC (ecm).
    pub ecm: Option<EcmState>,
    /// Loss breakdown sums.
    pub sums: BreakdownSums,
    /// (motor speed [rad/s], torque demand [N·m], Δt \[s\]) of moving intervals.
    pub hist_samples: Vec<(f64, f64, f64)>,
    /// Traces.
    pub traces: Option<TraceData>,
    /// Motor-model evaluations.
    pub evaluations: u64,
}

/// Simulate one motor over the intervals of one cycle.
///
/// # Errors
/// [`BusFuelEconomyError::Deadline`] when the budget runs out.
#[expect(
    clippy::too_many_lines,
    reason = "one pass over the intervals of spec §5.1-§5.6 (demand, envelope policy, regeneration, motor loss, power chain, battery, compensated sums, traces): each interval's quantities feed the next step and the Kahan sums, so splitting would scatter the chain"
)]
pub fn simulate(
    veh: &Vehicle,
    motor: &mut MotorEvaluator<'_>,
    battery: &Battery,
    intervals: &[Interval],
    set: &SimSettings,
    budget: &Budget,
) -> Result<SimOutcome, BusFuelEconomyError> {
    let mut out = SimOutcome {
        n_intervals: intervals.len() as u64,
        ..SimOutcome::default()
    };
    let mut traces = set.traces.then(TraceData::default);
    let mut ecm_state = match battery {
        Battery::Ecm(e) => Some(e.initial()),
        Battery::Constant { .. } => None,
    };
    let (mut dist, mut e_in, mut e_pos, mut e_neg, mut brake) = (
        Kahan::default(),
        Kahan::default(),
        Kahan::default(),
        Kahan::default(),
        Kahan::default(),
    );
    let mut u = intervals.first().map_or(0.0, |iv| iv.v0);
    out.max_speed = u;
    let mut max_t = f64::NEG_INFINITY;
    for (j, iv) in intervals.iter().enumerate() {
        if j % BUDGET_STRIDE == BUDGET_STRIDE - 1 && budget.expired() {
            return Err(BusFuelEconomyError::Deadline {
                elapsed_ms: budget.elapsed_ms(),
            });
        }
        let dt = iv.dt;
        // Start speed: the trace, or the achieved speed in forward mode.
        let v_start = if set.mode == Mode::Forward { u } else { iv.v0 };
        let mut v_end = iv.v1;
        let mut vbar = 0.5 * (v_start + v_end);
        let accel = (v_end - v_start) / dt;
        let moving = vbar > 0.0;
        let mut w = veh.motor_speed(vbar);
        // At rest the brakes hold the bus and the drive is idle.
        let t_demand = if moving {
            veh.motor_torque(veh.resistance(vbar, iv.grade) + veh.mass_eff * accel)
        } else {
            0.0
        };
        max_t = max_t.max(t_demand);
        let mut t_max = motor.t_max(w);
        let over = t_demand > t_max + OVER_ENVELOPE_TOL;
        let mut t_mot = t_demand;
        if over {
            out.n_over += 1;
            match set.mode {
                Mode::Backward => {}
                Mode::Clip => t_mot = t_max,
                Mode::Forward => {
                    // Fixed point on the achieved end speed with the motor at its envelope.
                    let mut ue = iv.v1;
                    let mut converged = false;
                    for _ in 0..FORWARD_MAX_ITERS {
                        let vb = 0.5 * (v_start + ue);
                        let tm = motor.t_max(veh.motor_speed(vb));
                        let fw = tm * veh.gear_eff * veh.gear_ratio / veh.wheel_radius;
                        let a = (fw - veh.resistance(vb, iv.grade)) / veh.mass_eff;
                        let un = (v_start + a * dt).max(0.0);
                        let du = (un - ue).abs();
                        ue = un;
                        if du < FORWARD_TOL {
                            converged = true;
                            break;
                        }
                    }
                    if !converged {
                        out.n_forward_unconverged += 1;
                    }
                    v_end = ue.min(iv.v1);
                    vbar = 0.5 * (v_start + v_end);
                    w = veh.motor_speed(vbar);
                    t_max = motor.t_max(w);
                    t_mot = if vbar > 0.0 { t_max } else { 0.0 };
                }
            }
        }
        // Regeneration and friction brakes (spec §5.4).
        let mut t_del = t_mot;
        if t_mot < 0.0 {
            if !set.regen {
                t_del = 0.0;
            } else if set.regen_limit && t_mot < -t_max {
                t_del = -t_max;
                out.n_regen_limited += 1;
            }
        }
        let p_brake = if t_mot < 0.0 {
            -(t_mot - t_del) * w / veh.gear_eff
        } else {
            0.0
        };
        brake.add(p_brake * dt);
        // Motor loss (spec §5.4/5.5): maps and ipmsm at the torque clamped to the envelope,
        // the constant model at the delivered torque.
        let t_eval = t_del.clamp(-t_max, t_max);
        let le = if vbar > 0.0 {
            out.evaluations += 1;
            if t_del.abs() > t_max && motor.clamps_beyond_envelope() {
                out.n_loss_clamped += 1;
            }
            motor.loss(w, t_del, t_eval, t_max, set.breakdown)
        } else {
            super::motor::LossEval::default()
        };
        out.n_fallback += u64::from(le.fallback);
        let p_m = t_del * w;
        let p_el = match set.convention {
            PowerConvention::Loss => p_m + le.loss,
            PowerConvention::Paper => {
                if p_m.abs() < ZERO_POWER_W {
                    0.0
                } else {
                    // η = |P_m|/(|P_m| + P_loss) with the delivered P_m and the loss at the clamp
                    // (spec §5.5): beyond the envelope this charges P_m + P_loss(T_max).
                    let eta = le
                        .eta_const
                        .unwrap_or_else(|| p_m.abs() / (p_m.abs() + le.loss));
                    if p_m > 0.0 { p_m / eta } else { p_m * eta }
                }
            }
        };
        let p_dc_drive = if p_el >= 0.0 {
            p_el / set.inverter_eff
        } else {
            p_el * set.inverter_eff
        };
        let p_dc = p_dc_drive + veh.aux_w;
        let p_in = match battery {
            Battery::Constant { eta } => {
                if p_dc >= 0.0 {
                    p_dc / eta
                } else {
                    p_dc * eta
                }
            }
            Battery::Ecm(e) => match ecm_state.as_mut() {
                Some(st) => e.step(st, p_dc, dt),
                None => p_dc,
            },
        };
        e_in.add(p_in * dt);
        if p_in >= 0.0 {
            e_pos.add(p_in * dt);
        } else {
            e_neg.add(p_in * dt);
        }
        if set.mode == Mode::Clip && t_demand > t_mot {
            out.sums
                .clipped
                .add((t_demand - t_mot) * w * veh.gear_eff * dt);
        }
        dist.add(vbar * dt);
        u = v_end;
        out.max_speed = out.max_speed.max(v_end);
        if set.breakdown {
            let s = &mut out.sums;
            if t_mot >= 0.0 {
                let p_shaft = t_mot * w;
                s.wheel.add(p_shaft * veh.gear_eff * dt);
                s.gear.add(p_shaft * (1.0 - veh.gear_eff) * dt);
            } else {
                s.wheel.add(t_mot * w / veh.gear_eff * dt);
                s.gear
                    .add((t_del * w).abs() * (1.0 / veh.gear_eff - 1.0) * dt);
            }
            s.motor_charged.add((p_el - p_m) * dt);
            s.motor_model.add(le.loss * dt);
            if let Some(parts) = le.parts {
                for (k, v) in parts.into_iter().enumerate() {
                    s.parts[k].add(v * dt);
                }
            }
            s.inverter.add((p_dc_drive - p_el) * dt);
            s.battery.add((p_in - p_dc) * dt);
            s.aux.add(veh.aux_w * dt);
            s.abs_pm.add(p_m.abs() * dt);
            s.abs_pm_loss.add((p_m.abs() + le.loss) * dt);
        }
        if set.histogram && vbar > 0.0 {
            out.hist_samples.push((w, t_demand, dt));
        }
        if let Some(tr) = traces.as_mut() {
            tr.t.push(iv.t0);
            tr.v.push(vbar);
            tr.omega.push(w);
            tr.t_demand.push(t_demand);
            tr.t_motor.push(t_del);
            tr.p_m.push(p_m);
            tr.p_loss.push(le.loss);
            tr.p_in.push(p_in);
        }
    }
    out.distance_m = dist.value();
    out.e_in = e_in.value();
    out.e_pos = e_pos.value();
    out.e_neg = e_neg.value();
    out.brake = brake.value();
    out.max_t_demand = if max_t.is_finite() { max_t } else { 0.0 };
    out.ecm = ecm_state;
    out.traces = traces;
    Ok(out)
}
