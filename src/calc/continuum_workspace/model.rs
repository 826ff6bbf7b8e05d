//! The mechanism model in SI units and the FK residual with its exact Jacobian (spec 4.2,
//! paper eqs. 16-19 and 22).
//!
//! Unknowns (length `3N + 3`): `v = [mb0_1, nbx_1, nby_1, ..., mb0_N, nbx_N, nby_N, px/L_ref,
//! py/L_ref, theta_EE]`. Residual: per rod the closure `(B_i - p - R(theta) r_i)/L_ref` and the
//! pinned-tip moment `mb_i(1)`, then platform force `(sum n_i - F)/F_ref` and moment about the
//! origin `(sum B_i x n_i - p x F - M)/(F_ref L_ref)`.

use super::rod::{self, RodEnd, RodOde, RodTrace};

/// One linear actuator (guide) in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Actuator {
    /// Point on the guide `o_j` \[m\].
    pub origin: [f64; 2],
    /// Unit guide direction `d_j`.
    pub dir: [f64; 2],
    /// Admissible inputs `[min, max]` \[m\].
    pub stroke: [f64; 2],
}

/// One rod in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Rod {
    /// Index of the actuator carrying the clamp.
    pub actuator: usize,
    /// Clamp offset `c_i` on the carriage \[m\].
    pub offset: [f64; 2],
    /// Clamp angle `theta_c,i` \[rad\].
    pub clamp: f64,
    /// Length `L_i` \[m\].
    pub length: f64,
    /// Bending stiffness `EI_i` [N m^2].
    pub ei: f64,
    /// Axial stiffness `EA_i` \[N\] when known (needs a diameter and a modulus).
    pub ea: Option<f64>,
    /// Diameter `d_i` \[m\] when known (for stresses).
    pub diameter: Option<f64>,
    /// Platform attachment `r_i` in the platform frame \[m\].
    pub attach: [f64; 2],
}

/// A planar parallel continuum mechanism.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Guides.
    pub actuators: Vec<Actuator>,
    /// Rods.
    pub rods: Vec<Rod>,
    /// Inputs at which every rod is straight and unloaded with `theta_EE = 0`, if known.
    pub home: Option<Vec<f64>>,
    /// Allowable bending stress \[Pa\] (warnings, optional workspace limit).
    pub sigma_allow: Option<f64>,
}

/// Loads and inputs: the parameters of one FK problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Actuator inputs `lambda_j` \[m\].
    pub lambda: Vec<f64>,
    /// Force on the platform at P \[N\].
    pub force: [f64; 2],
    /// Couple on the platform [N m].
    pub moment: f64,
}

/// The FK model: design plus reference scales, RK4 base step count and rod model.
#[derive(Debug, Clone)]
pub struct Model {
    /// The design.
    pub design: Design,
    /// Mean rod length \[m\].
    pub l_ref: f64,
    /// Mean rod EI [N m^2].
    pub ei_ref: f64,
    /// `EI_ref / L_ref^2` \[N\].
    pub f_ref: f64,
    /// Base RK4 steps per rod (`solver.rk4_steps`).
    pub base_steps: usize,
    /// Whether axial extensibility is on.
    pub extensible: bool,
    odes: Vec<RodOde>,
}

/// Rotation of `r` by `t`.
#[must_use]
pub fn rot(t: f64, r: [f64; 2]) -> [f64; 2] {
    let (s, c) = t.sin_cos();
    [c.mul_add(r[0], -s * r[1]), s.mul_add(r[0], c * r[1])]
}

/// `R'(t) r`.
#[must_use]
pub fn drot(t: f64, r: [f64; 2]) -> [f64; 2] {
    let (s, c) = t.sin_cos();
    [(-s).mul_add(r[0], -c * r[1]), c.mul_add(r[0], -s * r[1])]
}

/// 2-D cross product.
#[must_use]
pub fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0].mul_add(b[1], -a[1] * b[0])
}

