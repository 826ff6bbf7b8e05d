//! Small dense linear algebra on nalgebra's `DMatrix` that more than one method needs: a guarded
//! matrix exponential, balanced complex eigenvalues and a bracketing root finder.

use nalgebra::{Complex, DMatrix, DVector, Dim, Matrix, Matrix4, StorageMut};

/// `exp(a)` by nalgebra's scaling-and-squaring Padé (Al-Mohy–Higham, ported from SciPy) applied to
/// the balanced matrix, `exp(A) = D exp(D⁻¹AD) D⁻¹` (power-of-two `D`, exact), or `None` when `a`
/// or the result is not finite.
///
/// Balancing lowers the norm of badly unit-scaled matrices (a coil row with `K_p/L_c ≈ 1e6` next to
/// unit entries), which saves squarings and the rounding they amplify. nalgebra solves the Padé
/// denominator by LU and unwraps the solution internally, which panics if that denominator is
/// singular; the call is isolated with `catch_unwind` so such a matrix is a typed failure for the caller, never
/// a crashed job. Finite inputs were never observed to reach it.
#[must_use]
pub fn expm(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let (b, d) = balance_with_scaling(a);
    let mut e = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || b.exp())).ok()?;
    for i in 0..e.nrows() {
        for j in 0..e.ncols() {
            e[(i, j)] *= d[i] / d[j];
        }
    }
    e.iter().all(|x| x.is_finite()).then_some(e)
}

/// Parlett–Reinsch balancing: a diagonal similarity `D⁻¹ A D` (powers of two, so exact) that makes
/// row and column norms comparable. Eigenvalues are unchanged; their computed accuracy improves
/// for badly scaled matrices (unit scaling mixing 1e-3 and 1e6 entries).
#[must_use]
pub fn balance(a: &DMatrix<f64>) -> DMatrix<f64> {
    balance_with_scaling(a).0
}

/// [`balance`] and its diagonal `d` (`B = D⁻¹ A D`, `D = diag(d)`).
#[must_use]
pub fn balance_with_scaling(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>) {
    let n = a.nrows();
    let mut d = vec![1.0; n];
    let mut b = a.clone();
    let radix = 2.0_f64;
    for _sweep in 0..64 {
        let mut converged = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += b[(j, i)].abs();
                    r += b[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / radix {
                f *= radix;
                cc *= radix;
                rr /= radix;
            }
            while cc >= rr * radix {
                f /= radix;
                cc /= radix;
                rr *= radix;
            }
            if (cc + rr) < 0.95 * s {
                converged = false;
                d[i] *= f;
                for j in 0..n {
                    b[(i, j)] /= f;
                }
                for j in 0..n {
                    b[(j, i)] *= f;
                }
            }
        }
        if converged {
            break;
        }
    }
    (b, d)
}

/// Eigenvalues of a real square matrix (balanced, then real Schur form), or `None` when the QR
/// iteration does not converge within `30·n` sweeps or the matrix is not finite.
#[must_use]
pub fn eigenvalues(a: &DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    if a.nrows() == 0 {
        return Some(Vec::new());
    }
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let b = balance(a);
    let schur = nalgebra::linalg::Schur::try_new(b, f64::EPSILON, 30 * a.nrows().max(10))?;
    let ev = schur.complex_eigenvalues();
    let v: Vec<Complex<f64>> = ev.iter().copied().collect();
    v.iter()
        .all(|z| z.re.is_finite() && z.im.is_finite())
        .then_some(v)
}

/// [`expm`] for a 4 × 4 matrix: the same balanced scaling-and-squaring Padé on the stack, without
/// heap allocation, for the small systems evaluated many times (the absorber's step response,
/// refined at every bisection level). `None` when `a` or the result is not finite.
#[must_use]
pub fn expm4(a: &Matrix4<f64>) -> Option<Matrix4<f64>> {
    const N: usize = 4;
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let mut b = *a;
    let mut d = [1.0; N];
    balance_in_place(&mut b, &mut d);
    let mut e = std::panic::catch_unwind(move || b.exp()).ok()?;
    for i in 0..N {
        for j in 0..N {
            e[(i, j)] *= d[i] / d[j];
        }
    }
    e.iter().all(|x| x.is_finite()).then_some(e)
}

