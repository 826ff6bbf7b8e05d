//! The zero-residual-vibration law as a direct linear solve (spec §3.7): the residual is affine in
//! the free ordinates γ, the energy a convex quadratic; a secondary objective picks one law from
//! the affine set of zero-energy laws.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::law::{binomial, control_ordinates, derivative_polygon};
use super::plant::{Plant, ResponseMatrix};

/// Eigenvalues of `Kc` below this fraction of the largest are dropped (spec §3.7).
pub const PINV_REL_TOL: f64 = 1e-10;

/// The secondary objective (spec §3.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Objective {
    /// Closest to the reference ordinates (`Hq = I`, `f = −γ_ref`).
    MinDeviation,
    /// Least `∫₀ᵀ φ''² dt`.
    MinAccelL2,
    /// Least `∫₀ᵀ φ'''² dt`.
    MinJerkL2,
}

/// The shape of the law being optimised: `m`, `p`, `Phi`, `T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawShape {
    /// Order of the vanishing end derivatives.
    pub m: usize,
    /// Free interior ordinates.
    pub p: usize,
    /// Total motor rotation \[rad\].
    pub phi: f64,
    /// Motion time \[s\].
    pub t: f64,
}

impl LawShape {
    /// `N = 2m + p − 1`, the degree of φ''.
    #[must_use]
    pub fn accel_degree(&self) -> usize {
        2 * self.m + self.p - 1
    }

    /// Acceleration ordinates of the affine part `S0` (γ = 0) and of each unit free ordinate.
    fn accel_columns(&self) -> (Vec<f64>, Vec<Vec<f64>>) {
        let zeros = vec![0.0; self.p];
        let a0 = accel(&control_ordinates(self.m, self.phi, &zeros), self.t);
        let cols = (0..self.p)
            .map(|j| {
                let mut g = zeros.clone();
                g[j] = 1.0;
                accel(&control_ordinates(self.m, 0.0, &g), self.t)
            })
            .collect();
        (a0, cols)
    }
}

fn accel(s: &[f64], t: f64) -> Vec<f64> {
    derivative_polygon(&derivative_polygon(s, t), t)
}

/// The residual rows of one plant: `r(γ) = r0 + R γ` with `E = ‖r‖²` (spec §3.7).
#[derive(Debug, Clone, PartialEq)]
pub struct ResidualRows {
    /// `R = L K` (2 × p).
    pub r: DMatrix<f64>,
    /// `r0 = L x0`.
    pub r0: DVector<f64>,
}

/// `R` and `r0` for a plant with response matrix `h`.
#[must_use]
pub fn residual_rows(plant: &Plant, h: &ResponseMatrix, shape: &LawShape) -> ResidualRows {
    let (a0, cols) = shape.accel_columns();
    let l = (plant.j_eq / 2.0).sqrt();
    let lrow = |x: [f64; 2]| [l * plant.wn * x[0], l * x[1]];
    let x0 = lrow(h.apply(&a0));
    let mut r = DMatrix::zeros(2, shape.p);
    for (j, c) in cols.iter().enumerate() {
        let x = lrow(h.apply(c));
        r[(0, j)] = x[0];
        r[(1, j)] = x[1];
    }
    ResidualRows {
        r,
        r0: DVector::from_vec(x0.to_vec()),
    }
}

/// Gram matrix of the Bernstein basis of degree `n` on [0, 1]:
/// `G[i,j] = C(n,i) C(n,j) / ((2n+1) C(2n, i+j))`.
#[must_use]
pub fn bernstein_gram(n: usize) -> DMatrix<f64> {
    let d = 2.0 * n as f64 + 1.0;
    DMatrix::from_fn(n + 1, n + 1, |i, j| {
        binomial(n, i) * binomial(n, j) / (d * binomial(2 * n, i + j))
    })
}

