//! Seeded random streams of the module: one ChaCha8 stream per purpose, so that e.g. adding
//! k-fold CV does not change the column samples of the main model.

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The stream of the train/test permutation.
pub const STREAM_SPLIT: u64 = 1;
/// The stream of the k-fold permutation.
pub const STREAM_FOLDS: u64 = 2;
/// The stream of column and row sampling of one model.
pub const STREAM_SAMPLING: u64 = 3;
/// The stream of SMOGN.
pub const STREAM_SMOGN: u64 = 4;
/// The stream of the SHAP-summary row sample.
pub const STREAM_SHAP_ROWS: u64 = 5;

/// The generator of `purpose` for `seed`.
#[must_use]
pub fn stream(seed: u64, purpose: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(purpose);
    r
}

/// A uniformly random permutation of `0..n`.
#[must_use]
pub fn permutation(rng: &mut ChaCha8Rng, n: usize) -> Vec<u32> {
    let mut p: Vec<u32> = (0..n)
        .map(|i| u32::try_from(i).unwrap_or(u32::MAX))
        .collect();
    p.shuffle(rng);
    p
}

/// `k` distinct indices of `0..n`, ascending (uniform without replacement).
#[must_use]
pub fn sample_sorted(rng: &mut ChaCha8Rng, n: usize, k: usize) -> Vec<usize> {
    let mut v = rand::seq::index::sample(rng, n, k.min(n)).into_vec();
    v.sort_unstable();
    v
}

/// A standard normal deviate (Box–Muller; `u1` in (0, 1] so the logarithm is finite).
#[must_use]
pub fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - rng.random::<f64>();
    let u2 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// A uniform deviate in [0, 1).
#[must_use]
pub fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    rng.random::<f64>()
}

/// A uniform index in `0..n` (`n ≥ 1`).
#[must_use]
pub fn index(rng: &mut ChaCha8Rng, n: usize) -> usize {
    rng.random_range(0..n.max(1))
}
