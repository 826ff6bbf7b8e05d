//! Stress and rejection tests of `shared/specs/component_importance.md` §2 and §6 (hazards
//! H1–H9): every request must give a typed error or finite numbers — never NaN, never a panic.
//! Sizes from 2 to 2000 components, dense cyclic graphs at the enumeration budget, β at its range
//! ends, times near 0 and far past η, path counts beyond f64, exhausted budgets, and every
//! rejection rule with its JSON pointer.
#![allow(clippy::unwrap_used)] // tests: a panic is the failure report
#![allow(clippy::suboptimal_flops)] // tests spell formulas as printed, for readability

use std::time::Duration;

use mechcalc::calc::component_importance::run;
use mechcalc::calc::component_importance::wire::{
    BetweennessMode, ComponentImportanceRequest, ComponentImportanceResponse, ComponentSpec,
    ConstantWeights, EntropyWeights, FailureMode, Outputs, PathMethod, TimeOverride, Weibull,
};
use mechcalc::calc::{CalcFailure, ProblemClass};
use mechcalc::numerics::Budget;

use crate::support::component_importance::{random_request, request_on};

fn paper() -> ComponentImportanceRequest {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/api/component_importance/machining_center.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn all_outputs(mut r: ComponentImportanceRequest) -> ComponentImportanceRequest {
    r.outputs = Outputs {
        matrices: true,
        indices: true,
        reliability: true,
        centralities: true,
    };
    r
}

/// Every number of a response is finite (serde_json would silently write NaN/∞ as null), and
/// each time's ranks are a permutation of 1..n.
fn assert_finite(resp: &ComponentImportanceResponse) {
    crate::support::finite::assert_finite(resp);
    for r in &resp.results {
        let mut ranks = r.rank.clone();
        ranks.sort_unstable();
        assert_eq!(
            ranks,
            (1..=u32::try_from(r.ci.len()).unwrap()).collect::<Vec<_>>()
        );
    }
}

fn ok(r: ComponentImportanceRequest) -> ComponentImportanceResponse {
    let resp = run(r, &Budget::unlimited()).unwrap();
    assert_finite(&resp);
    resp
}

fn err(r: ComponentImportanceRequest) -> CalcFailure {
    match run(r, &Budget::unlimited()) {
        Ok(_) => panic!("expected a typed error"),
        Err(e) => e,
    }
}

/// The failure names `pointer` among its field issues.
#[track_caller]
fn rejects_at(r: ComponentImportanceRequest, pointer: &str) -> CalcFailure {
    let e = err(r);
    assert!(
        e.errors.iter().any(|i| i.pointer == pointer),
        "expected an issue at {pointer}, got {e}"
    );
    e
}

/// The failure names every one of `pointers` among its field issues.
#[track_caller]
fn rejects_at_all(r: ComponentImportanceRequest, pointers: &[&str]) -> CalcFailure {
    let e = err(r);
    for p in pointers {
        assert!(
            e.errors.iter().any(|i| i.pointer == *p),
            "{p} missing in {e}"
        );
    }
    e
}

fn has_warning(resp: &ComponentImportanceResponse, code: &str) -> bool {
    resp.warnings.iter().any(|w| w.code == code)
}

fn comp(id: &str, eta: f64, beta: f64, s: f64) -> ComponentSpec {
    ComponentSpec {
        id: id.to_owned(),
        weibull: Some(Weibull { eta_h: eta, beta }),
        failure_modes: None,
        mode_sum: Some(s),
        efficiency_override: None,
        level_override: None,
    }
}

/// A request on ids `n0..` with the given edges.
fn graph_request(n: usize, edges: &[(usize, usize)]) -> ComponentImportanceRequest {
    let components = (0..n)
        .map(|i| comp(&format!("n{i}"), 5000.0 + 100.0 * i as f64, 0.8, 0.3))
        .collect();
    request_on(components, edges)
}

fn complete_edges(n: usize) -> Vec<(usize, usize)> {
    let mut e = Vec::new();
    for i in 0..n {
        for j in 0..n {
            if i != j {
                e.push((i, j));
            }
        }
    }
    e
}

// ---------------------------------------------------------------------------------------------
// Rejections (spec §2): 422 with a field path and reason
// ---------------------------------------------------------------------------------------------

#[test]
fn rejects_graph_errors_with_pointers() {
    let mut r = paper();
    r.edges.push(["S".into(), "S".into()]);
    let e = rejects_at(r, "/edges/16");
    assert_eq!(e.class, ProblemClass::InvalidInput);
    assert!(e.to_string().contains("self-loop"), "{e}");

    let mut r = paper();
    r.edges.push(["S".into(), "X".into()]);
    r.edges.push(["Y".into(), "S".into()]);
    rejects_at(r.clone(), "/edges/16/1");
    rejects_at(r, "/edges/17/0");

    let mut r = paper();
    r.edges.push(["S".into(), "M".into()]);
    let e = rejects_at(r, "/edges/16");
    assert!(e.to_string().contains("duplicate edge"), "{e}");

    let mut r = paper();
    r.edges.clear();
    rejects_at(r, "/edges");

    let mut r = paper();
    r.components[3].id = "S".into();
    rejects_at(r, "/components/3/id");
    let mut r = paper();
    r.components[3].id = String::new();
    rejects_at(r, "/components/3/id");
    let mut r = paper();
    r.components[3].id = "x".repeat(65);
    rejects_at(r, "/components/3/id");

    let mut r = paper();
    r.components.truncate(1);
    rejects_at(r, "/components");
    let r = random_request(2001, 1.0, true, 1);
    rejects_at(r, "/components");
}

#[test]
fn rejects_reliability_and_time_errors() {
    let mut r = paper();
    r.components[0].weibull = Some(Weibull {
        eta_h: 0.0,
        beta: 1.0,
    });
    r.components[1].weibull = Some(Weibull {
        eta_h: 1000.0,
        beta: 0.049,
    });
    r.components[2].weibull = Some(Weibull {
        eta_h: 1000.0,
        beta: 20.01,
    });
    r.components[3].weibull = Some(Weibull {
        eta_h: f64::INFINITY,
        beta: 1.0,
    });
    r.components[4].weibull = Some(Weibull {
        eta_h: 1000.0,
        beta: f64::NAN,
    });
    let e = rejects_at_all(
        r,
        &[
            "/components/0/weibull/eta_h",
            "/components/1/weibull/beta",
            "/components/2/weibull/beta",
            "/components/3/weibull/eta_h",
            "/components/4/weibull/beta",
        ],
    );
    // Every issue is collected at once.
    assert_eq!(e.errors.len(), 5, "{e}");

    for (t, k) in [(0.0, 1), (-5.0, 1), (f64::NAN, 1)] {
        let mut r = paper();
        r.times_h[1] = t;
        r.overrides.truncate(1);
        rejects_at(r, &format!("/times_h/{k}"));
    }
    let mut r = paper();
    r.times_h.clear();
    r.overrides.clear();
    rejects_at(r, "/times_h");
    let mut r = paper();
    r.times_h = (1..=1001).map(f64::from).collect();
    r.overrides.clear();
    rejects_at(r, "/times_h");

    let mut r = paper();
    r.components[0].failure_modes = Some(vec![FailureMode {
        alpha: 1.5,
        impact: -1.0,
    }]);
    rejects_at_all(
        r,
        &[
            "/components/0/failure_modes/0/alpha",
            "/components/0/failure_modes/0/impact",
        ],
    );
    let mut r = paper();
    r.components[0].failure_modes = Some(Vec::new());
    rejects_at(r, "/components/0/failure_modes");
    let mut r = paper();
    r.components[0].failure_modes = None;
    rejects_at(r, "/components/0/failure_modes");
    let mut r = paper();
    r.components[0].mode_sum = Some(0.2);
    rejects_at(r, "/components/0/mode_sum");
    let mut r = paper();
    r.components[0].failure_modes = None;
    r.components[0].mode_sum = Some(-0.1);
    rejects_at(r, "/components/0/mode_sum");
    let mut r = paper();
    r.components[0].weibull = None;
    let e = rejects_at(r, "/components/0/weibull");
    assert!(e.to_string().contains("unless overrides"), "{e}");
    let mut r = paper();
    r.components[0].efficiency_override = Some(-1.0);
    r.components[1].level_override = Some(0);
    rejects_at_all(
        r,
        &[
            "/components/0/efficiency_override",
            "/components/1/level_override",
        ],
    );
}

#[test]
fn rejects_override_errors() {
    // Values out of range are refused at the door (all of them at once), unknown ids after it.
    let mut r = paper();
    r.overrides[0].f.insert("S".into(), 1.2);
    r.overrides[1].ri.insert("NC".into(), -1e-6);
    rejects_at_all(r, &["/overrides/0/F/S", "/overrides/1/RI/NC"]);
    let mut r = paper();
    r.overrides[0].f.insert("a/b".into(), 0.1);
    let e = rejects_at(r, "/overrides/0/F/a~1b");
    assert_eq!(e.code, "UNKNOWN_COMPONENT_ID");
    let mut r = paper();
    r.overrides[1].time_h = 1999.0;
    rejects_at(r, "/overrides/1/time_h");
    let mut r = paper();
    r.overrides[1].time_h = 500.0;
    rejects_at(r, "/overrides/1/time_h");
    // Complete overrides (F and RI at every time) replace Weibull data and failure modes.
    let mut r = paper();
    r.components[0].weibull = None;
    r.components[0].failure_modes = None;
    for o in &mut r.overrides {
        o.ri.insert("S".into(), 3e-5);
    }
    ok(r);
}

#[test]
fn rejects_option_errors() {
    let mut r = paper();
    r.options.q_in = Some(0.3);
    let e = rejects_at(r, "/options/o_out");
    assert!(e.to_string().contains("Q + O must equal 1"), "{e}");
    let mut r = paper();
    r.options.q_in = Some(1.2);
    r.options.o_out = Some(-0.2);
    rejects_at_all(r, &["/options/q_in", "/options/o_out"]);
    let mut r = paper();
    r.options.constant_weights = ConstantWeights::Fixed(vec![0.6, 0.5]);
    rejects_at(r, "/options/constant_weights");
    let mut r = paper();
    r.options.constant_weights = ConstantWeights::Fixed(vec![1.0, 0.0]);
    rejects_at(r, "/options/constant_weights/1");
    let mut r = paper();
    r.options.constant_weights = ConstantWeights::Fixed(vec![1.0]);
    rejects_at(r, "/options/constant_weights");
    let mut r = paper();
    r.options.constant_weights = ConstantWeights::Entropy(EntropyWeights {
        subjective: vec![0.5, 0.5],
        entropy_at_h: 1000.0,
    });
    rejects_at(r, "/options/constant_weights/entropy_at_h");
    for k in [0, 9] {
        let mut r = paper();
        r.options.path_cap = Some(k);
        rejects_at(r, "/options/path_cap");
    }
    for m in [999.0, 1.000_000_1e8] {
        let mut r = paper();
        r.options.max_simple_paths = Some(m);
        rejects_at(r, "/options/max_simple_paths");
    }
}

/// Unknown fields are refused by the wire types (deny_unknown_fields).
#[test]
fn rejects_unknown_fields() {
    let mut v: serde_json::Value = serde_json::to_value(paper()).unwrap();
    v["options"]["path_kap"] = 3.into();
    assert!(serde_json::from_value::<ComponentImportanceRequest>(v).is_err());
    let mut v: serde_json::Value = serde_json::to_value(paper()).unwrap();
    v["components"][0]["weibull"]["eta"] = 3.into();
    assert!(serde_json::from_value::<ComponentImportanceRequest>(v).is_err());
}

// ---------------------------------------------------------------------------------------------
// Warnings
// ---------------------------------------------------------------------------------------------

#[test]
fn warns_alpha_sum_and_isolated_components() {
    let mut r = paper();
    r.components[0].failure_modes.as_mut().unwrap()[0].alpha += 0.01;
    r.components.push(comp("Z", 1000.0, 1.0, 0.2));
    let out = ok(r);
    let w = out.warnings.iter().find(|w| w.code == "ALPHA_SUM").unwrap();
    assert_eq!(w.pointer.as_deref(), Some("/components/0/failure_modes"));
    assert!(has_warning(&out, "ISOLATED_COMPONENTS"));
    assert!(out.results.iter().all(|r| r.ci[10] == 0.0));
}

// ---------------------------------------------------------------------------------------------
// Hazards H1–H9
// ---------------------------------------------------------------------------------------------

/// H1/H2: β at its range ends, times near 0 and far past η: finite results; ρ ≥ 1 is warned and
/// its bound reported as null; risk rates beyond f64 are a typed error.
#[test]
fn weibull_extremes_and_times() {
    for beta in [0.05, 0.5, 1.0, 3.0, 20.0] {
        for t in [1e-300, 1e-9, 1e-3, 1.0, 500.0, 1e5, 1e9, 1e300] {
            let mut r = paper();
            r.overrides.clear();
            r.times_h = vec![t];
            for c in &mut r.components {
                c.weibull.as_mut().unwrap().beta = beta;
            }
            match run(all_outputs(r), &Budget::unlimited()) {
                Ok(out) => {
                    assert_finite(&out);
                    let res = &out.results[0];
                    let tb = res.tail_bound.as_ref().unwrap();
                    if tb.risk.is_none() || tb.probability.is_none() {
                        assert!(has_warning(&out, "TRUNCATION_BOUND_VOID"), "β={beta} t={t}");
                    }
                }
                Err(e) => {
                    assert_eq!(e.code, "HAZARD_RATE_OVERFLOW", "β={beta} t={t}: {e}");
                    assert!(e.errors[0].pointer.ends_with("/weibull"));
                }
            }
        }
    }
}

/// H1: β = 0.05 at t = 1e-300 h gives λ ≈ 1e283 /h: normalized indices stay exact (log-space
/// sum), the raw risk index is omitted with a warning, the bound is void.
#[test]
fn huge_risk_rates_are_handled_in_log_space() {
    let mut r = paper();
    r.overrides.clear();
    r.times_h = vec![1e-300];
    for c in &mut r.components {
        c.weibull.as_mut().unwrap().beta = 0.05;
    }
    let out = ok(r);
    assert!(has_warning(&out, "TRUNCATION_BOUND_VOID"));
    assert!(has_warning(&out, "RAW_INDEX_OVERFLOW"));
    let res = &out.results[0];
    assert!(res.fp_risk_raw.is_none());
    let s: f64 = res.fp_risk.as_ref().unwrap().iter().sum();
    assert!((s - 1.0).abs() < 1e-12);
    // Long paths dominate: V (source of the 3-edge paths V→NC→S→M/J) leads the risk index.
    let fr = res.fp_risk.as_ref().unwrap();
    let v = fr[5];
    assert!(fr.iter().all(|&x| x <= v), "{fr:?}");
}

/// λ or RI beyond f64: typed error naming the component.
#[test]
fn hazard_rate_overflow_is_typed() {
    let mut r = paper();
    r.overrides.clear();
    r.times_h = vec![1e300];
    r.components[3].weibull = Some(Weibull {
        eta_h: 1e-300,
        beta: 20.0,
    });
    let e = rejects_at(r, "/components/3/weibull");
    assert_eq!(e.code, "HAZARD_RATE_OVERFLOW");
    let mut r = paper();
    r.overrides.clear();
    r.components[3].failure_modes = None;
    r.components[3].mode_sum = Some(f64::MAX);
    r.components[3].weibull = Some(Weibull {
        eta_h: 1.0,
        beta: 3.0,
    });
    let e = rejects_at(r, "/components/3/weibull");
    assert_eq!(e.code, "HAZARD_RATE_OVERFLOW");
}

/// H2: F tiny but representable keeps full relative precision; F that underflows to 0 gives a
/// zero index column with a warning (not NaN).
#[test]
fn tiny_and_zero_failure_probabilities() {
    // The paper's graph at one time t with every component Weibull(η, β = 20): F = (t/η)^20.
    let at = |t: f64, eta_h: f64| {
        let mut r = paper();
        r.overrides.clear();
        r.times_h = vec![t];
        for c in &mut r.components {
            c.weibull = Some(Weibull { eta_h, beta: 20.0 });
        }
        r
    };
    let out = ok(at(1e-6, 1e6)); // F = 1e-240
    let fp = out.results[0].fp_probability.as_ref().unwrap();
    assert!((fp.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{fp:?}");
    let out = ok(at(1e-10, 1e10)); // F = 1e-400 → 0
    assert!(has_warning(&out, "ZERO_INDEX"));
    assert!(out.results[0].ci.iter().all(|&c| c == 0.0));
}

/// H3: path counts at the edge of f64 on a DAG (layered, width 4, 500 layers: 4^498 ≈ 6e299
/// paths between the end layers); symmetric edges get identical betweenness.
#[test]
fn dag_path_counts_near_f64_limit() {
    let (width, layers) = (4usize, 500usize);
    let n = width * layers;
    let mut edges = Vec::new();
    for l in 0..layers - 1 {
        for a in 0..width {
            for b in 0..width {
                edges.push((l * width + a, (l + 1) * width + b));
            }
        }
    }
    let mut r = graph_request(n, &edges);
    r.outputs.matrices = true;
    r.times_h = vec![500.0];
    let out = ok(r);
    let b = out.matrices.unwrap().edge_betweenness;
    // Within one layer transition all 16 edges are equivalent.
    let mid = (layers / 2) * width * width;
    let v0 = b[mid].value;
    assert!(v0 > 0.0 && v0.is_finite());
    for e in &b[mid..mid + width * width] {
        assert!((e.value - v0).abs() <= 1e-9 * v0, "{} vs {v0}", e.value);
    }
}

/// H3: a 3-wide, 666-layer DAG with skip edges has ≈ 3.3^665 ≈ 1e345 paths end to end: counts
/// beyond f64 are recounted in log space and the result stays finite and normalized.
#[test]
fn dag_path_counts_far_beyond_f64() {
    let layers = 666usize;
    let width = 3usize;
    let n = width * layers;
    let mut edges = Vec::new();
    for l in 0..layers - 1 {
        for a in 0..width {
            for b in 0..width {
                edges.push((l * width + a, (l + 1) * width + b));
            }
            if l + 2 < layers {
                edges.push((l * width + a, (l + 2) * width + a));
            }
        }
    }
    let mut r = graph_request(n, &edges);
    r.times_h = vec![500.0];
    r.outputs.matrices = true;
    let out = ok(r);
    assert!(out.meta.is_dag);
    let m = out.matrices.unwrap();
    let total: f64 = m.hc.iter().map(|e| e.value).sum();
    assert!((total - 1.0).abs() < 1e-9, "ΣHc = {total}");
}

/// H5/H6: ΣB = 0 (no path of length ≥ 2) and ΣI = 0 (all efficiencies overridden to 0).
#[test]
fn zero_betweenness_and_zero_efficiency() {
    // Star: 0 → 1..4. No path has two edges: B = 0 everywhere.
    let mut r = graph_request(5, &[(0, 1), (0, 2), (0, 3), (0, 4)]);
    r.outputs.matrices = true;
    let out = ok(r.clone());
    assert!(out.matrices.unwrap().hc.iter().all(|e| e.value == 0.0));
    assert!(out.results[0].ci[0] > 0.0);
    for c in &mut r.components {
        c.efficiency_override = Some(0.0);
    }
    let out = ok(r);
    assert!(has_warning(&out, "ZERO_INDEX"));
    assert!(out.results.iter().all(|t| t.ci.iter().all(|&c| c == 0.0)));
}

/// H7: structurally identical components with identical inputs get bit-identical values.
#[test]
fn identical_components_are_bit_identical() {
    // Two mirror components 1 and 2, both 0 → {1, 2} → 3, listed with different edge orders.
    let mut r = graph_request(4, &[(2, 3), (0, 1), (1, 3), (0, 2)]);
    for c in &mut r.components {
        c.weibull = Some(Weibull {
            eta_h: 4000.0,
            beta: 0.9,
        });
    }
    r.outputs.centralities = true;
    let out = ok(r);
    for t in &out.results {
        assert_eq!(t.ci[1].to_bits(), t.ci[2].to_bits());
        assert_eq!(t.rank[1] + 1, t.rank[2]);
    }
    let c = out.centralities.unwrap();
    assert_eq!(
        c.pagerank_reversed[1].to_bits(),
        c.pagerank_reversed[2].to_bits()
    );
}

/// H8: dense cyclic graphs at the enumeration budget. The complete digraph on 9 nodes has
/// 986 400 simple paths (< 2e6): accepted; on 10 nodes 9 864 090 (> 2e6): 422 suggesting
/// `shortest_paths`, which then succeeds.
#[test]
fn cyclic_enumeration_budget() {
    let out = ok(graph_request(9, &complete_edges(9)));
    assert!(!out.meta.is_dag);
    assert_eq!(out.meta.simple_paths_enumerated, 2 * 986_400);
    assert_eq!(out.meta.betweenness_algorithm, "simple_path_enumeration");
    assert_eq!(out.meta.propagation_algorithm, "closed_form_k3");

    let r = graph_request(10, &complete_edges(10));
    let e = err(r.clone());
    assert_eq!(e.class, ProblemClass::TooLarge);
    assert_eq!(e.code, "SIMPLE_PATH_BUDGET_EXCEEDED");
    assert!(e.detail.contains("\"shortest_paths\""), "{e}");
    assert_eq!(e.errors[0].pointer, "/options/betweenness");

    let mut r2 = r.clone();
    r2.options.max_simple_paths = Some(1e7);
    let out = ok(r2);
    assert_eq!(out.meta.simple_paths_enumerated, 2 * 9_864_090);

    let mut r3 = r;
    r3.options.betweenness = BetweennessMode::ShortestPaths;
    let out = ok(all_outputs(r3));
    assert_eq!(out.meta.betweenness_algorithm, "brandes_shortest_paths");
    // Symmetric graph, identical inputs except η: every B is 1 (only the direct pair).
    let b = out.matrices.unwrap().edge_betweenness;
    assert!(b.iter().all(|e| (e.value - 1.0).abs() < 1e-12));
}

/// H8: the exact propagation DFS (cyclic, K > 3) has the same budget and suggests `walks`.
#[test]
fn cyclic_propagation_budget() {
    let mut r = graph_request(30, &complete_edges(30));
    r.options.betweenness = BetweennessMode::ShortestPaths;
    r.options.path_cap = Some(5);
    let e = err(r.clone());
    assert_eq!(e.code, "PROPAGATION_PATH_BUDGET_EXCEEDED");
    assert!(e.detail.contains("\"walks\""), "{e}");
    // K = 3 uses the exact closed form, walks the upper bound.
    let mut r3 = r.clone();
    r3.options.path_cap = Some(3);
    let exact = ok(r3.clone());
    r3.options.path_method = PathMethod::Walks;
    let walks = ok(r3);
    assert!(has_warning(&walks, "WALKS_UPPER_BOUND"));
    let (a, b) = (
        exact.results[0].fp_probability_raw.as_ref().unwrap(),
        walks.results[0].fp_probability_raw.as_ref().unwrap(),
    );
    assert!(a.iter().zip(b).all(|(x, y)| y >= x));
    r.options.path_method = PathMethod::Walks;
    r.options.path_cap = Some(8);
    ok(r);
}

/// Exhausted time or evaluation budgets are typed errors naming the stage.
#[test]
fn exhausted_budget_is_typed() {
    let e = run(paper(), &Budget::new(Duration::ZERO)).unwrap_err();
    assert_eq!(e.code, "BUDGET_EXHAUSTED");
    assert_eq!(e.class, ProblemClass::TooLarge);
    let r = graph_request(9, &complete_edges(9));
    let e = run(r, &Budget::unlimited().with_max_evaluations(10_000)).unwrap_err();
    assert_eq!(e.code, "BUDGET_EXHAUSTED");
    assert!(e.detail.contains("MaxEvaluations"), "{e}");
}

/// H9 and sizes: 2 components with one edge; isolated components; 2000 components (DAG with
/// exact betweenness, cyclic with shortest paths + closed form), several times each.
#[test]
fn sizes_from_2_to_2000() {
    let out = ok(all_outputs(graph_request(2, &[(0, 1)])));
    assert!(out.results[0].ci[1] == 0.0, "a sink has CI = 0");
    assert!(out.results[0].ci[0] > 0.0);

    let out = ok(all_outputs(graph_request(6, &[(0, 1)])));
    assert!(has_warning(&out, "ISOLATED_COMPONENTS"));

    let mut r = random_request(2000, 4.0, true, 7);
    r.times_h = vec![1.0, 500.0, 5000.0, 1e6];
    let out = ok(r);
    assert!(out.meta.is_dag);
    assert_eq!(out.meta.propagation_algorithm, "dag_walks");

    let mut r = random_request(2000, 4.0, false, 8);
    r.options.betweenness = BetweennessMode::ShortestPaths;
    r.outputs.centralities = true;
    let out = ok(r);
    assert!(!out.meta.is_dag);
    assert_eq!(out.meta.propagation_algorithm, "closed_form_k3");
}

/// The entropy mode survives degenerate index columns.
#[test]
fn entropy_weights_degenerate() {
    let mut r = graph_request(3, &[(0, 1), (1, 2)]);
    r.options.constant_weights = ConstantWeights::Entropy(EntropyWeights {
        subjective: vec![0.3, 0.7],
        entropy_at_h: 500.0,
    });
    let out = ok(r);
    let w = out.meta.constant_weights;
    assert!((w[0] + w[1] - 1.0).abs() < 1e-12 && w[0] > 0.0 && w[1] > 0.0);
}

/// Mutate every number of the api example to extreme values: each run gives a typed error or
/// finite numbers.
#[test]
fn mutated_api_example_never_gives_nan() {
    let base: serde_json::Value = serde_json::to_value(paper()).unwrap();
    let mut pointers = Vec::new();
    collect_number_pointers(&base, String::new(), &mut pointers);
    let values = [
        0.0, -1.0, 1e-308, 5e-324, 1e-12, 0.999_999, 1.0, 1.000_001, 20.0, 1e12, 1e308,
    ];
    let mut runs = 0;
    for p in &pointers {
        for &x in &values {
            let mut v = base.clone();
            *v.pointer_mut(p).unwrap() = serde_json::json!(x);
            let Ok(mut req) = serde_json::from_value::<ComponentImportanceRequest>(v) else {
                continue; // a decode error: HTTP 400/422 before the calculation
            };
            req.outputs.centralities = true;
            req.outputs.matrices = true;
            req.outputs.reliability = true;
            match run(req, &Budget::unlimited()) {
                Ok(out) => assert_finite(&out),
                Err(e) => assert!(!e.detail.is_empty(), "{p} = {x}"),
            }
            runs += 1;
        }
    }
    assert!(runs > 1000, "{runs}");
}

fn collect_number_pointers(v: &serde_json::Value, at: String, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Number(_) => out.push(at),
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                collect_number_pointers(x, format!("{at}/{i}"), out);
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                let k = k.replace('~', "~0").replace('/', "~1");
                collect_number_pointers(x, format!("{at}/{k}"), out);
            }
        }
        _ => {}
    }
}

/// Random requests of many shapes (seeded): typed error or finite numbers.
#[test]
fn random_graphs_never_give_nan() {
    for seed in 0..60u64 {
        let n = 2 + usize::try_from(seed * 7 % 60).unwrap();
        let d = [0.5, 1.0, 2.0, 3.0, 6.0][usize::try_from(seed % 5).unwrap()];
        let mut r = random_request(n, d, seed % 2 == 0, seed);
        r.options.path_cap = Some(u32::try_from(1 + seed % 8).unwrap());
        r.options.path_method = if seed % 3 == 0 {
            PathMethod::Walks
        } else {
            PathMethod::Exact
        };
        r.times_h = vec![1e-3, 100.0, 1e4, 1e7];
        r.overrides = vec![TimeOverride {
            time_h: 100.0,
            f: [("C0".to_owned(), 1.0)].into_iter().collect(),
            ri: [("C1".to_owned(), 0.0)].into_iter().collect(),
        }];
        match run(all_outputs(r), &Budget::unlimited()) {
            Ok(out) => assert_finite(&out),
            Err(e) => assert_eq!(e.class, ProblemClass::TooLarge, "seed {seed}: {e}"),
        }
    }
}
