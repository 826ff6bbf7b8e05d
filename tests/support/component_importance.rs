//! Seeded synthetic requests of `component_importance` (spec §7) on the module's random fault
//! graphs ([`random_edges`]). Shared by `tests/slow/stress_component_importance.rs` and, through
//! `#[path]`, `benches/component_importance.rs`.

use mechcalc::calc::component_importance::synthetic::random_edges;
use mechcalc::calc::component_importance::wire::{
    ComponentImportanceRequest, ComponentSpec, FailureMode, Options, Outputs, Weibull,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
    request_on(components, &edges)
}

/// A request on `components` with edges between their indices (`(a, b)`: from
/// `components[a]` to `components[b]`), times 500 h and 2000 h, default options and outputs.
#[must_use]
pub fn request_on(
    components: Vec<ComponentSpec>,
    edges: &[(usize, usize)],
) -> ComponentImportanceRequest {
    let edges = edges
        .iter()
        .map(|&(a, b)| [components[a].id.clone(), components[b].id.clone()])
        .collect();
    ComponentImportanceRequest {
        components,
        edges,
        times_h: vec![500.0, 2000.0],
        overrides: Vec::new(),
        options: Options::default(),
        outputs: Outputs::default(),
        time_limit_ms: None,
    }
}
