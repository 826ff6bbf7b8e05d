//! Forward kinematics: starting points (spec 4.3), post-processing of a solution (forces, moments,
//! stresses, energies, shapes; spec 4.8) and the stability evaluation of a solution (spec 4.5).

use std::f64::consts::PI;

use super::model::{Model, Params};
use super::newton::{self, ContinuationResult, Counter, Failed, NewtonOptions, Solution, Stepping};
use super::stability::{self, RodDisc, Tips};
use crate::numerics::Budget;
use crate::numerics::dense;

/// Least-squares residual above which a design has no stress-free home (spec 4.3: 1e-9 L_ref).
pub const HOME_REL_TOL: f64 = 1e-9;
/// Continuation step length target (spec 4.3: K = max(10, ceil(max |dlambda| / (0.01 L_ref)))).
const CONTINUATION_REL_STEP: f64 = 0.01;
/// Minimum number of continuation steps (spec 4.3).
const MIN_CONTINUATION_STEPS: usize = 10;
/// Stability margins at or below this are unstable (spec 4.5: stable iff margin > 1e-8).
pub const STABLE_MARGIN: f64 = 1e-8;
/// A rod whose chord exceeds this fraction of its length is reported as taut (spec 7).
pub const TAUT_CHORD: f64 = 0.999;

/// The stress-free home of a design: inputs, platform position and the exact home state.
#[derive(Debug, Clone)]
pub struct Home {
    /// Home inputs \[m\].
    pub lambda: Vec<f64>,
    /// Platform position at home \[m\].
    pub position: [f64; 2],
    /// Largest closure residual of the least-squares fit \[m\].
    pub residual: f64,
}

/// Least-squares home (spec 4.3 rule 2): `a_i(lambda) + L_i t_i = p + r_i`, unknowns lambda and p;
/// when `fixed` is given only p is fitted. Returns the fit and its largest residual.
#[must_use]
pub fn home_fit(model: &Model, fixed: Option<&[f64]>) -> Home {
    let d = &model.design;
    let na = d.actuators.len();
    let nr = d.rods.len();
    let nunk = if fixed.is_some() { 2 } else { na + 2 };
    let mut a = nalgebra::DMatrix::<f64>::zeros(2 * nr, nunk);
    let mut b = nalgebra::DVector::<f64>::zeros(2 * nr);
    for (i, r) in d.rods.iter().enumerate() {
        let act = &d.actuators[r.actuator];
        let (s, c) = r.clamp.sin_cos();
        let rhs = [
            r.length
                .mul_add(-c, r.attach[0] - act.origin[0] - r.offset[0]),
            r.length
                .mul_add(-s, r.attach[1] - act.origin[1] - r.offset[1]),
        ];
        for k in 0..2 {
            let row = 2 * i + k;
            let mut val = rhs[k];
            match fixed {
                Some(l) => val -= l[r.actuator] * act.dir[k],
                None => a[(row, r.actuator)] = act.dir[k],
            }
            a[(row, nunk - 2 + k)] = -1.0;
            b[row] = val;
        }
    }
    let svd = a.clone().svd(true, true);
    let x = svd
        .solve(&b, 1e-12)
        .unwrap_or_else(|_| nalgebra::DVector::zeros(nunk));
    let res = &a * &x - &b;
    let residual = res.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let lambda = match fixed {
        Some(l) => l.to_vec(),
        None => x.iter().take(na).copied().collect(),
    };
    let residual = if residual.is_finite() {
        residual
    } else {
        f64::INFINITY
    };
    Home {
        lambda,
        position: [x[nunk - 2], x[nunk - 1]],
        residual,
    }
}

/// Number of continuation steps of spec 4.3 from `from` to `to`.
#[must_use]
pub fn continuation_steps(model: &Model, from: &[f64], to: &[f64]) -> usize {
    let dmax = from
        .iter()
        .zip(to)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let k = (dmax / (CONTINUATION_REL_STEP * model.l_ref)).ceil();
    if k.is_finite() && k < 1e6 {
        (k as usize).max(MIN_CONTINUATION_STEPS)
    } else {
        1_000_000
    }
}

/// Solve at home then continue to `target` (spec 4.3 rule 2) with `stepping` (`k`: the spec's
/// number of equal steps; the adaptive path's first step is `1/k`).
#[expect(
    clippy::too_many_arguments,
    reason = "the continuation's full context; grouping it would only rename it"
)]
pub fn from_home(
    model: &Model,
    home: &Home,
    target: &Params,
    k: usize,
    stepping: Stepping,
    opts: NewtonOptions,
    budget: &Budget,
    counter: &mut Counter,
) -> Result<ContinuationResult, Failed> {
    let start_params = Params {
        lambda: home.lambda.clone(),
        force: [0.0, 0.0],
        moment: 0.0,
    };
    let v0 = model.home_state(home.position);
    let start = newton::solve(model, &start_params, &v0, opts, budget, counter)?;
    newton::continue_path(
        stepping,
        model,
        start,
        &start_params,
        target,
        k,
        opts,
        budget,
        counter,
    )
}

