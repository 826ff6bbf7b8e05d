//! Property tests of `shared/specs/component_importance.md` §5 ("Property tests") on random fault
//! graphs (2 ≤ n ≤ 14, cyclic and acyclic): exactness of the path-sum algorithms against
//! enumeration, normalization, weight and CI bounds, permutation equivariance, monotonicity,
//! the truncation bound, and time-independence of the structure.
//!
//! Case count: 48 per property by default (debug build); `PROPTEST_CASES` overrides it.
#![allow(clippy::unwrap_used)] // tests: a panic is the failure report
#![allow(clippy::suboptimal_flops)] // tests spell formulas as printed, for readability

use mechcalc::calc::component_importance::error::Work;
use mechcalc::calc::component_importance::graph::Digraph;
use mechcalc::calc::component_importance::wire::{
    ComponentImportanceRequest, ComponentImportanceResponse, ComponentSpec, Options, Outputs,
    PathMethod, TimeOverride, Weibull,
};
use mechcalc::calc::component_importance::{centrality, propagation, reliability, run, structure};
use mechcalc::numerics::Budget;
use proptest::prelude::*;

/// Exact algorithms agree to rounding: sums of ≤ 14^3 products of values ≤ 1.
const EXACT_TOL: f64 = 1e-12;
/// Reordering components changes summation orders: results agree to this relative tolerance.
const PERMUTATION_TOL: f64 = 1e-10;
/// Σ fp = 1, Σ ω_b = 1 to rounding.
const SUM_TOL: f64 = 1e-12;

fn config() -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(48);
    ProptestConfig {
        cases,
        ..ProptestConfig::default()
    }
}

/// A random fault graph with component data.
#[derive(Debug, Clone)]
struct Case {
    n: usize,
    edges: Vec<(usize, usize)>,
    eta: Vec<f64>,
    beta: Vec<f64>,
    mode_sum: Vec<f64>,
    times: Vec<f64>,
}

/// `acyclic`: `Some(true)` DAGs only, `Some(false)` any digraph, `None` either.
fn case(acyclic: Option<bool>) -> impl Strategy<Value = Case> {
    (2usize..=14, any::<bool>()).prop_flat_map(move |(n, dag_flip)| {
        let dag = acyclic.unwrap_or(dag_flip);
        (
            prop::collection::vec(0.0f64..1.0, n * n),
            // Cyclic graphs: mean out-degree ≤ 3.5 keeps simple-path enumeration small
            // (spec §6 H8: ~5e2 to 4.5e4 paths for n = 8..14 at out-degree 3).
            0.08f64..if dag {
                0.6
            } else {
                (3.5 / (n as f64 - 1.0)).clamp(0.1, 0.6)
            },
            Just((0..n).collect::<Vec<usize>>()).prop_shuffle(),
            prop::collection::vec(100.0f64..50_000.0, n),
            prop::collection::vec(0.3f64..3.0, n),
            prop::collection::vec(0.0f64..0.6, n),
            prop::collection::vec(1.0f64..20_000.0, 1..=3),
        )
            .prop_map(move |(u, density, perm, eta, beta, mode_sum, times)| {
                let mut edges = Vec::new();
                for i in 0..n {
                    for j in 0..n {
                        if i != j && (!dag || i < j) && u[i * n + j] < density {
                            edges.push((perm[i], perm[j]));
                        }
                    }
                }
                if edges.is_empty() {
                    edges.push((perm[0], perm[1]));
                }
                Case {
                    n,
                    edges,
                    eta,
                    beta,
                    mode_sum,
                    times,
                }
            })
    })
}

fn request(c: &Case) -> ComponentImportanceRequest {
    ComponentImportanceRequest {
        components: (0..c.n)
            .map(|i| ComponentSpec {
                id: format!("c{i}"),
                weibull: Some(Weibull {
                    eta_h: c.eta[i],
                    beta: c.beta[i],
                }),
                failure_modes: None,
                mode_sum: Some(c.mode_sum[i]),
                efficiency_override: None,
                level_override: None,
            })
            .collect(),
        edges: c
            .edges
            .iter()
            .map(|&(a, b)| [format!("c{a}"), format!("c{b}")])
            .collect(),
        times_h: c.times.clone(),
        overrides: Vec::new(),
        options: Options {
            max_simple_paths: Some(1e8),
            ..Options::default()
        },
        outputs: Outputs {
            matrices: true,
            indices: true,
            reliability: true,
            centralities: false,
        },
        time_limit_ms: None,
    }
}

