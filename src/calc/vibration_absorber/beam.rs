//! Euler–Bernoulli cantilever modes (spec §3.A): roots of the frequency equation, overflow-safe
//! mode shapes normalised to `∫₀ᴸ φ² dx = L`, and their nodes.

use crate::numerics::roots::bisect;

/// `β_k L`, the k-th root (k ≥ 1) of `1 + cos x cosh x = 0`, solved as `cos x + 1/cosh x = 0`
/// (the same roots, no overflow) by bisection in `[g − ½, g + ½]`, `g = (2k − 1)π/2`, which holds
/// exactly one root.
#[must_use]
pub fn beta_l(k: usize) -> f64 {
    let g = (2.0 * k as f64 - 1.0) * std::f64::consts::FRAC_PI_2;
    let f = |x: f64| x.cos() + 1.0 / x.cosh();
    // The bracket always holds a sign change (cos changes sign at g, 1/cosh x < 0.25 there for
    // k ≥ 2, and k = 1 is checked by the V1 test); fall back to the asymptote g otherwise.
    bisect(f, g - 0.5, g + 0.5).unwrap_or(g)
}

/// Coefficients of one mode shape in the cancellation-safe form of spec §3.A.
#[derive(Debug, Clone, Copy)]
pub struct ModeShape {
    /// `β_k L`.
    pub beta: f64,
    /// `σ_k`.
    sigma: f64,
    /// `e^{−β} + cos β + sin β` (numerator of `1 − σ`).
    num: f64,
    /// `1 + e^{−2β} + 2 cos β e^{−β}` (= `2 e^{−β}(cosh β + cos β)`).
    den: f64,
}

impl ModeShape {
    /// Mode k (≥ 1).
    #[must_use]
    pub fn new(k: usize) -> Self {
        let beta = beta_l(k);
        let em = (-beta).exp();
        let num = em + beta.cos() + beta.sin();
        let den = 1.0 + em * em + 2.0 * beta.cos() * em;
        let one_minus_sigma = num * 2.0 * em / den;
        Self {
            beta,
            sigma: 1.0 - one_minus_sigma,
            num,
            den,
        }
    }

    /// `½[(1−σ)eˢ + (1+σ)e⁻ˢ]` and `s`, for `ξ = x/L` in [0, 1].
    fn hyperbolic(&self, xi: f64) -> (f64, f64) {
        let s = self.beta * xi;
        // (1 − σ) eˢ = num · 2 e^{s−β} / den: bounded for every s ≤ β.
        let a = self.num * 2.0 * (s - self.beta).exp() / self.den;
        let b = (1.0 + self.sigma) * (-s).exp();
        (0.5 * (a + b), s)
    }

    /// `φ_k(x)` at `ξ = x/L` (dimensionless; `φ_k(L) = 2(−1)^{k+1}`).
    #[must_use]
    pub fn phi(&self, xi: f64) -> f64 {
        let (h, s) = self.hyperbolic(xi);
        h - s.cos() + self.sigma * s.sin()
    }

    /// `L²/β² · φ_k''(x)` at `ξ = x/L`: `cosh s + cos s − σ(sinh s + sin s)` in the safe form.
    #[must_use]
    pub fn phi_dd_scaled(&self, xi: f64) -> f64 {
        let (h, s) = self.hyperbolic(xi);
        h + s.cos() - self.sigma * s.sin()
    }

    /// Interior nodes (zeros of `φ_k` in (0, 1)) as `ξ = x/L`, ascending; mode k has k − 1.
    #[must_use]
    pub fn nodes(&self) -> Vec<f64> {
        let n = 64 * (1 + (self.beta as usize));
        let mut out = Vec::new();
        let mut prev = self.phi(1e-6);
        for i in 1..=n {
            let b = i as f64 / n as f64;
            let a = (i - 1) as f64 / n as f64;
            let cur = self.phi(b);
            if prev.signum() != cur.signum()
                && let Some(r) = bisect(|x| self.phi(x), a.max(1e-6), b)
            {
                out.push(r);
            }
            prev = cur;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tip_value_is_two_with_alternating_sign() {
        for k in 1..=50 {
            let m = ModeShape::new(k);
            let want = if k % 2 == 1 { 2.0 } else { -2.0 };
            assert!((m.phi(1.0) - want).abs() < 1e-12, "k={k}: {}", m.phi(1.0));
            assert!(m.phi(0.0).abs() < 1e-12, "k={k}");
            assert_eq!(m.nodes().len(), k - 1, "k={k}");
        }
    }
}
