//! Gauss–Legendre quadrature on `[0, 1]`.
//!
//! Nodes are the roots of the Legendre polynomial `P_q`, found by Newton's method from the
//! Tricomi initial guess (three-term recurrence for `P_q` and its derivative); weights
//! `2 / ((1 − x²) P_q'(x)²)`, halved for `[0, 1]`. Accurate to a few ulp for `q` up to several
//! hundred, which covers every rule the modules use.

/// Largest number of nodes [`gauss_legendre`] builds.
pub const MAX_NODES: usize = 1024;

/// The `q`-point Gauss–Legendre rule on `[0, 1]`: `(nodes, weights)`, nodes increasing.
///
/// `q` is clamped to `1..=MAX_NODES`. The rule integrates polynomials of degree ≤ `2q − 1`
/// exactly (up to round-off); the weights sum to 1.
#[must_use]
pub fn gauss_legendre(q: usize) -> (Vec<f64>, Vec<f64>) {
    let q = q.clamp(1, MAX_NODES);
    let mut nodes = vec![0.0; q];
    let mut weights = vec![0.0; q];
    // q ≤ 1024: every usize → f64 conversion below is exact.
    let qf = q as f64;
    for i in 0..q.div_ceil(2) {
        // Tricomi's approximation of the i-th largest root.
        let k = (i + 1) as f64;
        let theta = std::f64::consts::PI * (4.0 * k - 1.0) / (4.0 * qf + 2.0);
        let mut x = (1.0 - (qf - 1.0) / (8.0 * qf * qf * qf)) * theta.cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre(q, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        let (_, d) = legendre(q, x);
        if d.is_finite() && d != 0.0 {
            dp = d;
        }
        let w = 1.0 / ((1.0 - x * x) * dp * dp);
        // Map [-1, 1] → [0, 1]: node (1 ± x)/2, weight w (= 2/(…)/2).
        nodes[q - 1 - i] = 0.5 * (1.0 + x);
        weights[q - 1 - i] = w;
        nodes[i] = 0.5 * (1.0 - x);
        weights[i] = w;
    }
    (nodes, weights)
}

/// `(P_q(x), P_q'(x))` by the three-term recurrence.
fn legendre(q: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for n in 2..=q {
        let nf = n as f64;
        let p2 = ((2.0 * nf - 1.0) * x * p1 - (nf - 1.0) * p0) / nf;
        p0 = p1;
        p1 = p2;
    }
    if q == 0 {
        return (1.0, 0.0);
    }
    let d = q as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly() {
        for q in [1_usize, 2, 5, 12, 45, 200] {
            let (x, w) = gauss_legendre(q);
            let sum: f64 = w.iter().sum();
            assert!((sum - 1.0).abs() < 1e-13, "q={q} sum={sum}");
            for deg in [0_i32, 1, 2 * q as i32 - 1] {
                let exact = 1.0 / f64::from(deg + 1);
                let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg)).sum();
                assert!((got - exact).abs() < 1e-13, "q={q} deg={deg} {got}");
            }
            assert!(x.windows(2).all(|p| p[0] < p[1]));
        }
    }
}
