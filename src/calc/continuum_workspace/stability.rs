//! Stability test (spec 4.5): the smallest eigenvalue of the Hessian of the Lagrangian of a
//! discretised total potential, restricted to the tangent space of the closure constraints.
//!
//! Each rod is cut into `M` segments with angles `t_ij` at the segment mid-points. The reduced
//! Hessian `Z^T H Z` is taken against the mass `Z^T Mm Z` (`Mm = h_i` on the angles, 0 on the
//! platform pose), so the eigenvalue converges with `M` (error ~ M^-2) and, scaled by
//! `L_ref^2 / EI_ref`, is the nondimensional **stability margin**. See [`margin`] for how the
//! generalised problem is reduced to a standard one.

// Without a target FMA unit `f64::mul_add` is a libm call; plain arithmetic in the inner loops.

use nalgebra::DMatrix;

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
    /// Length `L_i` \[m\].
    pub length: f64,
    /// Clamp angle \[rad\].
    pub clamp: f64,
    /// Segment mid-point angles `t_ij`, `j = 1..M` \[rad\].
    pub angles: Vec<f64>,
    /// Rod force `n_i` \[N\] (force of the tip support on the rod, equal to the multiplier).
    pub force: [f64; 2],
}

/// How the rod tips are held.
#[derive(Debug, Clone, Copy)]
pub enum Tips<'a> {
    /// All tips pinned to a rigid platform with pose variables `(p, theta)`; `attach[i] = r_i`.
    Platform {
        /// Platform angle `theta_EE` \[rad\].
        theta: f64,
        /// Attachment points `r_i` in the platform frame \[m\].
        attach: &'a [[f64; 2]],
    },
    /// Every tip pinned to a fixed point (no pose variables).
    Pinned,
    /// Free tips carrying their (dead) force `n_i`; no constraints.
    Free,
}