/// The Parlett–Reinsch sweeps of [`balance_with_scaling`] on any square nalgebra matrix, in place:
/// `b ← D⁻¹ b D` with `D = diag(d)` accumulated into `d` (start from ones).
fn balance_in_place<D: Dim, S: StorageMut<f64, D, D>>(b: &mut Matrix<f64, D, D, S>, d: &mut [f64]) {
    let n = b.nrows();
    let radix = 2.0_f64;
    for _sweep in 0..64 {
        let mut converged = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += b[(j, i)].abs();
                    r += b[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / radix {
                f *= radix;
                cc *= radix;
                rr /= radix;
            }
            while cc >= rr * radix {
                f /= radix;
                cc /= radix;
                rr *= radix;
            }
            if (cc + rr) < 0.95 * s {
                converged = false;
                d[i] *= f;
                for j in 0..n {
                    b[(i, j)] /= f;
                }
                for j in 0..n {
                    b[(j, i)] *= f;
                }
            }
        }
        if converged {
            break;
        }
    }
}

/// One real Schur decomposition of a balanced matrix, kept for reuse: `A = D Q T Qᵀ D⁻¹` with
/// `D = diag(d)` the exact power-of-two balancing of [`balance_with_scaling`], `Q` orthogonal and
/// `T` upper quasi-triangular (1 × 1 and 2 × 2 diagonal blocks).
///
/// Shifted solves `(zI − A)⁻¹ b` then cost one quasi-triangular back substitution, `O(N²)`
/// instead of an `O(N³)` LU per shift, and a linear recurrence can be stepped in the coordinates
/// `u = Qᵀ D⁻¹ s`. Both stay exact where `A` is defective or has repeated eigenvalues (no
/// eigenvectors are formed: `Q` is orthogonal whatever the eigenstructure).
#[derive(Debug, Clone)]
pub struct BalancedSchur {
    /// Balancing diagonal `d`.
    pub d: Vec<f64>,
    /// Orthogonal `Q`.
    pub q: DMatrix<f64>,
    /// Quasi-triangular `T`.
    pub t: DMatrix<f64>,
    /// Eigenvalues (as [`eigenvalues`] returns them, same order).
    pub values: Vec<Complex<f64>>,
    /// Diagonal blocks of `T` as `(first row, size)`, size 1 or 2.
    pub blocks: Vec<(usize, usize)>,
}

impl BalancedSchur {
    /// Decomposes `a` exactly as [`eigenvalues`] does (same balancing, tolerance and sweep
    /// limit, hence the same eigenvalues) and keeps `Q`, `T`. `None` when `a` is empty or not
    /// finite, the iteration does not converge, or `T` is not quasi-triangular (an entry below
    /// the block diagonal, or two consecutive non-zero subdiagonal entries).
    #[must_use]
    pub fn new(a: &DMatrix<f64>) -> Option<Self> {
        let n = a.nrows();
        if n == 0 || !a.iter().all(|x| x.is_finite()) {
            return None;
        }
        let (b, d) = balance_with_scaling(a);
        let schur = nalgebra::linalg::Schur::try_new(b, f64::EPSILON, 30 * n.max(10))?;
        let values: Vec<Complex<f64>> = schur.complex_eigenvalues().iter().copied().collect();
        if !values.iter().all(|z| z.re.is_finite() && z.im.is_finite()) {
            return None;
        }
        let (q, t) = schur.unpack();
        let mut blocks = Vec::with_capacity(n);
        let mut i = 0;
        while i < n {
            let size = if i + 1 < n && t[(i + 1, i)] != 0.0 {
                2
            } else {
                1
            };
            blocks.push((i, size));
            i += size;
        }
        // Nothing below the block diagonal: rows below a block's last row are zero in its columns.
        for &(start, size) in &blocks {
            for j in start..start + size {
                if (start + size..n).any(|r| t[(r, j)] != 0.0) {
                    return None;
                }
            }
        }
        Some(Self {
            d,
            q,
            t,
            values,
            blocks,
        })
    }

