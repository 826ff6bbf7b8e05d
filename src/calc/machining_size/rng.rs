//! Seeded random streams of the module: one ChaCha8 stream per purpose, so that e.g. adding
//! k-fold CV does not change the column samples of the main model.

use rand::Rng;
use rand::seq::SliceRandom;
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

pub use crate::numerics::rng::{normal, stream};

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
