//! The zero-residual-vibration law as a direct linear solve (spec §3.7): the residual is affine in
//! the free ordinates γ, the energy a convex quadratic; a secondary objective picks one law from
//! the affine set of zero-energy laws.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::law::{control_ordinates, derivative_polygon};
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

/// `C(n, k)` as an exact integer (n ≤ 66 stays below 2^63; the Gram tables use n ≤ 60).
#[must_use]
pub fn binomial_exact(n: usize, k: usize) -> i128 {
    if k > n {
        return 0;
    }
    let k = k.min(n - k);
    let mut c: i128 = 1;
    for i in 0..k {
        // C(n, i+1) = C(n, i)·(n−i)/(i+1): the division is exact at every step.
        c = c * (n - i) as i128 / (i + 1) as i128;
    }
    c
}

/// Integer numerators of the Gram matrix of the Bernstein basis of degree `n` on [0, 1] over one
/// common denominator: `G[i,j] = C(n,i) C(n,j) / ((2n+1) C(2n, i+j)) = g[i][j] / D` with
/// `g[i][j] = C(i+j, i)·C(2n−i−j, n−i)` and `D = (2n+1)·C(2n, n)` (the identity
/// `C(n,i)C(n,j)/C(2n,i+j) = C(i+j,i)C(2n−i−j,n−i)/C(2n,n)`: both sides are
/// `n!² (i+j)! (2n−i−j)! / (i! j! (n−i)! (n−j)! (2n)!)`). Returns `(g, D)`; every entry is exact
/// (≤ C(60, 30) ≈ 1.2e17 for the degrees admitted).
#[must_use]
pub fn bernstein_gram_exact(n: usize) -> (Vec<Vec<i128>>, i128) {
    let g = (0..=n)
        .map(|i| {
            (0..=n)
                .map(|j| binomial_exact(i + j, i) * binomial_exact(2 * n - i - j, n - i))
                .collect()
        })
        .collect();
    (g, (2 * n + 1) as i128 * binomial_exact(2 * n, n))
}

/// Gram matrix of the Bernstein basis of degree `n` on [0, 1]:
/// `G[i,j] = C(n,i) C(n,j) / ((2n+1) C(2n, i+j))`, each entry the exact rational rounded once.
#[must_use]
pub fn bernstein_gram(n: usize) -> DMatrix<f64> {
    let (g, d) = bernstein_gram_exact(n);
    // g ≤ C(2n, n) < 2^57 and D < 2^63: the quotient of the two correctly rounded integers is
    // within 1.5 ulp of the exact rational.
    DMatrix::from_fn(n + 1, n + 1, |i, j| g[i][j] as f64 / d as f64)
}

/// The objective `scale·(½ γᵀ Hq γ + fᵀ γ)` of spec §3.7 (the constant part dropped).
///
/// For the L2 objectives `Hq` is the exact integer matrix `Pᵀ Δᵀ g Δ P` (Δ the integer
/// second- or third-difference matrix, g the Gram numerators of [`bernstein_gram_exact`]) rounded
/// once per entry, `f = Phi · Pᵀ Δᵀ g Δ s0` (s0 the 0/1 pinned ordinates), and
/// `scale = T·(n_s(n_s−1)/T²)² / D` (accel) or `T·(n_s(n_s−1)(n_s−2)/T³)² / D` (jerk): the solve
/// never sees a rounded product of rounded Gram entries (which put entry errors of ≈ 3e-14·max|Hq|
/// into the degree-30 objective, cond(Hq) ≈ 5e12). The minimiser does not depend on `scale`.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectiveTerms {
    /// `Hq` (p × p), without the scale.
    pub hq: DMatrix<f64>,
    /// `f` (p), without the scale.
    pub f: DVector<f64>,
    /// The common positive factor of the true objective.
    pub scale: f64,
    /// The exact integer terms (L2 objectives): `Hq` and `f = phi·f_int` before rounding.
    pub exact: Option<ExactTerms>,
}

/// The exact integer form of the L2 objective terms.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactTerms {
    /// `Hq` as exact integers.
    pub hq: Vec<Vec<i128>>,
    /// `f / Phi` as exact integers.
    pub f: Vec<i128>,
    /// `Phi` \[rad\].
    pub phi: f64,
}

