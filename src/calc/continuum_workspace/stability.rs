//! Stability test (spec 4.5): the smallest eigenvalue of the Hessian of the Lagrangian of a
//! discretised total potential, restricted to the tangent space of the closure constraints.
//!
//! Each rod is cut into `M` segments with angles `t_ij` at the segment mid-points. The reduced
//! Hessian `Z^T H Z` is taken against the mass `Z^T Mm Z` (`Mm = h_i` on the angles, 0 on the
//! platform pose), so the eigenvalue converges with `M` (error ~ M^-2) and, scaled by
//! `L_ref^2 / EI_ref`, is the nondimensional **stability margin**.

// Without a target FMA unit `f64::mul_add` is a libm call; plain arithmetic in the inner loops.
#![allow(clippy::suboptimal_flops)]

use nalgebra::{DMatrix, linalg::Cholesky};

use super::model::{drot, rot};

/// A constraint gradient (column of `C^T`) shorter than this fraction of the longest is taken as
/// zero: rank-deficient closure constraints appear exactly for straight rods (Euler tests,
/// straight over-constrained states), where the computed norms are round-off (~1e-16).
const RANK_REL_TOL: f64 = 1e-9;

/// One rod discretised for the stability test.
#[derive(Debug, Clone)]
pub struct RodDisc {
    /// Bending stiffness `EI_i` [N m^2].
    pub ei: f64,
    /// Length `L_i` [m].
    pub length: f64,
    /// Clamp angle [rad].
    pub clamp: f64,
    /// Segment mid-point angles `t_ij`, `j = 1..M` [rad].
    pub angles: Vec<f64>,
    /// Rod force `n_i` [N] (force of the tip support on the rod, equal to the multiplier).
    pub force: [f64; 2],
}

/// How the rod tips are held.
#[derive(Debug, Clone, Copy)]
pub enum Tips<'a> {
    /// All tips pinned to a rigid platform with pose variables `(p, theta)`; `attach[i] = r_i`.
    Platform {
        /// Platform angle `theta_EE` [rad].
        theta: f64,
        /// Attachment points `r_i` in the platform frame [m].
        attach: &'a [[f64; 2]],
    },
    /// Every tip pinned to a fixed point (no pose variables).
    Pinned,
    /// Free tips carrying their (dead) force `n_i`; no constraints.
    Free,
}

/// Smallest generalised eigenvalue of `(Z^T H Z, Z^T Mm Z)` scaled by `l_ref^2 / ei_ref`.
/// Returns `None` if the reduced mass matrix is not positive definite (platform rotation not
/// determined by the rods).
#[must_use]
pub fn margin(rods: &[RodDisc], tips: Tips<'_>, l_ref: f64, ei_ref: f64) -> Option<f64> {
    let nt: usize = rods.iter().map(|r| r.angles.len()).sum();
    let platform = matches!(tips, Tips::Platform { .. });
    let nv = nt + if platform { 3 } else { 0 };
    // Hessian of the Lagrangian.
    let mut h = DMatrix::<f64>::zeros(nv, nv);
    let mut mass = vec![0.0; nv];
    let mut off = 0usize;
    for r in rods {
        let m = r.angles.len();
        let hs = r.length / m as f64;
        let kk = r.ei / hs;
        for (j, &t) in r.angles.iter().enumerate() {
            let diag = if m == 1 {
                3.0 - 1.0
            } else if j == 0 {
                3.0
            } else if j + 1 == m {
                1.0
            } else {
                2.0
            };
            let (s, c) = t.sin_cos();
            h[(off + j, off + j)] = kk.mul_add(diag, hs * r.force[0].mul_add(c, r.force[1] * s));
            if j + 1 < m {
                h[(off + j, off + j + 1)] = -kk;
                h[(off + j + 1, off + j)] = -kk;
            }
            mass[off + j] = hs;
        }
        off += m;
    }
    // Constraint gradients as columns of C^T.
    let mut cols: Vec<Vec<f64>> = Vec::new();
    match tips {
        Tips::Platform { theta, attach } => {
            let mut hth = 0.0;
            for (r, a) in rods.iter().zip(attach) {
                let ra = rot(theta, *a);
                hth -= r.force[0].mul_add(ra[0], r.force[1] * ra[1]);
            }
            h[(nt + 2, nt + 2)] = hth;
            let mut off = 0usize;
            for (r, a) in rods.iter().zip(attach) {
                let m = r.angles.len();
                let hs = r.length / m as f64;
                let dr = drot(theta, *a);
                let mut cx = vec![0.0; nv];
                let mut cy = vec![0.0; nv];
                for (j, &t) in r.angles.iter().enumerate() {
                    let (s, c) = t.sin_cos();
                    cx[off + j] = -hs * s;
                    cy[off + j] = hs * c;
                }
                cx[nt] = -1.0;
                cy[nt + 1] = -1.0;
                cx[nt + 2] = -dr[0];
                cy[nt + 2] = -dr[1];
                cols.push(cx);
                cols.push(cy);
                off += m;
            }
        }
        Tips::Pinned => {
            let mut off = 0usize;
            for r in rods {
                let m = r.angles.len();
                let hs = r.length / m as f64;
                let mut cx = vec![0.0; nv];
                let mut cy = vec![0.0; nv];
                for (j, &t) in r.angles.iter().enumerate() {
                    let (s, c) = t.sin_cos();
                    cx[off + j] = -hs * s;
                    cy[off + j] = hs * c;
                }
                cols.push(cx);
                cols.push(cy);
                off += m;
            }
        }
        Tips::Free => {}
    }
    let reflectors = householder_pivoted(&mut cols, nv);
    let rank = reflectors.len();
    // Q^T A Q for A = H and A = Mm, applying the reflectors on both sides.
    let mut mm = DMatrix::<f64>::from_diagonal(&nalgebra::DVector::from_vec(mass));
    for (v, beta) in &reflectors {
        reflect_both(&mut h, v, *beta);
        reflect_both(&mut mm, v, *beta);
    }
    let nz = nv - rank;
    if nz == 0 {
        return Some(f64::INFINITY);
    }
    let hz = h.view((rank, rank), (nz, nz)).into_owned();
    let bz = mm.view((rank, rank), (nz, nz)).into_owned();
    let chol = Cholesky::new(bz)?;
    let l = chol.l();
    // G = L^-1 Hz L^-T (symmetric).
    let y = l.solve_lower_triangular(&hz)?;
    let g = l.solve_lower_triangular(&y.transpose())?;
    let g = (&g + g.transpose()) * 0.5;
    let eig = g.symmetric_eigenvalues();
    let min = eig.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    Some(min * l_ref * l_ref / ei_ref)
}