/// Everything the residual evaluation produces.
#[derive(Debug, Clone)]
pub struct Eval {
    /// Residual `g` (length `3N + 3`).
    pub g: Vec<f64>,
    /// Jacobian `dg/dv`, row-major, empty unless requested.
    pub jac: Vec<f64>,
    /// Tip positions `B_i` \[m\].
    pub tips: Vec<[f64; 2]>,
    /// Rod forces `n_i` \[N\].
    pub forces: Vec<[f64; 2]>,
    /// End states of the rods.
    pub ends: Vec<RodEnd>,
}

impl Eval {
    /// `||g||_inf` (infinite when any entry is non-finite).
    #[must_use]
    pub fn norm_inf(&self) -> f64 {
        norm_inf(&self.g)
    }
    /// `||g||_2` (infinite when any entry is non-finite).
    #[must_use]
    pub fn norm2(&self) -> f64 {
        norm2(&self.g)
    }
}

/// Infinity norm, infinite for non-finite entries.
#[must_use]
pub fn norm_inf(x: &[f64]) -> f64 {
    let mut m = 0.0f64;
    for v in x {
        if !v.is_finite() {
            return f64::INFINITY;
        }
        m = m.max(v.abs());
    }
    m
}

/// Euclidean norm, infinite for non-finite entries.
#[must_use]
pub fn norm2(x: &[f64]) -> f64 {
    let s: f64 = x.iter().map(|v| v * v).sum();
    if s.is_finite() {
        s.sqrt()
    } else {
        f64::INFINITY
    }
}

impl Model {
    /// Build the model; `extensible` switches on `ca = EI/(EA L^2)` for rods with a known `EA`.
    #[must_use]
    pub fn new(design: Design, base_steps: usize, extensible: bool) -> Self {
        let n = design.rods.len().max(1) as f64;
        let l_ref = design.rods.iter().map(|r| r.length).sum::<f64>() / n;
        let ei_ref = design.rods.iter().map(|r| r.ei).sum::<f64>() / n;
        let odes = design
            .rods
            .iter()
            .map(|r| RodOde {
                theta_c: r.clamp,
                ca: match (extensible, r.ea) {
                    (true, Some(ea)) => r.ei / (ea * r.length * r.length),
                    _ => 0.0,
                },
            })
            .collect();
        Self {
            design,
            l_ref,
            ei_ref,
            f_ref: ei_ref / (l_ref * l_ref),
            base_steps,
            extensible,
            odes,
        }
    }

    /// The same model with `base_steps` RK4 steps per rod at the base of the step rule (the
    /// coarse discretisation of a continuation's intermediate points).
    #[must_use]
    pub fn with_base_steps(&self, base_steps: usize) -> Self {
        Self {
            base_steps,
            ..self.clone()
        }
    }

    /// Number of rods `N`.
    #[must_use]
    pub fn n_rods(&self) -> usize {
        self.design.rods.len()
    }

    /// Number of unknowns `3N + 3`.
    #[must_use]
    pub fn n_unknowns(&self) -> usize {
        3 * self.n_rods() + 3
    }

    /// Number of actuators.
    #[must_use]
    pub fn n_act(&self) -> usize {
        self.design.actuators.len()
    }

    /// ODE constants of rod `i`.
    #[must_use]
    pub fn ode(&self, i: usize) -> &RodOde {
        &self.odes[i]
    }

    /// `EI_i / L_i^2` \[N\]: physical force per unit `nb`.
    #[must_use]
    pub fn k(&self, i: usize) -> f64 {
        let r = &self.design.rods[i];
        r.ei / (r.length * r.length)
    }