/// `(Hq, f)` of the objective `½ γᵀ Hq γ + fᵀ γ`.
#[must_use]
pub fn objective_terms(
    objective: Objective,
    shape: &LawShape,
    gamma_ref: &[f64],
) -> (DMatrix<f64>, DVector<f64>) {
    match objective {
        Objective::MinDeviation => (
            DMatrix::identity(shape.p, shape.p),
            -DVector::from_column_slice(gamma_ref),
        ),
        Objective::MinAccelL2 | Objective::MinJerkL2 => {
            let (a0, cols) = shape.accel_columns();
            let jerk = objective == Objective::MinJerkL2;
            let lift = |a: &[f64]| {
                if jerk {
                    derivative_polygon(a, shape.t)
                } else {
                    a.to_vec()
                }
            };
            let y0 = DVector::from_vec(lift(&a0));
            let ys: Vec<DVector<f64>> = cols.iter().map(|c| DVector::from_vec(lift(c))).collect();
            let g = bernstein_gram(y0.len() - 1);
            let t = shape.t;
            let gy: Vec<DVector<f64>> = ys.iter().map(|y| &g * y).collect();
            let hq = DMatrix::from_fn(shape.p, shape.p, |i, j| t * ys[i].dot(&gy[j]));
            let f = DVector::from_fn(shape.p, |i, _| t * gy[i].dot(&y0));
            (hq, f)
        }
    }
}

/// The solution of the equality-constrained quadratic program.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Optimal free ordinates γ* \[rad\].
    pub gamma: Vec<f64>,
    /// Lagrange multipliers μ (stationarity: `Hq γ* + f + Rᵀ μ = 0` on the kept constraints).
    pub mu: Vec<f64>,
    /// Number of constraint rows.
    pub n_constraints: usize,
    /// Numerical rank of `Kc = R Hq⁻¹ Rᵀ`.
    pub rank: usize,
}

/// Failure of the solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolveError {
    /// `Hq` is not numerically positive definite (Cholesky failed).
    NotPositiveDefinite,
}

/// Minimise `½ γᵀHqγ + fᵀγ` subject to `R γ = −r0` (rows stacked from one or more plants), with
/// the pseudo-inverse of `Kc` (spec §3.7). Never forms `Hq⁻¹`: Cholesky solves only.
///
/// # Errors
/// [`SolveError::NotPositiveDefinite`] when `Hq` has no Cholesky factor.
pub fn solve(
    hq: &DMatrix<f64>,
    f: &DVector<f64>,
    rows: &[ResidualRows],
) -> Result<Solution, SolveError> {
    let p = hq.nrows();
    let nc: usize = rows.iter().map(|r| r.r.nrows()).sum();
    let mut r = DMatrix::zeros(nc, p);
    let mut r0 = DVector::zeros(nc);
    let mut at = 0;
    for rr in rows {
        let k = rr.r.nrows();
        r.view_mut((at, 0), (k, p)).copy_from(&rr.r);
        r0.rows_mut(at, k).copy_from(&rr.r0);
        at += k;
    }
    let chol = hq
        .clone()
        .cholesky()
        .ok_or(SolveError::NotPositiveDefinite)?;
    let gamma_u = -chol.solve(f);
    let y = chol.solve(&r.transpose()); // Hq⁻¹ Rᵀ  (p × nc)
    let kc = &r * &y;
    let kc = (&kc + kc.transpose()) * 0.5;
    let eig = SymmetricEigen::new(kc);
    let lmax = eig.eigenvalues.iter().fold(0.0_f64, |a, &b| a.max(b));
    let rhs = &r * &gamma_u + &r0;
    let mut mu = DVector::zeros(nc);
    let mut rank = 0;
    for (i, &l) in eig.eigenvalues.iter().enumerate() {
        if lmax > 0.0 && l > PINV_REL_TOL * lmax {
            rank += 1;
            let v = eig.eigenvectors.column(i);
            mu += v * (v.dot(&rhs) / l);
        }
    }
    let gamma = gamma_u - &y * &mu;
    Ok(Solution {
        gamma: gamma.iter().copied().collect(),
        mu: mu.iter().copied().collect(),
        n_constraints: nc,
        rank,
    })
}