/// Householder QR with column pivoting of the matrix whose columns are `cols` (each of length
/// `nv`); returns the reflectors `(v, beta)` (P = I - beta v v^T) for the numerical rank.
fn householder_pivoted(cols: &mut [Vec<f64>], nv: usize) -> Vec<(Vec<f64>, f64)> {
    let nc = cols.len();
    let mut out = Vec::with_capacity(nc);
    let norm0 = cols
        .iter()
        .map(|c| c.iter().map(|x| x * x).sum::<f64>().sqrt())
        .fold(0.0f64, f64::max);
    if norm0.is_nan() || norm0 <= 0.0 {
        return out;
    }
    for k in 0..nc.min(nv) {
        // Pivot: remaining column with the largest norm below row k.
        let mut best = k;
        let mut best_norm = -1.0;
        for (j, c) in cols.iter().enumerate().skip(k) {
            let nrm = c[k..].iter().map(|x| x * x).sum::<f64>().sqrt();
            if nrm > best_norm {
                best_norm = nrm;
                best = j;
            }
        }
        if best_norm.is_nan() || best_norm <= RANK_REL_TOL * norm0 {
            break;
        }
        cols.swap(k, best);
        let x = &cols[k];
        let alpha = if x[k] >= 0.0 { -best_norm } else { best_norm };
        let mut v = vec![0.0; nv];
        v[k..].copy_from_slice(&x[k..]);
        v[k] -= alpha;
        let vv: f64 = v.iter().map(|a| a * a).sum();
        if vv.is_nan() || vv <= 0.0 {
            break;
        }
        let beta = 2.0 / vv;
        for c in cols.iter_mut().skip(k) {
            let d: f64 = v[k..].iter().zip(&c[k..]).map(|(a, b)| a * b).sum();
            let f = beta * d;
            for (ci, vi) in c[k..].iter_mut().zip(&v[k..]) {
                *ci -= f * *vi;
            }
        }
        out.push((v, beta));
    }
    out
}

/// `A <- P A P` with `P = I - beta v v^T` (A symmetric).
fn reflect_both(a: &mut DMatrix<f64>, v: &[f64], beta: f64) {
    let n = a.nrows();
    let first = v.iter().position(|x| *x != 0.0).unwrap_or(n);
    // A <- A - beta (A v) v^T
    let mut av = vec![0.0; n];
    for (r, avr) in av.iter_mut().enumerate() {
        let mut s = 0.0;
        for c in first..n {
            s += a[(r, c)] * v[c];
        }
        *avr = s;
    }
    for c in first..n {
        let f = beta * v[c];
        for r in 0..n {
            a[(r, c)] -= av[r] * f;
        }
    }
    // A <- A - beta v (v^T A)
    let mut va = vec![0.0; n];
    for (c, vac) in va.iter_mut().enumerate() {
        let mut s = 0.0;
        for r in first..n {
            s += v[r] * a[(r, c)];
        }
        *vac = s;
    }
    for r in first..n {
        let f = beta * v[r];
        for c in 0..n {
            a[(r, c)] -= f * va[c];
        }
    }
}

/// Stability margin of a straight rod of unit stiffness and length clamped at angle 0 under an
/// axial compressive tip load `p_nd = P L^2/EI`, with the tip pinned to a fixed point
/// (`pinned = true`) or free; `m` segments. Margin 0 marks the Euler critical load
/// (20.19 pinned, pi^2/4 free).
#[must_use]
pub fn straight_rod_margin(p_nd: f64, m: usize, pinned: bool) -> Option<f64> {
    let rod = RodDisc {
        ei: 1.0,
        length: 1.0,
        clamp: 0.0,
        angles: vec![0.0; m.max(1)],
        force: [-p_nd, 0.0],
    };
    let tips = if pinned { Tips::Pinned } else { Tips::Free };
    margin(std::slice::from_ref(&rod), tips, 1.0, 1.0)
}
