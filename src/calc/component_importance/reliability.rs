//! Two-parameter Weibull reliability of a component at age t (paper Eqs. 7–9, spec §3.7).
//!
//! Units: t and η in the same unit (hours on the wire); λ in 1/(that unit).

/// Weibull failure probability F(t) = 1 − exp(−(t/η)^β), computed as −expm1(−(t/η)^β) so that
/// F keeps full relative precision for t ≪ η (spec §6 H2). `t ≥ 0`, `η > 0`, `β > 0`.
#[must_use]
pub fn failure_probability(t: f64, eta: f64, beta: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    let z = (beta * (t.ln() - eta.ln())).exp();
    -(-z).exp_m1()
}

/// Weibull hazard rate λ(t) = (β/η)·(t/η)^{β−1}, evaluated as
/// exp(ln β − ln η + (β−1)(ln t − ln η)) so that neither t/η nor its power overflows on the way
/// (the result itself is +∞ only when λ exceeds f64). `t > 0`, `η > 0`, `β > 0`.
#[must_use]
pub fn hazard_rate(t: f64, eta: f64, beta: f64) -> f64 {
    let ln_eta = eta.ln();
    (beta - 1.0)
        .mul_add(t.ln() - ln_eta, beta.ln() - ln_eta)
        .exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn weibull_values() {
        // Spec VC2: F from Table 4 at 500 h, S (7832.7, 0.6414).
        assert_relative_eq!(
            failure_probability(500.0, 7832.7, 0.6414),
            0.157_367_161,
            max_relative = 1e-8
        );
        // β = 1 is exponential: λ = 1/η.
        assert_relative_eq!(hazard_rate(123.0, 1000.0, 1.0), 1e-3, max_relative = 1e-14);
        assert_relative_eq!(
            failure_probability(1e-12, 1.0, 1.0),
            1e-12,
            max_relative = 1e-10
        );
    }
}
