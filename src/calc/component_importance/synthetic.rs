//! Seeded synthetic fault graphs and requests for tests and benchmarks (spec §7): uniform random
//! DAGs (random topological order) and uniform random digraphs with a given mean out-degree.

use std::collections::HashSet;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::wire::{
    ComponentImportanceRequest, ComponentSpec, FailureMode, Options, Outputs, Weibull,
};

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

/// A complete request on [`random_edges`]: ids `C0..`, Weibull η ∈ [2000, 30000] h,
/// β ∈ [0.5, 1.5], 1–4 failure modes with Σα = 1, times 500 h and 2000 h, default options.
#[must_use]
pub fn random_request(
    n: usize,
    mean_out_degree: f64,
    acyclic: bool,
    seed: u64,
) -> ComponentImportanceRequest {
    let edges = random_edges(n, mean_out_degree, acyclic, seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed_cafe);
    let components = (0..n)
        .map(|i| {
            let k = rng.random_range(1..=4usize);
            let raw: Vec<f64> = (0..k).map(|_| rng.random_range(0.1..1.0)).collect();
            let total: f64 = raw.iter().sum();
            ComponentSpec {
                id: format!("C{i}"),
                weibull: Some(Weibull {
                    eta_h: rng.random_range(2000.0..30000.0),
                    beta: rng.random_range(0.5..1.5),
                }),
                failure_modes: Some(
                    raw.iter()
                        .map(|a| FailureMode {
                            alpha: a / total,
                            impact: rng.random_range(0.0..0.6),
                        })
                        .collect(),
                ),
                mode_sum: None,
                efficiency_override: None,
                level_override: None,
            }
        })
        .collect();
    ComponentImportanceRequest {
        components,
        edges: edges
            .iter()
            .map(|&(a, b)| [format!("C{a}"), format!("C{b}")])
            .collect(),
        times_h: vec![500.0, 2000.0],
        overrides: Vec::new(),
        options: Options::default(),
        outputs: Outputs::default(),
        time_limit_ms: None,
    }
}