    /// Clamp point `a_i(lambda)` \[m\].
    #[must_use]
    pub fn base_point(&self, i: usize, lambda: &[f64]) -> [f64; 2] {
        let r = &self.design.rods[i];
        let a = &self.design.actuators[r.actuator];
        let l = lambda[r.actuator];
        [
            l.mul_add(a.dir[0], a.origin[0]) + r.offset[0],
            l.mul_add(a.dir[1], a.origin[1]) + r.offset[1],
        ]
    }

    /// Rod unknowns `q_i` from the unknown vector.
    #[must_use]
    pub fn q(&self, v: &[f64], i: usize) -> [f64; 3] {
        [v[3 * i], v[3 * i + 1], v[3 * i + 2]]
    }

    /// Platform position \[m\] from the unknown vector.
    #[must_use]
    pub fn position(&self, v: &[f64]) -> [f64; 2] {
        let n = 3 * self.n_rods();
        [v[n] * self.l_ref, v[n + 1] * self.l_ref]
    }

    /// Platform angle `theta_EE` \[rad\] from the unknown vector (continuous, unwrapped).
    #[must_use]
    pub fn angle(&self, v: &[f64]) -> f64 {
        v[3 * self.n_rods() + 2]
    }

    /// Step counts the rule of spec 4.1 asks for at `v`.
    #[must_use]
    pub fn steps_for(&self, v: &[f64]) -> Vec<usize> {
        (0..self.n_rods())
            .map(|i| rod::steps_for(self.base_steps, &self.q(v, i)))
            .collect()
    }

    /// Evaluate the residual (and the Jacobian if `want_jac`) at `v` with `steps[i]` RK4 steps.
    #[must_use]
    pub fn evaluate(&self, v: &[f64], p: &Params, steps: &[usize], want_jac: bool) -> Eval {
        let nr = self.n_rods();
        let n = self.n_unknowns();
        let (l_ref, f_ref) = (self.l_ref, self.f_ref);
        let pos = self.position(v);
        let th = self.angle(v);
        let mut g = vec![0.0; n];
        let mut jac = if want_jac {
            vec![0.0; n * n]
        } else {
            Vec::new()
        };
        let mut tips = Vec::with_capacity(nr);
        let mut forces = Vec::with_capacity(nr);
        let mut ends = Vec::with_capacity(nr);
        let (mut fx, mut fy, mut mom) = (0.0, 0.0, 0.0);
        let fm = f_ref * l_ref;
        for i in 0..nr {
            let rodd = &self.design.rods[i];
            let q = self.q(v, i);
            let end = if want_jac {
                rod::shoot(&self.odes[i], &q, steps[i])
            } else {
                RodEnd {
                    z: rod::shoot_plain(&self.odes[i], &q, steps[i]),
                    s: [[0.0; 3]; 4],
                }
            };
            let a = self.base_point(i, &p.lambda);
            let li = rodd.length;
            let b = [li.mul_add(end.z[0], a[0]), li.mul_add(end.z[1], a[1])];
            let rr = rot(th, rodd.attach);
            g[3 * i] = (b[0] - pos[0] - rr[0]) / l_ref;
            g[3 * i + 1] = (b[1] - pos[1] - rr[1]) / l_ref;
            g[3 * i + 2] = end.z[3];
            let ki = self.k(i);
            let nf = [ki * q[1], ki * q[2]];
            fx += nf[0];
            fy += nf[1];
            mom += cross(b, nf);
            if want_jac {
                let s = &end.s;
                let dr = drot(th, rodd.attach);
                for c in 0..3 {
                    jac[(3 * i) * n + 3 * i + c] = li * s[0][c] / l_ref;
                    jac[(3 * i + 1) * n + 3 * i + c] = li * s[1][c] / l_ref;
                    jac[(3 * i + 2) * n + 3 * i + c] = s[3][c];
                    // Moment row: dB x n + B x dn.
                    let dbxn = li * s[0][c].mul_add(nf[1], -s[1][c] * nf[0]);
                    let bxdn = match c {
                        1 => -b[1] * ki,
                        2 => b[0] * ki,
                        _ => 0.0,
                    };
                    jac[(3 * nr + 2) * n + 3 * i + c] = (dbxn + bxdn) / fm;
                }
                jac[(3 * i) * n + 3 * nr] = -1.0;
                jac[(3 * i + 1) * n + 3 * nr + 1] = -1.0;
                jac[(3 * i) * n + 3 * nr + 2] = -dr[0] / l_ref;
                jac[(3 * i + 1) * n + 3 * nr + 2] = -dr[1] / l_ref;
                jac[(3 * nr) * n + 3 * i + 1] = ki / f_ref;
                jac[(3 * nr + 1) * n + 3 * i + 2] = ki / f_ref;
            }
            tips.push(b);
            forces.push(nf);
            ends.push(end);
        }
        g[3 * nr] = (fx - p.force[0]) / f_ref;
        g[3 * nr + 1] = (fy - p.force[1]) / f_ref;
        g[3 * nr + 2] = (mom - cross(pos, p.force) - p.moment) / fm;
        if want_jac {
            jac[(3 * nr + 2) * n + 3 * nr] = -p.force[1] / f_ref;
            jac[(3 * nr + 2) * n + 3 * nr + 1] = p.force[0] / f_ref;
        }
        Eval {
            g,
            jac,
            tips,
            forces,
            ends,
        }
    }

