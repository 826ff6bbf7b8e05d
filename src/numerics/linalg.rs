//! Small dense linear algebra on nalgebra's `DMatrix` that more than one method needs: a guarded
//! matrix exponential, balanced complex eigenvalues and a bracketing root finder.

use nalgebra::{Complex, DMatrix};

/// `exp(a)` by nalgebra's scaling-and-squaring Padé (Al-Mohy–Higham, ported from SciPy) applied to
/// the balanced matrix, `exp(A) = D exp(D⁻¹AD) D⁻¹` (power-of-two `D`, exact), or `None` when `a`
/// or the result is not finite.
///
/// Balancing lowers the norm of badly unit-scaled matrices (a coil row with `K_p/L_c ≈ 1e6` next to
/// unit entries), which saves squarings and the rounding they amplify. nalgebra solves the Padé
/// denominator with `lu().solve(..).unwrap()`, which panics if that denominator is singular; the
/// call is isolated with `catch_unwind` so such a matrix is a typed failure for the caller, never
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