fn run_ok(req: ComponentImportanceRequest) -> ComponentImportanceResponse {
    run(req, &Budget::unlimited()).unwrap()
}

fn graph(c: &Case) -> Digraph {
    Digraph::from_edges(c.n, &c.edges).unwrap().0
}

/// Deterministic edge values in (0, 1] from the case.
fn edge_values(g: &Digraph, c: &Case) -> Vec<f64> {
    (0..g.m())
        .map(|e| 0.05 + 0.95 * c.mode_sum[g.tail(e)] / 0.6 * c.beta[g.head(e)] / 3.0)
        .collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

proptest! {
    #![proptest_config(config())]

    /// Spec §5: exact DFS = K ≤ 3 closed form on any digraph (reference max diff 1.2e-14).
    #[test]
    fn closed_form_equals_dfs(c in case(None)) {
        let g = graph(&c);
        let p = edge_values(&g, &c);
        for k in 1..=3 {
            let cf = propagation::path_sums_closed_form(&g, &p, k).unwrap();
            let dfs = propagation::path_sums_dfs(&g, &p, k, u64::MAX, &Budget::unlimited(), &mut Work::default()).unwrap();
            for l in 0..k {
                for i in 0..c.n {
                    prop_assert!(close(cf[l][i], dfs[l][i], EXACT_TOL), "K={k} L={} i={i}: {} vs {}", l + 1, cf[l][i], dfs[l][i]);
                }
            }
        }
    }

    /// Spec §5: on DAGs `walks` = `exact` (every K ≤ 6); with cycles walks ≥ exact.
    #[test]
    fn walks_versus_exact(c in case(None)) {
        let g = graph(&c);
        let p = edge_values(&g, &c);
        let dag = g.topological_order().is_some();
        for k in 1..=6 {
            let w = propagation::walk_sums(&g, &p, k);
            let e = propagation::path_sums_dfs(&g, &p, k, u64::MAX, &Budget::unlimited(), &mut Work::default()).unwrap();
            for l in 0..k {
                for i in 0..c.n {
                    if dag {
                        prop_assert!(close(w[l][i], e[l][i], EXACT_TOL), "DAG K={k}: {} vs {}", w[l][i], e[l][i]);
                    } else {
                        prop_assert!(w[l][i] >= e[l][i] * (1.0 - EXACT_TOL), "walks < exact");
                    }
                }
            }
        }
    }

    /// Spec §5: the DAG betweenness formula = DFS enumeration (reference 4e-14).
    #[test]
    fn dag_betweenness_equals_enumeration(c in case(Some(true))) {
        let g = graph(&c);
        prop_assert!(g.topological_order().is_some());
        let dp = structure::simple_path_betweenness_dag(&g, &Budget::unlimited(), &mut Work::default()).unwrap();
        let en = structure::simple_path_betweenness_enumerated(&g, u64::MAX, &Budget::unlimited(), &mut Work::default()).unwrap();
        for (a, b) in dp.iter().zip(&en) {
            prop_assert!(close(*a, *b, EXACT_TOL), "{a} vs {b}");
        }
    }

    /// Spec §5: Σ_i fp^u_i = 1; Σ_u ω_b^u(i) = 1; sinks have fp = 0 and CI = 0;
    /// min_u fp ≤ CI ≤ max_u fp and CI ≤ Σ_u ω_c^u fp^u (harmonic ≤ arithmetic); never NaN.
    #[test]
    fn normalization_and_bounds(c in case(None)) {
        let g = graph(&c);
        let out = run_ok(request(&c));
        let wc = out.meta.constant_weights;
        for r in &out.results {
            let (f1, f2) = (r.fp_probability.as_ref().unwrap(), r.fp_risk.as_ref().unwrap());
            let (w1, w2) = (r.weights_probability.as_ref().unwrap(), r.weights_risk.as_ref().unwrap());
            for col in [f1, f2] {
                let s: f64 = col.iter().sum();
                prop_assert!((s - 1.0).abs() < SUM_TOL || col.iter().all(|&x| x == 0.0), "Σfp = {s}");
            }
            for i in 0..c.n {
                prop_assert!(r.ci[i].is_finite() && f1[i].is_finite() && f2[i].is_finite());
                prop_assert!((w1[i] + w2[i] - 1.0).abs() < SUM_TOL);
                let (lo, hi) = (f1[i].min(f2[i]), f1[i].max(f2[i]));
                prop_assert!(r.ci[i] >= lo - 1e-15 && r.ci[i] <= hi + 1e-15);
                prop_assert!(r.ci[i] <= wc[0].mul_add(f1[i], wc[1] * f2[i]) + 1e-15);
                if g.out_degree(i) == 0 {
                    prop_assert!(f1[i] == 0.0 && f2[i] == 0.0 && r.ci[i] == 0.0);
                }
            }
            let mut ranks = r.rank.clone();
            ranks.sort_unstable();
            prop_assert_eq!(ranks, (1..=u32::try_from(c.n).unwrap()).collect::<Vec<_>>());
        }
    }

    /// Spec §5: relabeling/reordering components (and edges) permutes every output.
    #[test]
    fn permutation_equivariance(c in case(None), seed in any::<u64>()) {
        let base = run_ok(request(&c));
        // A permutation of the request order and a reversed edge list.
        let mut order: Vec<usize> = (0..c.n).collect();
        let mut s = seed;
        for i in (1..c.n).rev() {
            s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let j = usize::try_from(s >> 33).unwrap() % (i + 1);
            order.swap(i, j);
        }
        let mut req = request(&c);
        req.components = order.iter().map(|&i| req.components[i].clone()).collect();
        req.edges.reverse();
        let perm = run_ok(req);
        for (ti, (a, b)) in base.results.iter().zip(&perm.results).enumerate() {
            for (k, &i) in order.iter().enumerate() {
                prop_assert!(close(b.ci[k], a.ci[i], PERMUTATION_TOL), "t{ti} CI {} vs {}", b.ci[k], a.ci[i]);
                let (fa, fb) = (a.fp_risk.as_ref().unwrap(), b.fp_risk.as_ref().unwrap());
                prop_assert!(close(fb[k], fa[i], PERMUTATION_TOL));
            }
            // Ranks agree wherever CI values are not (near-)tied.
            for (k1, &i1) in order.iter().enumerate() {
                for (k2, &i2) in order.iter().enumerate() {
                    if a.ci[i1] > a.ci[i2] * (1.0 + 1e-9) + 1e-300 {
                        prop_assert!(b.rank[k1] < b.rank[k2]);
                    }
                }
            }
        }
        let (ma, mb) = (base.matrices.unwrap(), perm.matrices.unwrap());
        for (k, &i) in order.iter().enumerate() {
            prop_assert!(close(mb.t[k], ma.t[i], PERMUTATION_TOL));
            prop_assert!(close(mb.efficiency[k], ma.efficiency[i], PERMUTATION_TOL));
            prop_assert_eq!(mb.levels[k], ma.levels[i]);
        }
    }

    /// Spec §5: F_i(t) increases with t; raw fp¹_i is non-decreasing in every F_k.
    #[test]
    fn monotonicity(c in case(None), bump in 0.001f64..0.5, which in any::<prop::sample::Index>()) {
        for i in 0..c.n {
            let (a, b) = (c.times[0], c.times[0] * 1.5);
            let (fa, fb) = (
                reliability::failure_probability(a, c.eta[i], c.beta[i]),
                reliability::failure_probability(b, c.eta[i], c.beta[i]),
            );
            // Strictly increasing until F rounds to 1.
            prop_assert!(fa < fb || (fa - 1.0).abs() < f64::EPSILON, "F({a}) = {fa}, F({b}) = {fb}");
        }
        let base = run_ok(request(&c));
        let f = base.results[0].f.clone().unwrap();
        let k = which.index(c.n);
        let mut req = request(&c);
        let mut over = TimeOverride { time_h: c.times[0], f: Default::default(), ri: Default::default() };
        over.f.insert(format!("c{k}"), (f[k] + bump).min(1.0));
        req.overrides.push(over);
        let up = run_ok(req);
        let (r0, r1) = (base.results[0].fp_probability_raw.as_ref().unwrap(), up.results[0].fp_probability_raw.as_ref().unwrap());
        for i in 0..c.n {
            prop_assert!(r1[i] >= r0[i] * (1.0 - 1e-13), "fp¹_raw[{i}] fell: {} -> {}", r0[i], r1[i]);
        }
    }

    /// Spec §5: relative truncation error ≤ ρ^K/(1−ρ), checked against P(I−P)^{-1}·1 on DAGs.
    #[test]
    fn truncation_bound_holds_on_dags(c in case(Some(true)), scale in 0.05f64..0.95) {
        let g = graph(&c);
        let topo = g.topological_order().unwrap();
        let raw = edge_values(&g, &c);
        // Scale rows so that ρ = max row sum = `scale`.
        let rho0 = (0..c.n).map(|i| g.out_edges(i).map(|e| raw[e]).sum::<f64>()).fold(0.0, f64::max);
        let p: Vec<f64> = raw.iter().map(|v| v * scale / rho0).collect();
        let inf = propagation::dag_total_sum(&g, &topo, &p);
        for k in 1..=6usize {
            let s = propagation::walk_sums(&g, &p, k);
            let bound = propagation::tail_bound(scale.ln(), k).unwrap();
            for i in 0..c.n {
                let fk: f64 = s.iter().map(|row| row[i]).sum();
                if fk > 0.0 {
                    prop_assert!((inf[i] - fk) / fk <= bound * (1.0 + 1e-9) + 1e-15,
                        "K={k}: {} > {bound}", (inf[i] - fk) / fk);
                }
            }
        }
    }

    /// Spec §5: B, I, levels, T, HE do not depend on t or on reliability inputs.
    #[test]
    fn structure_independent_of_time_and_reliability(c in case(None)) {
        let a = run_ok(request(&c)).matrices.unwrap();
        let mut c2 = c.clone();
        c2.times = vec![c.times[0] * 3.0 + 7.0];
        c2.eta.iter_mut().for_each(|e| *e *= 0.37);
        c2.beta.reverse();
        c2.mode_sum.iter_mut().for_each(|s| *s = 0.6 - *s);
        let b = run_ok(request(&c2)).matrices.unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let evals = |v: &[mechcalc::calc::component_importance::wire::EdgeValue]| v.iter().map(|x| x.value.to_bits()).collect::<Vec<_>>();
        prop_assert_eq!(evals(&a.edge_betweenness), evals(&b.edge_betweenness));
        prop_assert_eq!(evals(&a.he), evals(&b.he));
        prop_assert_eq!(bits(&a.t), bits(&b.t));
        prop_assert_eq!(bits(&a.efficiency), bits(&b.efficiency));
        prop_assert_eq!(a.levels, b.levels);
    }

    /// `walks` on a DAG request equals `exact` bit for bit (same algorithm on DAGs).
    #[test]
    fn walks_request_equals_exact_on_dag(c in case(Some(true))) {
        let a = run_ok(request(&c));
        let mut req = request(&c);
        req.options.path_method = PathMethod::Walks;
        let b = run_ok(req);
        for (x, y) in a.results.iter().zip(&b.results) {
            prop_assert_eq!(x.ci.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), y.ci.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
        }
    }

    /// Brandes edge/node betweenness equals the pair-by-pair definition
    /// Σ_{s≠t} σ_st(e)/σ_st, and its distance summaries equal the plain BFS ones bit for bit.
    #[test]
    fn brandes_matches_definition(c in case(None)) {
        let g = graph(&c);
        let b = structure::shortest_path_betweenness(&g, &Budget::unlimited(), &mut Work::default()).unwrap();
        let n = c.n;
        // All-pairs BFS distances and shortest-path counts.
        let mut dist = vec![vec![usize::MAX; n]; n];
        let mut sigma = vec![vec![0.0f64; n]; n];
        for s in 0..n {
            dist[s][s] = 0;
            sigma[s][s] = 1.0;
            let mut queue = vec![s];
            let mut h = 0;
            while h < queue.len() {
                let v = queue[h];
                h += 1;
                for &w in g.succ(v) {
                    if dist[s][w] == usize::MAX {
                        dist[s][w] = dist[s][v] + 1;
                        queue.push(w);
                    }
                    if dist[s][w] == dist[s][v] + 1 {
                        sigma[s][w] += sigma[s][v];
                    }
                }
            }
        }
        let mut edge = vec![0.0; g.m()];
        let mut node = vec![0.0; n];
        for s in 0..n {
            for t in 0..n {
                if s == t || dist[s][t] == usize::MAX {
                    continue;
                }
                for (e, be) in edge.iter_mut().enumerate() {
                    let (v, w) = (g.tail(e), g.head(e));
                    if dist[s][v] != usize::MAX && dist[w][t] != usize::MAX && dist[s][v] + 1 + dist[w][t] == dist[s][t] {
                        *be += sigma[s][v] * sigma[w][t] / sigma[s][t];
                    }
                }
                for v in 0..n {
                    if v != s && v != t && dist[s][v] != usize::MAX && dist[v][t] != usize::MAX && dist[s][v] + dist[v][t] == dist[s][t] {
                        node[v] += sigma[s][v] * sigma[v][t] / sigma[s][t];
                    }
                }
            }
        }
        for (a, w) in b.edge.iter().zip(&edge) {
            prop_assert!(close(*a, *w, EXACT_TOL), "edge {a} vs {w}");
        }
        for (a, w) in b.node.iter().zip(&node) {
            prop_assert!(close(*a, *w, EXACT_TOL), "node {a} vs {w}");
        }
        let bfs = structure::distances(&g, &Budget::unlimited(), &mut Work::default()).unwrap();
        for i in 0..n {
            prop_assert_eq!(bfs.efficiency[i].to_bits(), b.reach.efficiency[i].to_bits());
            prop_assert_eq!(bfs.reach[i], b.reach.reach[i]);
            prop_assert_eq!(bfs.dist_sum[i].to_bits(), b.reach.dist_sum[i].to_bits());
        }
    }

    /// Kendall τ_b in O(n log n) equals the O(n²) definition, with ties.
    #[test]
    fn kendall_tau_b_matches_definition(x in prop::collection::vec(0u8..5, 2..40), seed in any::<u64>()) {
        let yi: Vec<u64> = x.iter().enumerate().map(|(i, &v)| (u64::from(v) * 7 + (i as u64).wrapping_mul(seed)) % 4).collect();
        let xs: Vec<f64> = x.iter().map(|&v| f64::from(v)).collect();
        let ys: Vec<f64> = yi.iter().map(|&v| f64::from(u32::try_from(v).unwrap())).collect();
        let (mut c, mut d, mut tx, mut ty) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for i in 0..x.len() {
            for j in i + 1..x.len() {
                let a = x[i].cmp(&x[j]);
                let b = yi[i].cmp(&yi[j]);
                match (a.is_eq(), b.is_eq()) {
                    (true, true) => {}
                    (true, false) => tx += 1.0,
                    (false, true) => ty += 1.0,
                    _ if a == b => c += 1.0,
                    _ => d += 1.0,
                }
            }
        }
        let den = ((c + d + tx) * (c + d + ty)).sqrt();
        let want = (den > 0.0).then(|| (c - d) / den);
        let got = centrality::kendall_tau_b(&xs, &ys);
        match (got, want) {
            (Some(g), Some(w)) => prop_assert!((g - w).abs() < 1e-13, "{g} vs {w}"),
            (None, None) => {}
            (g, w) => prop_assert!(false, "{g:?} vs {w:?}"),
        }
    }
}