    /// `dg/dlambda` (row-major `n x n_act`) at a solution with rod forces `forces`.
    #[must_use]
    pub fn dg_dlambda(&self, forces: &[[f64; 2]]) -> Vec<f64> {
        let nr = self.n_rods();
        let n = self.n_unknowns();
        let na = self.n_act();
        let fm = self.f_ref * self.l_ref;
        let mut d = vec![0.0; n * na];
        for (i, rodd) in self.design.rods.iter().enumerate() {
            let j = rodd.actuator;
            let dir = self.design.actuators[j].dir;
            d[(3 * i) * na + j] += dir[0] / self.l_ref;
            d[(3 * i + 1) * na + j] += dir[1] / self.l_ref;
            d[(3 * nr + 2) * na + j] += cross(dir, forces[i]) / fm;
        }
        d
    }

    /// `dg/dt` along the straight path `lambda(t) = l0 + t dl`, `F(t) = F0 + t dF`, `M(t) = M0 + t dM`.
    #[must_use]
    pub fn dg_dt(
        &self,
        v: &[f64],
        forces: &[[f64; 2]],
        dl: &[f64],
        df: [f64; 2],
        dm: f64,
    ) -> Vec<f64> {
        let nr = self.n_rods();
        let n = self.n_unknowns();
        let na = self.n_act();
        let dgl = self.dg_dlambda(forces);
        let mut out = vec![0.0; n];
        for (r, o) in out.iter_mut().enumerate() {
            for j in 0..na {
                *o = dgl[r * na + j].mul_add(dl[j], *o);
            }
        }
        let pos = self.position(v);
        let fm = self.f_ref * self.l_ref;
        out[3 * nr] -= df[0] / self.f_ref;
        out[3 * nr + 1] -= df[1] / self.f_ref;
        out[3 * nr + 2] -= (cross(pos, df) + dm) / fm;
        out
    }

    /// The RK4 node trace of rod `i` at `v`.
    #[must_use]
    pub fn trace(&self, v: &[f64], i: usize, steps: usize) -> RodTrace {
        rod::trace(&self.odes[i], &self.q(v, i), steps)
    }

    /// The unknown vector of the straight, unloaded home state at platform position `p` \[m\].
    #[must_use]
    pub fn home_state(&self, p: [f64; 2]) -> Vec<f64> {
        let nr = self.n_rods();
        let mut v = vec![0.0; self.n_unknowns()];
        v[3 * nr] = p[0] / self.l_ref;
        v[3 * nr + 1] = p[1] / self.l_ref;
        v
    }
}
