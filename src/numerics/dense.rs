//! Small dense linear algebra on row-major `Vec<f64>` matrices (written for the continuum-workspace
//! FK Jacobians, general for any square system): LU with partial pivoting (with the
//! determinant sign the stability companion test needs), minimum-norm solves for the statically
//! indeterminate straight-rod states, and the 2-norm condition number.

// Without a target FMA unit `f64::mul_add` is a libm call; plain arithmetic in the inner loops.

use nalgebra::{DMatrix, DVector};

/// A pivot below this fraction of the largest entry of the matrix is treated as zero: the scaled
/// FK Jacobian has O(1) entries, so such a pivot means cond(J) beyond ~1e13, where LU steps are noise
/// and the minimum-norm (SVD) step is used instead.
pub const PIVOT_REL_TOL: f64 = 1e-13;
/// Singular values below this fraction of the largest are dropped in minimum-norm solves (same
/// reasoning as `PIVOT_REL_TOL`).
pub const SVD_REL_CUTOFF: f64 = 1e-13;
/// Reported in place of an infinite condition number (exactly singular matrices); JSON cannot carry inf.
pub const COND_CAP: f64 = 1e20;

/// LU factorisation `P A = L U` of a square matrix.
#[derive(Debug, Clone)]
pub struct Lu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
    parity: f64,
    singular: bool,
}

impl Lu {
    /// Factor the `n x n` row-major matrix `a`.
    #[must_use]
    pub fn new(a: &[f64], n: usize) -> Self {
        let mut m = a.to_vec();
        let scale = m.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        let mut piv: Vec<usize> = (0..n).collect();
        let mut parity = 1.0;
        let mut singular = scale.is_nan() || scale <= 0.0 || !scale.is_finite();
        for k in 0..n {
            let mut p = k;
            let mut best = m[k * n + k].abs();
            for r in (k + 1)..n {
                let v = m[r * n + k].abs();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if best.is_nan() || best <= PIVOT_REL_TOL * scale {
                singular = true;
                continue;
            }
            if p != k {
                for c in 0..n {
                    m.swap(k * n + c, p * n + c);
                }
                piv.swap(k, p);
                parity = -parity;
            }
            let d = m[k * n + k];
            for r in (k + 1)..n {
                let f = m[r * n + k] / d;
                if f == 0.0 {
                    continue;
                }
                m[r * n + k] = f;
                for c in (k + 1)..n {
                    m[r * n + c] -= f * m[k * n + c];
                }
            }
        }
        Self {
            n,
            a: m,
            piv,
            parity,
            singular,
        }
    }

    /// Whether a pivot was (numerically) zero.
    #[must_use]
    pub fn is_singular(&self) -> bool {
        self.singular
    }

    /// Sign of the determinant: +1, -1, or 0 when singular.
    #[must_use]
    pub fn det_sign(&self) -> i8 {
        if self.singular {
            return 0;
        }
        let mut s = self.parity;
        for k in 0..self.n {
            if self.a[k * self.n + k] < 0.0 {
                s = -s;
            }
        }
        if s > 0.0 { 1 } else { -1 }
    }

    /// Solve `A x = b` in place (only meaningful when not singular).
    #[expect(
        clippy::needless_range_loop,
        reason = "triangular solves read clearest with indices"
    )]
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let n = self.n;
        let mut y: Vec<f64> = self.piv.iter().map(|&p| b[p]).collect();
        for r in 0..n {
            let mut s = y[r];
            for c in 0..r {
                s -= self.a[r * n + c] * y[c];
            }
            y[r] = s;
        }
        for r in (0..n).rev() {
            let mut s = y[r];
            for c in (r + 1)..n {
                s -= self.a[r * n + c] * y[c];
            }
            y[r] = s / self.a[r * n + r];
        }
        b.copy_from_slice(&y);
    }
}

/// Minimum-norm least-squares solution of `A x = b` (`A` is `n x n` row-major) by SVD.
#[must_use]
pub fn min_norm_solve(a: &[f64], n: usize, b: &[f64]) -> Vec<f64> {
    let m = DMatrix::from_row_slice(n, n, a);
    let svd = m.svd(true, true);
    let smax = svd.singular_values.iter().fold(0.0f64, |s, &x| s.max(x));
    let eps = (SVD_REL_CUTOFF * smax).max(f64::MIN_POSITIVE);
    match svd.solve(&DVector::from_row_slice(b), eps) {
        Ok(x) => x.iter().copied().collect(),
        // Unreachable: U and V^T were requested above; zeros keep the caller finite regardless.
        Err(_) => vec![0.0; n],
    }
}

/// Solve `A x = b`: LU when regular, minimum-norm SVD otherwise. Returns the solution and the LU.
#[must_use]
pub fn solve(a: &[f64], n: usize, b: &[f64]) -> (Vec<f64>, Lu) {
    let lu = Lu::new(a, n);
    if lu.is_singular() {
        (min_norm_solve(a, n, b), lu)
    } else {
        let mut x = b.to_vec();
        lu.solve_in_place(&mut x);
        (x, lu)
    }
}

/// 2-norm condition number of the `n x n` row-major matrix (capped at [`COND_CAP`]).
#[must_use]
pub fn cond2(a: &[f64], n: usize) -> f64 {
    if a.iter().any(|x| !x.is_finite()) {
        return COND_CAP;
    }
    let m = DMatrix::from_row_slice(n, n, a);
    let sv = m.singular_values();
    let smax = sv.iter().fold(0.0f64, |s, &x| s.max(x));
    let smin = sv.iter().fold(f64::INFINITY, |s, &x| s.min(x));
    if smin > 0.0 && smax.is_finite() {
        (smax / smin).min(COND_CAP)
    } else {
        COND_CAP
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lu_solves_and_signs() {
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let (x, lu) = solve(&a, 3, &[3.0, 2.0, 4.0]);
        for (xi, ei) in x.iter().zip([1.0, 1.0, 1.0]) {
            assert!((xi - ei).abs() < 1e-14);
        }
        // det = 0*(1-0) - 2*(1-0) + 1*(0-3) = -5
        assert_eq!(lu.det_sign(), -1);
    }

    #[test]
    fn singular_uses_min_norm() {
        let a = [1.0, 1.0, 1.0, 1.0];
        let (x, lu) = solve(&a, 2, &[2.0, 2.0]);
        assert!(lu.is_singular());
        assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12);
        assert!(cond2(&a, 2) >= 1e15);
    }
}