/// The difference stencil of order `order` applied to the ordinates `s` (integers).
fn int_differences(s: &[i128], order: usize) -> Vec<i128> {
    let mut d = s.to_vec();
    for _ in 0..order {
        d = d.windows(2).map(|w| w[1] - w[0]).collect();
    }
    d
}

/// The objective terms of `objective` (spec §3.7).
#[must_use]
pub fn objective_terms(
    objective: Objective,
    shape: &LawShape,
    gamma_ref: &[f64],
) -> ObjectiveTerms {
    let order = match objective {
        Objective::MinDeviation => {
            return ObjectiveTerms {
                hq: DMatrix::identity(shape.p, shape.p),
                f: -DVector::from_column_slice(gamma_ref),
                scale: 1.0,
                exact: None,
            };
        }
        Objective::MinAccelL2 => 2,
        Objective::MinJerkL2 => 3,
    };
    let (m, p) = (shape.m, shape.p);
    let n_s = 2 * m + p + 1;
    let unit = |slot: Option<usize>| {
        let mut s = vec![0_i128; n_s + 1];
        match slot {
            Some(k) => s[k] = 1,
            None => s[m + p + 1..].fill(1),
        }
        int_differences(&s, order)
    };
    let y0 = unit(None);
    let ys: Vec<Vec<i128>> = (0..p).map(|j| unit(Some(m + 1 + j))).collect();
    let (g, d) = bernstein_gram_exact(n_s - order);
    // The stencils have at most order+1 non-zero entries each: (g·y) only where y is non-zero.
    let form = |a: &[i128], b: &[i128]| -> i128 {
        let mut acc = 0_i128;
        for (i, &ai) in a.iter().enumerate().filter(|(_, x)| **x != 0) {
            for (j, &bj) in b.iter().enumerate().filter(|(_, x)| **x != 0) {
                acc += ai * g[i][j] * bj;
            }
        }
        acc
    };
    let hq_int: Vec<Vec<i128>> = (0..p)
        .map(|i| (0..p).map(|j| form(&ys[i], &ys[j])).collect())
        .collect();
    let f_int: Vec<i128> = (0..p).map(|i| form(&ys[i], &y0)).collect();
    let hq = DMatrix::from_fn(p, p, |i, j| hq_int[i][j] as f64);
    let f = DVector::from_fn(p, |i, _| shape.phi * f_int[i] as f64);
    let t = shape.t;
    let factor = (n_s - order + 1..=n_s).map(|k| k as f64).product::<f64>() / t.powi(order as i32);
    ObjectiveTerms {
        hq,
        f,
        scale: t * factor * factor / d as f64,
        exact: Some(ExactTerms {
            hq: hq_int,
            f: f_int,
            phi: shape.phi,
        }),
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

/// The factored KKT system `[[Hq, Rᵀ], [R, 0]]`: Cholesky of `Hq`, `Y = Hq⁻¹Rᵀ`, and the
/// eigen-decomposition of `Kc = R Y` for its pseudo-inverse (spec §3.7).
struct Kkt {
    chol: nalgebra::Cholesky<f64, nalgebra::Dyn>,
    r: DMatrix<f64>,
    r0: DVector<f64>,
    y: DMatrix<f64>,
    eig: SymmetricEigen<f64, nalgebra::Dyn>,
    lmax: f64,
}

impl Kkt {
    fn new(hq: &DMatrix<f64>, rows: &[ResidualRows]) -> Result<Self, SolveError> {
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
        let y = chol.solve(&r.transpose()); // Hq⁻¹ Rᵀ  (p × nc)
        let kc = &r * &y;
        let kc = (&kc + kc.transpose()) * 0.5;
        let eig = SymmetricEigen::new(kc);
        let lmax = eig.eigenvalues.iter().fold(0.0_f64, |a, &b| a.max(b));
        Ok(Self {
            chol,
            r,
            r0,
            y,
            eig,
            lmax,
        })
    }

    /// `(γ, μ, rank)` with `Hq γ + Rᵀ μ = a`, `R γ = b` (least squares in the dropped
    /// directions of `Kc`).
    fn apply(&self, a: &DVector<f64>, b: &DVector<f64>) -> (DVector<f64>, DVector<f64>, usize) {
        let gamma_u = self.chol.solve(a);
        let rhs = &self.r * &gamma_u - b;
        let mut mu = DVector::zeros(self.r.nrows());
        let mut rank = 0;
        for (i, &l) in self.eig.eigenvalues.iter().enumerate() {
            if self.lmax > 0.0 && l > PINV_REL_TOL * self.lmax {
                rank += 1;
                let v = self.eig.eigenvectors.column(i);
                mu += v * (v.dot(&rhs) / l);
            }
        }
        (gamma_u - &self.y * &mu, mu, rank)
    }
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
    let kkt = Kkt::new(hq, rows)?;
    let (gamma, mu, rank) = kkt.apply(&-f, &-&kkt.r0);
    Ok(Solution {
        gamma: gamma.iter().copied().collect(),
        mu: mu.iter().copied().collect(),
        n_constraints: kkt.r.nrows(),
        rank,
    })
}

/// Refinement steps of [`solve_terms`] (each gains ≈ −log10(cond·ε) digits; two reach the
/// data's own accuracy for cond(Hq) ≤ 1e13, the third confirms).
const REFINE_STEPS: usize = 3;

/// [`solve`] for [`objective_terms`], with mixed-precision iterative refinement when the terms
/// are exact integers (the L2 objectives) and every constraint is kept: the KKT residual is
/// formed in double-double arithmetic from the exact integer `Hq` and `f` (and `R`, `r0` as given),
/// and the correction solved with the same factors. The solve's own error, ≈ cond(Hq)·ε of γ
/// (3e-5 of max|γ| at cond 5e12), falls to the level the data carry.
///
/// # Errors
/// [`SolveError::NotPositiveDefinite`] when `Hq` has no Cholesky factor.
pub fn solve_terms(terms: &ObjectiveTerms, rows: &[ResidualRows]) -> Result<Solution, SolveError> {
    let kkt = Kkt::new(&terms.hq, rows)?;
    let (mut gamma, mut mu, rank) = kkt.apply(&-&terms.f, &-&kkt.r0);
    let nc = kkt.r.nrows();
    if let Some(exact) = terms.exact.as_ref().filter(|_| rank == nc) {
        let p = gamma.len();
        for _ in 0..REFINE_STEPS {
            // a = −f − Hq γ − Rᵀ μ,  b = −r0 − R γ, each accumulated in double-double.
            let a = DVector::from_fn(p, |i, _| {
                let mut acc = Dd::product_int(-exact.f[i], exact.phi);
                for j in 0..p {
                    acc = acc.add(Dd::product_int(-exact.hq[i][j], gamma[j]));
                }
                for c in 0..nc {
                    acc = acc.add(Dd::product(-kkt.r[(c, i)], mu[c]));
                }
                acc.hi + acc.lo
            });
            let b = DVector::from_fn(nc, |c, _| {
                let mut acc = Dd {
                    hi: -kkt.r0[c],
                    lo: 0.0,
                };
                for j in 0..p {
                    acc = acc.add(Dd::product(-kkt.r[(c, j)], gamma[j]));
                }
                acc.hi + acc.lo
            });
            let (dg, dm, _) = kkt.apply(&a, &b);
            gamma += dg;
            mu += dm;
        }
    }
    Ok(Solution {
        gamma: gamma.iter().copied().collect(),
        mu: mu.iter().copied().collect(),
        n_constraints: nc,
        rank,
    })
}

/// A double-double number `hi + lo` (|lo| ≤ ulp(hi)/2): enough for a residual whose terms cancel
/// to 1e-13 of their size.
#[derive(Debug, Clone, Copy)]
struct Dd {
    hi: f64,
    lo: f64,
}

impl Dd {
    /// `x·y` exactly (fused multiply-add gives the rounding error of the product).
    fn product(x: f64, y: f64) -> Self {
        let hi = x * y;
        Self {
            hi,
            lo: x.mul_add(y, -hi),
        }
    }

    /// `n·y` for an integer `n` (|n| < 2^106): `n` split exactly into two doubles.
    fn product_int(n: i128, y: f64) -> Self {
        let nh = n as f64;
        let nl = (n - nh as i128) as f64;
        let p = Self::product(nh, y);
        p.add(Self::product(nl, y))
    }

    /// Sum (Knuth's two-sum, renormalised).
    fn add(self, o: Self) -> Self {
        let s = self.hi + o.hi;
        let bb = s - self.hi;
        let e = (self.hi - (s - bb)) + (o.hi - bb);
        let lo = e + self.lo + o.lo;
        let hi = s + lo;
        Self {
            hi,
            lo: lo - (hi - s),
        }
    }
}
