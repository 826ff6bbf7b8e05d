//! Motor models behind one evaluation interface (spec §5.5): envelope T_max(ω) and loss at an
//! operating point, for constant-efficiency, loss-map and parametric IPMSM motors (directly or
//! through a precomputed loss map).

use std::collections::HashMap;

use super::ipmsm::{Ipmsm, LossSplit, rad_s_to_rpm, rpm_to_rad_s};
use super::maps::{Envelope, Grid2};
use crate::numerics::Budget;

/// A validated motor (SI units).
#[derive(Debug, Clone)]
pub struct MotorInput {
    /// Motor id.
    pub id: String,
    /// Model.
    pub kind: MotorKind,
    /// Highest admissible speed [rad/s] (n_max; for maps also the last map speed).
    pub omega_max: f64,
    /// The same in rpm.
    pub n_max_rpm: f64,
    /// Warnings from the input conversion (efficiency → loss map, ...).
    pub warnings: Vec<String>,
}

/// Motor model.
#[derive(Debug, Clone)]
pub enum MotorKind {
    /// Constant efficiency η_M with an envelope.
    Constant {
        /// η_M.
        eta: f64,
        /// Envelope.
        envelope: Envelope,
    },
    /// Loss map (given, or converted from an efficiency map) with an envelope.
    Map {
        /// Total loss \[W\].
        loss: Grid2,
        /// Envelope.
        envelope: Envelope,
    },
    /// Parametric IPMSM.
    Ipmsm(Box<Ipmsm>),
}

/// Loss at one evaluated operating point.
#[derive(Debug, Clone, Copy, Default)]
pub struct LossEval {
    /// Total motor loss P_loss \[W\].
    pub loss: f64,
    /// Constant efficiency of a `constant` motor (used directly by the paper convention).
    pub eta_const: Option<f64>,
    /// DC copper, extra AC copper, iron, mechanical \[W\] (ipmsm only).
    pub parts: Option<[f64; 4]>,
    /// The ipmsm operating point could not be solved and the envelope point was used.
    pub fallback: bool,
}

fn parts_of(s: &LossSplit) -> [f64; 4] {
    [s.cu_dc, s.cu_ac_extra(), s.iron, s.mech]
}

/// A precomputed ipmsm loss map (total and the four parts) with its envelope on the grid speeds.
#[derive(Debug, Clone)]
pub struct IpmsmMap {
    /// Total loss \[W\].
    pub total: Grid2,
    /// DC copper, extra AC copper, iron, mechanical loss maps \[W\].
    pub parts: [Grid2; 4],
    /// Envelope at the grid speeds (linear in between); informational: the simulation evaluates
    /// T_max exactly per distinct speed, as the spec's reference does.
    pub envelope: Envelope,
    /// Grid points that needed the envelope fallback.
    pub fallbacks: u64,
    /// Model evaluations spent on the map.
    pub evaluations: u64,
}

/// Grid axes of a map: speeds 0, Δn, 2Δn, … plus n_max itself \[rpm\]; torques ±kΔT covering
/// ±t_top [N·m].
#[must_use]
pub fn grid_axes(
    n_max_rpm: f64,
    t_top: f64,
    speed_step_rpm: f64,
    torque_step: f64,
) -> (Vec<f64>, Vec<f64>) {
    let mut speed = Vec::new();
    let mut k = 0.0;
    loop {
        let n = k * speed_step_rpm;
        // Points within 1e-9 of n_max are merged with it.
        if n >= n_max_rpm * (1.0 - 1e-9) {
            break;
        }
        speed.push(n);
        k += 1.0;
    }
    speed.push(n_max_rpm);
    let kt = (t_top / torque_step).ceil().max(1.0);
    let mut torque = Vec::new();
    let mut j = -kt;
    while j <= kt {
        torque.push(j * torque_step);
        j += 1.0;
    }
    (speed, torque)
}

/// Number of grid points of [`grid_axes`] without building it.
#[must_use]
pub fn grid_size(n_max_rpm: f64, t_top: f64, speed_step_rpm: f64, torque_step: f64) -> f64 {
    ((n_max_rpm / speed_step_rpm).ceil() + 1.0)
        * 2.0f64.mul_add((t_top / torque_step).ceil().max(1.0), 1.0)
}

/// Build the ipmsm loss map of §5.5/§9: at every grid point the loss at the torque clamped to
/// ±T_max(n) (so cells straddling the envelope interpolate towards the envelope losses).
/// `None` if the budget ran out.
#[must_use]
pub fn build_ipmsm_map(
    m: &Ipmsm,
    n_max_rpm: f64,
    speed_step_rpm: f64,
    torque_step: f64,
    budget: &Budget,
) -> Option<IpmsmMap> {
    let t_top = m.t_max(0.0);
    let (speed_rpm, torque) = grid_axes(n_max_rpm, t_top, speed_step_rpm, torque_step);
    let speed: Vec<f64> = speed_rpm.iter().map(|&n| rpm_to_rad_s(n)).collect();
    let nt = torque.len();
    let mut total = Vec::with_capacity(speed.len() * nt);
    let mut parts: [Vec<f64>; 4] = Default::default();
    let mut t_env = Vec::with_capacity(speed.len());
    let mut fallbacks = 0u64;
    let mut evaluations = 0u64;
    for &w in &speed {
        if budget.expired() {
            return None;
        }
        let tm = m.t_max(w);
        t_env.push(tm);
        // Clamped points repeat the same torque: evaluate each distinct clamp once.
        let mut last: Option<(f64, LossSplit)> = None;
        for &t in &torque {
            let tc = t.clamp(-tm, tm);
            let split = match last {
                Some((tl, s)) if (tl - tc).abs() <= 0.0 => s,
                _ => {
                    let (s, _, fb) = m.evaluate(w, tc, tm);
                    evaluations += 1;
                    fallbacks += u64::from(fb);
                    s
                }
            };
            last = Some((tc, split));
            total.push(split.total);
            for (k, v) in parts_of(&split).into_iter().enumerate() {
                parts[k].push(v);
            }
        }
    }
    let mk = |values: Vec<f64>| Grid2 {
        speed: speed.clone(),
        torque: torque.clone(),
        values,
    };
    let [p0, p1, p2, p3] = parts;
    Some(IpmsmMap {
        total: mk(total),
        parts: [mk(p0), mk(p1), mk(p2), mk(p3)],
        envelope: Envelope::Table {
            speed: speed.clone(),
            t_max: t_env,
        },
        fallbacks,
        evaluations,
    })
}