/// Smallest generalised eigenvalue of `(Z^T H Z, Z^T Mm Z)` scaled by `l_ref^2 / ei_ref`.
/// Returns `None` when the platform rotation is not determined by the rods (coincident
/// attachments), where the reduced mass matrix is singular.
///
/// Computation: the zero-mass pose variables are eliminated first (a QR of the pose columns of
/// the constraint Jacobian expresses `(dp, dtheta)` through the angles and leaves `2N - 3`
/// constraints on the angles alone; the platform's `H[theta, theta]` becomes a rank-1 term), the
/// angles are scaled by `sqrt(h_i)` so that the mass is the identity, and the remaining
/// constraints are removed by Householder reflections. What is left is a standard symmetric
/// eigenproblem of size `NM - (2N - 3)`: no Cholesky factor and no generalised solve.
#[expect(
    clippy::needless_range_loop,
    reason = "Householder QR on a ragged row block reads clearest with indices"
)]
#[must_use]
pub fn margin(rods: &[RodDisc], tips: Tips<'_>, l_ref: f64, ei_ref: f64) -> Option<f64> {
    let nt: usize = rods.iter().map(|r| r.angles.len()).sum();
    if nt == 0 {
        return None;
    }
    // Scaled Hessian H_u = D^-1/2 H_tt D^-1/2 (column-major, dense), D = diag(h_i).
    let mut a = vec![0.0; nt * nt];
    let mut sqrt_h = vec![0.0; nt];
    let mut off = 0usize;
    for r in rods {
        let m = r.angles.len();
        let hs = r.length / m as f64;
        let kk = r.ei / hs;
        for (j, &t) in r.angles.iter().enumerate() {
            let diag = if m == 1 {
                2.0
            } else if j == 0 {
                3.0
            } else if j + 1 == m {
                1.0
            } else {
                2.0
            };
            let (s, c) = t.sin_cos();
            let k = off + j;
            a[k * nt + k] = (kk * diag + hs * (r.force[0] * c + r.force[1] * s)) / hs;
            if j + 1 < m {
                a[(k + 1) * nt + k] = -kk / hs;
                a[k * nt + k + 1] = -kk / hs;
            }
            sqrt_h[k] = hs.sqrt();
        }
        off += m;
    }
    // Constraint rows on the angles (scaled by D^-1/2), two per rod.
    let mut rows: Vec<Vec<f64>> = Vec::new();
    if !matches!(tips, Tips::Free) {
        let mut off = 0usize;
        for r in rods {
            let m = r.angles.len();
            let hs = r.length / m as f64;
            let mut cx = vec![0.0; nt];
            let mut cy = vec![0.0; nt];
            for (j, &t) in r.angles.iter().enumerate() {
                let (s, c) = t.sin_cos();
                cx[off + j] = -hs * s / sqrt_h[off + j];
                cy[off + j] = hs * c / sqrt_h[off + j];
            }
            rows.push(cx);
            rows.push(cy);
            off += m;
        }
    }
    if let Tips::Platform { theta, attach } = tips {
        let nc = rows.len();
        // Pose columns of C per constraint row: [-1, 0, -dr_x] and [0, -1, -dr_y].
        let mut cp = vec![[0.0f64; 3]; nc];
        let mut hth = 0.0;
        for (i, (r, at)) in rods.iter().zip(attach).enumerate() {
            let dr = drot(theta, *at);
            cp[2 * i] = [-1.0, 0.0, -dr[0]];
            cp[2 * i + 1] = [0.0, -1.0, -dr[1]];
            let ra = rot(theta, *at);
            hth -= r.force[0] * ra[0] + r.force[1] * ra[1];
        }
        // Householder QR of the nc x 3 pose block, applied to the angle rows as well.
        let scale = cp.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut diag_r = [0.0f64; 3];
        for k in 0..3 {
            let norm = (k..nc).map(|i| cp[i][k] * cp[i][k]).sum::<f64>().sqrt();
            if norm.is_nan() || norm <= RANK_REL_TOL * scale.max(f64::MIN_POSITIVE) {
                return None;
            }
            let alpha = if cp[k][k] >= 0.0 { -norm } else { norm };
            let mut v = vec![0.0; nc];
            for i in k..nc {
                v[i] = cp[i][k];
            }
            v[k] -= alpha;
            let vv: f64 = v.iter().map(|x| x * x).sum();
            let beta = 2.0 / vv;
            for col in k..3 {
                let d: f64 = (k..nc).map(|i| v[i] * cp[i][col]).sum();
                for i in k..nc {
                    cp[i][col] -= beta * d * v[i];
                }
            }
            for c in 0..nt {
                let d: f64 = (k..nc).map(|i| v[i] * rows[i][c]).sum();
                if d != 0.0 {
                    for i in k..nc {
                        rows[i][c] -= beta * d * v[i];
                    }
                }
            }
            diag_r[k] = cp[k][k];
        }
        // dtheta = -(Q^T C_t)[2] / R[2][2] (last row of the triangular solve): the platform term
        // H[theta, theta] dtheta^2 becomes the rank-1 update hth * w w^T.
        let w: Vec<f64> = rows[2].iter().map(|x| -x / diag_r[2]).collect();
        if hth != 0.0 {
            for c in 0..nt {
                let f = hth * w[c];
                if f != 0.0 {
                    for (r, wr) in w.iter().enumerate() {
                        a[c * nt + r] += f * wr;
                    }
                }
            }
        }
        rows.drain(0..3);
    }
    // Remove the remaining constraints: Householder QR with column pivoting of C_u^T, then
    // A <- P A P per reflector; the trailing block is the reduced operator.
    let reflectors = householder_pivoted(&mut rows, nt);
    for (v, beta) in &reflectors {
        reflect_sym(&mut a, nt, v, *beta);
    }
    let r = reflectors.len();
    let nz = nt - r;
    if nz == 0 {
        return Some(f64::INFINITY);
    }
    let z = DMatrix::<f64>::from_fn(nz, nz, |rr, c| a[(c + r) * nt + rr + r]);
    let eig = z.symmetric_eigenvalues();
    let min = eig.iter().fold(f64::INFINITY, |m, &b| m.min(b));
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

/// `A <- P A P` with `P = I - beta v v^T` for a symmetric column-major `n x n` matrix:
/// `p = beta A v`, `w = p - (beta v^T p / 2) v`, `A <- A - v w^T - w v^T` (one product and one
/// rank-2 update).
fn reflect_sym(a: &mut [f64], n: usize, v: &[f64], beta: f64) {
    let first = v.iter().position(|x| *x != 0.0).unwrap_or(n);
    let mut p = vec![0.0; n];
    for c in first..n {
        let vc = v[c];
        if vc == 0.0 {
            continue;
        }
        let col = &a[c * n..(c + 1) * n];
        for (pr, ar) in p.iter_mut().zip(col) {
            *pr += ar * vc;
        }
    }
    for x in &mut p {
        *x *= beta;
    }
    let k = 0.5
        * beta
        * v[first..]
            .iter()
            .zip(&p[first..])
            .map(|(x, y)| x * y)
            .sum::<f64>();
    let w: Vec<f64> = p.iter().zip(v).map(|(pi, vi)| pi - k * vi).collect();
    for c in 0..n {
        let (vc, wc) = (v[c], w[c]);
        let col = &mut a[c * n..(c + 1) * n];
        for ((ar, vr), wr) in col.iter_mut().zip(v).zip(&w) {
            *ar -= vr * wc + wr * vc;
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
