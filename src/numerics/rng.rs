//! Seeded random numbers: reproducible ChaCha8 streams (one per purpose, so adding one use of
//! randomness never shifts the draws of another) and the standard normal deviate every module
//! draws the same way.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The ChaCha8 generator of `seed`, on the independent stream `purpose`.
#[must_use]
pub fn stream(seed: u64, purpose: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(purpose);
    r
}

/// A standard normal deviate (Box–Muller, cosine branch; two uniforms per call so the draw
/// order is fixed; `u1` in (0, 1] so the logarithm stays finite).
pub fn normal<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_independent() {
        let (mut a, mut b, mut c) = (stream(7, 1), stream(7, 1), stream(7, 2));
        let (x, y, z) = (normal(&mut a), normal(&mut b), normal(&mut c));
        assert_eq!(x.to_bits(), y.to_bits());
        assert_ne!(x.to_bits(), z.to_bits());
    }

    #[test]
    fn normal_has_unit_moments() {
        let mut r = stream(20_261_125, 0);
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| normal(&mut r)).collect();
        let mean = xs.iter().sum::<f64>() / f64::from(n);
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / f64::from(n - 1);
        // Standard errors: 1/sqrt(n) = 2.2e-3 for the mean, sqrt(2/n) = 3.2e-3 for the variance.
        assert!(mean.abs() < 0.012, "mean {mean}");
        assert!((var - 1.0).abs() < 0.016, "variance {var}");
        assert!(xs.iter().all(|x| x.is_finite()));
    }
}
