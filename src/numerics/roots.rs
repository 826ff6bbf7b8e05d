//! One-dimensional roots and extrema: bracketed bisection to the last bit ([`bisect`]) and
//! bounded maximisation by Brent's method ([`maximize`]: golden section with parabolic steps;
//! R. P. Brent, "Algorithms for Minimization without Derivatives", 1973, ch. 5, procedure
//! `localmin`).

/// A root of `f` in `[lo, hi]` where `f(lo)` and `f(hi)` differ in sign (bisection to the last
/// bit, at most 200 halvings); `None` without a sign change.
pub fn bisect(mut f: impl FnMut(f64) -> f64, mut lo: f64, mut hi: f64) -> Option<f64> {
    let (mut flo, fhi) = (f(lo), f(hi));
    if flo == 0.0 {
        return Some(lo);
    }
    if fhi == 0.0 {
        return Some(hi);
    }
    if flo.signum() == fhi.signum() || !flo.is_finite() || !fhi.is_finite() {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let fm = f(mid);
        if fm == 0.0 {
            return Some(mid);
        }
        if fm.signum() == flo.signum() {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Result of [`maximize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaxResult {
    /// Arg max found.
    pub x: f64,
    /// f(x).
    pub fx: f64,
    /// Function evaluations.
    pub evaluations: u64,
}

/// (3 − √5)/2, the golden-section fraction.
const GOLDEN: f64 = 0.381_966_011_250_105_1;
/// Relative part of the step tolerance: a few ulps, so steps never fall below the spacing of floats at x.
const REL_TOL: f64 = 4.0 * f64::EPSILON;

/// Maximise `f` on [a, b] to a bracket half-width ≤ `tol` (absolute, plus a few ulps of x), at most
/// `max_iter` iterations. Returns the best point evaluated. `f` must be finite on [a, b].
pub fn maximize(
    mut f: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    tol: f64,
    max_iter: u32,
) -> MaxResult {
    let (mut a, mut b) = if a <= b { (a, b) } else { (b, a) };
    let mut x = GOLDEN.mul_add(b - a, a);
    let mut w = x;
    let mut v = x;
    // Minimise g = −f.
    let mut fx = -f(x);
    let mut fw = fx;
    let mut fv = fx;
    let mut evaluations = 1u64;
    let mut d: f64 = 0.0;
    let mut e: f64 = 0.0;
    for _ in 0..max_iter {
        let xm = 0.5 * (a + b);
        let tol1 = REL_TOL.mul_add(x.abs(), tol / 3.0);
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= 0.5f64.mul_add(-(b - a), tol2) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // Parabola through x, w, v.
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v).mul_add(q, -(x - w) * r);
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let e_prev = e;
            if p.abs() < (0.5 * q * e_prev).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if xm >= x { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= xm { a - x } else { b - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else if d >= 0.0 {
            x + tol1
        } else {
            x - tol1
        };
        let fu = -f(u);
        evaluations += 1;
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            v = w;
            fv = fw;
            w = x;
            fw = fx;
            x = u;
            fx = fu;
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || (w - x).abs() < f64::MIN_POSITIVE {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if fu <= fv
                || (v - x).abs() < f64::MIN_POSITIVE
                || (v - w).abs() < f64::MIN_POSITIVE
            {
                v = u;
                fv = fu;
            }
        }
    }
    MaxResult {
        x,
        fx: -fx,
        evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisect_finds_sqrt2() {
        let r = bisect(|x| x * x - 2.0, 0.0, 2.0).expect("bracket");
        assert!((r - 2.0_f64.sqrt()).abs() < 4e-16);
        assert!(bisect(|x| x * x + 1.0, 0.0, 2.0).is_none());
    }

    #[test]
    fn finds_parabola_max() {
        let r = maximize(|x| -(x - 0.3).powi(2) + 2.0, 0.0, 1.0, 1e-10, 200);
        assert!((r.x - 0.3).abs() < 1e-7, "{r:?}");
        assert!((r.fx - 2.0).abs() < 1e-14);
        assert!(r.evaluations < 60);
    }

    #[test]
    fn finds_non_quadratic_max() {
        let r = maximize(|x: f64| x.sin() * (-0.1 * x).exp(), 0.5, 2.5, 1e-10, 200);
        let xstar = 10f64.atan();
        assert!((r.x - xstar).abs() < 1e-7, "{r:?}");
    }

    #[test]
    fn handles_edge_max() {
        let r = maximize(|x| x, 0.0, 1.0, 1e-10, 200);
        assert!(r.x > 1.0 - 1e-9, "{r:?}");
    }
}
