//! The optional time history (spec §3.8): exact transition plus Gauss–Legendre per step on a
//! uniform grid (sub-steps when `h·|p_fast| > 8`), closed-form free vibration after `T`.

use super::law::{BezierLaw, bernstein_horner};
use super::plant::Plant;
use crate::numerics::Budget;
use crate::numerics::quadrature::gauss_legendre;

/// Largest `h_sub·|p_fast|` of one sub-step (spec §3.8).
pub const STEP_RHO: f64 = 8.0;
/// Largest `rho_max` for which a history is computed (total sub-steps ≈ rho_max/8 ≤ 2e5).
pub const RHO_MAX_HISTORY: f64 = 1.6e6;

/// What to sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistorySpec {
    /// Uniform samples on [0, T], both ends included (0: none).
    pub n_samples: usize,
    /// Length of the window after T \[s\].
    pub t_after: f64,
    /// Samples in (T, T + t_after].
    pub n_after: usize,
}

/// Sampled response, one entry per sample in every vector.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct History {
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Motor angle φ \[rad\].
    pub phi: Vec<f64>,
    /// Motor speed φ' [rad/s].
    pub dphi: Vec<f64>,
    /// Motor acceleration φ'' [rad/s²].
    pub ddphi: Vec<f64>,
    /// Rigid-joint output angle α = zφ \[rad\].
    pub alpha: Vec<f64>,
    /// Platform angle β = zφ + ψ \[rad\].
    pub beta: Vec<f64>,
    /// Platform speed β' [rad/s].
    pub dbeta: Vec<f64>,
    /// Platform acceleration β'' [rad/s²].
    pub ddbeta: Vec<f64>,
    /// Platform lag ψ = β − zφ \[rad\].
    pub psi: Vec<f64>,
    /// Joint torque on the platform τ_j = J_eq β'' [N m].
    pub torque: Vec<f64>,
    /// Sub-steps per sample interval.
    pub substeps: usize,
    /// Quadrature nodes per sub-step.
    pub nodes: usize,
}

impl History {
    fn push(&mut self, plant: &Plant, t: f64, k: [f64; 3], x: [f64; 2]) {
        let z = plant.z;
        let dd = -(2.0 * plant.xi * plant.wn * x[1] + plant.wn * (plant.wn * x[0]));
        self.t.push(t);
        self.phi.push(k[0]);
        self.dphi.push(k[1]);
        self.ddphi.push(k[2]);
        self.alpha.push(z * k[0]);
        self.beta.push(z * k[0] + x[0]);
        self.dbeta.push(z * k[1] + x[1]);
        self.ddbeta.push(dd);
        self.psi.push(x[0]);
        self.torque.push(plant.j_eq * dd);
    }
}

/// Sub-steps per interval of length `h`.
#[must_use]
pub fn substeps(plant: &Plant, h: f64) -> usize {
    let rho = h * plant.pole_magnitudes().1;
    // rho ≤ 1.6e6 here: a small whole number.
    (rho / STEP_RHO).ceil().max(1.0) as usize
}

/// The history; `None` when the budget ran out.
#[must_use]
pub fn history(
    plant: &Plant,
    law: &BezierLaw,
    x_end: [f64; 2],
    spec: &HistorySpec,
    budget: &Budget,
) -> Option<History> {
    let mut out = History::default();
    let t_end = law.t;
    let n = law.accel_degree();
    if spec.n_samples > 0 {
        let intervals = spec.n_samples.saturating_sub(1).max(1);
        let h = t_end / intervals as f64;
        let sub = substeps(plant, h);
        let hs = h / sub as f64;
        let q = (n as f64 / 2.0 + 0.75 * hs * plant.pole_magnitudes().1 + 8.0).ceil() as usize;
        out.substeps = sub;
        out.nodes = q;
        let (nodes, weights) = gauss_legendre(q);
        let e = plant.transition(hs);
        let cols: Vec<[f64; 2]> = nodes
            .iter()
            .map(|l| plant.column2(hs * (1.0 - l)))
            .collect();
        let kin = |t: f64| {
            let lam = (t / t_end).clamp(0.0, 1.0);
            [
                bernstein_horner(&law.s, lam),
                bernstein_horner(&law.v, lam),
                bernstein_horner(&law.a, lam),
            ]
        };
        let mut x = [0.0, 0.0];
        out.push(plant, 0.0, kin(0.0), x);
        let mut steps = 0_u64;
        for j in 0..spec.n_samples.saturating_sub(1) {
            for s in 0..sub {
                let t0 = j as f64 * h + s as f64 * hs;
                let mut f = [0.0, 0.0];
                for ((l, w), c) in nodes.iter().zip(&weights).zip(&cols) {
                    let u = bernstein_horner(&law.a, ((t0 + l * hs) / t_end).clamp(0.0, 1.0));
                    f[0] += w * c[0] * u;
                    f[1] += w * c[1] * u;
                }
                let k = -plant.z * hs;
                x = [
                    e[0][0] * x[0] + e[0][1] * x[1] + k * f[0],
                    e[1][0] * x[0] + e[1][1] * x[1] + k * f[1],
                ];
                steps += 1;
                if steps.is_multiple_of(4096) && budget.check(steps).is_some() {
                    return None;
                }
            }
            let t = if j + 2 == spec.n_samples {
                t_end
            } else {
                (j + 1) as f64 * h
            };
            out.push(plant, t, kin(t), x);
        }
    }
    let phi = law.s.last().copied().unwrap_or(0.0);
    for j in 1..=spec.n_after {
        let tau = spec.t_after * j as f64 / spec.n_after as f64;
        let x = plant.propagate(x_end, tau);
        out.push(plant, t_end + tau, [phi, 0.0, 0.0], x);
    }
    Some(out)
}