    /// Size `N`.
    #[must_use]
    pub fn size(&self) -> usize {
        self.t.nrows()
    }

    /// Input in Schur coordinates: `Qᵀ D⁻¹ b`.
    #[must_use]
    pub fn to_schur(&self, b: &DVector<f64>) -> DVector<f64> {
        let scaled = DVector::from_iterator(b.len(), b.iter().zip(&self.d).map(|(x, d)| x / d));
        self.q.tr_mul(&scaled)
    }

    /// Output row in Schur coordinates: `c D Q` (as a column), so that `c·s = ĉ·u`.
    #[must_use]
    pub fn row_to_schur(&self, c: &DVector<f64>) -> DVector<f64> {
        let scaled = DVector::from_iterator(c.len(), c.iter().zip(&self.d).map(|(x, d)| x * d));
        self.q.tr_mul(&scaled)
    }

    /// Solves `(zI − T) x = y` by block back substitution, column by column (`N²/2`
    /// complex-by-real products). A shift on an eigenvalue gives non-finite entries; the caller
    /// checks. `x` and `y` have length `N`.
    pub fn solve_shifted(&self, z: Complex<f64>, y: &[f64], x: &mut [Complex<f64>]) {
        let t = &self.t;
        for (xi, yi) in x.iter_mut().zip(y) {
            *xi = Complex::new(*yi, 0.0);
        }
        for &(start, size) in self.blocks.iter().rev() {
            if size == 1 {
                x[start] /= z - t[(start, start)];
            } else {
                let (a00, a01) = (z - t[(start, start)], -t[(start, start + 1)]);
                let (a10, a11) = (-t[(start + 1, start)], z - t[(start + 1, start + 1)]);
                let det = a00 * a11 - a01 * a10;
                let (r0, r1) = (x[start], x[start + 1]);
                x[start] = (r0 * a11 - r1 * a01) / det;
                x[start + 1] = (r1 * a00 - r0 * a10) / det;
            }
            // Move the solved block's columns to the right-hand side of the rows above.
            for j in start..start + size {
                let xj = x[j];
                let col = t.column(j);
                for (xi, tij) in x[..start].iter_mut().zip(col.iter()) {
                    *xi += xj * *tij;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_of_a_rotation_generator_is_a_rotation() {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0]);
        let e = expm(&a).expect("finite");
        assert!((e[(0, 0)] - 1.0_f64.cos()).abs() < 1e-15);
        assert!((e[(0, 1)] - 1.0_f64.sin()).abs() < 1e-15);
        assert!(expm(&DMatrix::from_element(2, 2, f64::NAN)).is_none());
    }

    #[test]
    fn expm_of_a_badly_scaled_triangular_matrix() {
        let a = DMatrix::from_row_slice(2, 2, &[-1.0, 1e6, 0.0, -2.0]);
        let e = expm(&a).expect("finite");
        let (e1, e2) = ((-1.0_f64).exp(), (-2.0_f64).exp());
        assert!((e[(0, 0)] - e1).abs() < 1e-15 && (e[(1, 1)] - e2).abs() < 1e-15);
        assert!((e[(0, 1)] / (1e6 * (e1 - e2)) - 1.0).abs() < 1e-14);
        assert!(e[(1, 0)] == 0.0);
    }

    #[test]
    fn balanced_eigenvalues_of_a_badly_scaled_matrix() {
        // Companion-like matrix with eigenvalues -1, -1e3, -1e6 scaled by 1e8 off-diagonal.
        let a = DMatrix::from_row_slice(3, 3, &[-1.0, 1e8, 0.0, 0.0, -1e3, 1e8, 0.0, 0.0, -1e6]);
        let mut ev: Vec<f64> = eigenvalues(&a)
            .expect("converges")
            .iter()
            .map(|z| z.re)
            .collect();
        ev.sort_by(f64::total_cmp);
        assert!(
            (ev[0] + 1e6).abs() < 1e-6 && (ev[1] + 1e3).abs() < 1e-9 && (ev[2] + 1.0).abs() < 1e-12
        );
    }
}