/// Everything reported about one solved equilibrium.
#[derive(Debug, Clone)]
pub struct Described {
    /// Platform position \[m\].
    pub position: [f64; 2],
    /// Platform angle \[rad\], continuous.
    pub angle: f64,
    /// Rod forces `n_i` \[N\].
    pub forces: Vec<[f64; 2]>,
    /// Base moments `m_i(0)` [N m].
    pub base_moments: Vec<f64>,
    /// Largest `|m_i(s)|` over the RK4 nodes [N m].
    pub max_moments: Vec<f64>,
    /// Largest bending stress per rod \[Pa\] (None without a diameter).
    pub stresses: Vec<Option<f64>>,
    /// Bending energy per rod \[J\].
    pub energies: Vec<f64>,
    /// Actuator forces `f_j = -sum n_i . d_j` \[N\].
    pub actuator_forces: Vec<f64>,
    /// Shapes `[x, y, theta_deg, m]` per rod, when requested.
    pub shapes: Option<Vec<Vec<[f64; 4]>>>,
    /// Stability margin (None when not requested or undefined).
    pub margin: Option<f64>,
    /// Sign of det J.
    pub det_sign: i8,
}

/// Actuator forces `f_j = -sum_{i on j} n_i . d_j` (spec 4.8).
#[must_use]
pub fn actuator_forces(model: &Model, forces: &[[f64; 2]]) -> Vec<f64> {
    let mut f = vec![0.0; model.n_act()];
    for (r, n) in model.design.rods.iter().zip(forces) {
        let d = model.design.actuators[r.actuator].dir;
        f[r.actuator] -= n[0].mul_add(d[0], n[1] * d[1]);
    }
    f
}

/// Stability margin of a solution with `segments` segments per rod (spec 4.5).
#[must_use]
pub fn margin_of(model: &Model, sol: &Solution, segments: usize) -> Option<f64> {
    let m = segments.max(1);
    let rods: Vec<RodDisc> = (0..model.n_rods())
        .map(|i| {
            let tr = model.trace(&sol.v, i, sol.steps[i]);
            let r = &model.design.rods[i];
            let angles = (0..m)
                .map(|j| tr.at((j as f64 + 0.5) / m as f64)[2])
                .collect();
            RodDisc {
                ei: r.ei,
                length: r.length,
                clamp: r.clamp,
                angles,
                force: sol.eval.forces[i],
            }
        })
        .collect();
    let attach: Vec<[f64; 2]> = model.design.rods.iter().map(|r| r.attach).collect();
    stability::margin(
        &rods,
        Tips::Platform {
            theta: model.angle(&sol.v),
            attach: &attach,
        },
        model.l_ref,
        model.ei_ref,
    )
}

/// Describe a solution: forces, moments, stresses, energies, optional shapes and stability.
#[must_use]
pub fn describe(
    model: &Model,
    sol: &Solution,
    shape_points: usize,
    stability_segments: Option<usize>,
) -> Described {
    let nr = model.n_rods();
    let mut base_moments = Vec::with_capacity(nr);
    let mut max_moments = Vec::with_capacity(nr);
    let mut stresses = Vec::with_capacity(nr);
    let mut energies = Vec::with_capacity(nr);
    let mut shapes = if shape_points > 0 {
        Some(Vec::with_capacity(nr))
    } else {
        None
    };
    for i in 0..nr {
        let r = &model.design.rods[i];
        let tr = model.trace(&sol.v, i, sol.steps[i]);
        let scale = r.ei / r.length;
        base_moments.push(sol.v[3 * i] * scale);
        let mmax = tr.max_abs_mb() * scale;
        max_moments.push(mmax);
        stresses.push(r.diameter.map(|d| {
            let inertia = PI * d.powi(4) / 64.0;
            0.5 * d * mmax / inertia
        }));
        energies.push(tr.bending_energy * scale);
        if let Some(sh) = shapes.as_mut() {
            let end = tr.nodes[tr.steps()];
            let base = [
                r.length.mul_add(-end[0], sol.eval.tips[i][0]),
                r.length.mul_add(-end[1], sol.eval.tips[i][1]),
            ];
            let pts = (0..shape_points)
                .map(|k| {
                    let sb = if shape_points == 1 {
                        1.0
                    } else {
                        k as f64 / (shape_points - 1) as f64
                    };
                    let z = tr.at(sb);
                    [
                        r.length.mul_add(z[0], base[0]),
                        r.length.mul_add(z[1], base[1]),
                        z[2].to_degrees(),
                        z[3] * scale,
                    ]
                })
                .collect();
            sh.push(pts);
        }
    }
    let margin = stability_segments.and_then(|m| margin_of(model, sol, m));
    Described {
        position: model.position(&sol.v),
        angle: model.angle(&sol.v),
        forces: sol.eval.forces.clone(),
        base_moments,
        max_moments,
        stresses,
        energies,
        actuator_forces: actuator_forces(model, &sol.eval.forces),
        shapes,
        margin,
        det_sign: sol.lu.det_sign(),
    }
}

/// 2-norm condition number of the scaled Jacobian at a solution.
#[must_use]
pub fn condition(model: &Model, sol: &Solution) -> f64 {
    dense::cond2(&sol.eval.jac, model.n_unknowns())
}

/// Indices of rods whose chord exceeds `TAUT_CHORD` of their length at `v`.
#[must_use]
pub fn taut_rods(model: &Model, p: &Params, v: &[f64]) -> Vec<usize> {
    let steps = model.steps_for(v);
    let e = model.evaluate(v, p, &steps, false);
    (0..model.n_rods())
        .filter(|&i| {
            let a = model.base_point(i, &p.lambda);
            let b = e.tips[i];
            let chord = (b[0] - a[0]).hypot(b[1] - a[1]);
            chord > TAUT_CHORD * model.design.rods[i].length
        })
        .collect()
}