/// Evaluation interface of the simulation: T_max(ω) and the loss at a clamped torque.
#[derive(Debug)]
pub enum MotorEvaluator<'a> {
    /// Constant η.
    Constant {
        /// η_M.
        eta: f64,
        /// Envelope.
        envelope: &'a Envelope,
        /// n_max [rad/s].
        omega_max: f64,
    },
    /// Loss map.
    Map {
        /// Loss map.
        loss: &'a Grid2,
        /// Envelope.
        envelope: &'a Envelope,
        /// Admissible speed [rad/s].
        omega_max: f64,
    },
    /// ipmsm evaluated at every interval (T_max cached per distinct speed).
    IpmsmDirect {
        /// The motor.
        motor: &'a Ipmsm,
        /// T_max per speed (key: f64 bits).
        cache: HashMap<u64, f64>,
    },
    /// ipmsm through its precomputed loss map; T_max still evaluated exactly (cached per
    /// distinct speed), as the spec's reference implementation does.
    IpmsmMap {
        /// The map.
        map: &'a IpmsmMap,
        /// The motor (for T_max).
        motor: &'a Ipmsm,
        /// T_max per speed (key: f64 bits).
        cache: HashMap<u64, f64>,
    },
}

impl MotorEvaluator<'_> {
    /// Whether the loss is evaluated at the torque clamped to the envelope beyond it (maps and
    /// ipmsm), rather than at the delivered torque (constant efficiency).
    pub const fn clamps_beyond_envelope(&self) -> bool {
        !matches!(self, Self::Constant { .. })
    }

    /// T_max(ω) [N·m] (0 above the admissible speed).
    pub fn t_max(&mut self, w: f64) -> f64 {
        match self {
            Self::Constant {
                envelope,
                omega_max,
                ..
            }
            | Self::Map {
                envelope,
                omega_max,
                ..
            } => {
                if w > *omega_max {
                    0.0
                } else {
                    envelope.t_max(w)
                }
            }
            Self::IpmsmDirect { motor, cache } | Self::IpmsmMap { motor, cache, .. } => {
                *cache.entry(w.to_bits()).or_insert_with(|| motor.t_max(w))
            }
        }
    }

    /// Loss at speed ω for the delivered torque `t_del`, `t` being it clamped to ±`t_max`
    /// (spec §5.4: losses at the envelope); `want_parts` asks for the ipmsm split.
    ///
    /// The ipmsm loss map is looked up at `t_del` itself (clamped to its torque axis only): its
    /// grid points beyond the envelope already hold the envelope loss of their speed, so the
    /// clamp is applied at the grid points. This is what the spec's reference implementation does
    /// (it reproduces the §10 example and the §9 accuracy table to the printed digits).
    pub fn loss(&mut self, w: f64, t_del: f64, t: f64, t_max: f64, want_parts: bool) -> LossEval {
        match self {
            // The constant model holds at any torque: the delivered one, never the clamp
            // (spec §5.4, "Loss evaluation beyond the envelope").
            Self::Constant { eta, .. } => LossEval {
                loss: (t_del * w).abs() * (1.0 / *eta - 1.0),
                eta_const: Some(*eta),
                ..LossEval::default()
            },
            Self::Map { loss, .. } => LossEval {
                loss: loss.lookup(w, t).max(0.0),
                ..LossEval::default()
            },
            Self::IpmsmDirect { motor, .. } => {
                let (s, _, fallback) = motor.evaluate(w, t, t_max);
                LossEval {
                    loss: s.total,
                    eta_const: None,
                    parts: Some(parts_of(&s)),
                    fallback,
                }
            }
            Self::IpmsmMap { map, .. } => {
                let t = t_del;
                let parts = want_parts.then(|| {
                    let p = &map.parts;
                    [
                        p[0].lookup(w, t),
                        p[1].lookup(w, t),
                        p[2].lookup(w, t),
                        p[3].lookup(w, t),
                    ]
                });
                LossEval {
                    loss: map.total.lookup(w, t).max(0.0),
                    eta_const: None,
                    parts,
                    fallback: false,
                }
            }
        }
    }
}

/// Format a speed for messages.
#[must_use]
pub fn rpm_str(w: f64) -> String {
    format!("{:.1} rpm", rad_s_to_rpm(w))
}
