//! Seeded synthetic fault graphs for tests and benchmarks (spec §7): uniform random DAGs (random
//! topological order) and uniform random digraphs with a given mean out-degree. Whole requests on
//! these graphs are built by the test support (`tests/support/component_importance.rs`).

use std::collections::HashSet;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `m = round(n·d)` distinct edges (capped at the maximum possible), uniformly at random.
/// `acyclic`: every edge goes forward in a random permutation of the nodes (a uniform random
/// DAG whose topological order is not the index order); otherwise any ordered pair i ≠ j.
#[must_use]
pub fn random_edges(
    n: usize,
    mean_out_degree: f64,
    acyclic: bool,
    seed: u64,
) -> Vec<(usize, usize)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    if n < 2 {
        return Vec::new();
    }
    let max = if acyclic {
        n * (n - 1) / 2
    } else {
        n * (n - 1)
    };
    let want = (super::structure::to_f64(n) * mean_out_degree.max(0.0)).round();
    // `want` is a small non-negative integer-valued float (≤ 2000 · d).
    let m = (want as usize).min(max);
    let mut perm: Vec<usize> = (0..n).collect();
    perm.shuffle(&mut rng);
    let map = |a: usize, b: usize| -> (usize, usize) {
        if acyclic {
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            (perm[lo], perm[hi])
        } else {
            (a, b)
        }
    };
    if m * 2 > max {
        let mut all: Vec<(usize, usize)> = Vec::with_capacity(max);
        for a in 0..n {
            for b in 0..n {
                if (acyclic && a < b) || (!acyclic && a != b) {
                    all.push(map(a, b));
                }
            }
        }
        all.shuffle(&mut rng);
        all.truncate(m);
        return all;
    }
    let mut seen: HashSet<(usize, usize)> = HashSet::with_capacity(m);
    let mut edges = Vec::with_capacity(m);
    while edges.len() < m {
        let a = rng.random_range(0..n);
        let b = rng.random_range(0..n);
        if a == b {
            continue;
        }
        let e = map(a, b);
        if seen.insert(e) {
            edges.push(e);
        }
    }
    edges
}
