//! Benchmarks of `component_importance` (spec `shared/specs/component_importance.md` §7).
//!
//! * criterion groups: the paper request (acceptance < 1 ms), full requests on random DAGs and
//!   cyclic digraphs (acceptance: n = 1000, d = 4, K = 3 < 100 ms), propagation methods and
//!   betweenness algorithms at n = 1000.
//! * accuracy-vs-cost sweeps (printed as markdown tables, only with `cargo bench`): the path cap
//!   K on DAGs against the exact K = ∞ sum P(I−P)^{-1}·1 and the K = 3 value; the propagation
//!   method (exact DFS, K ≤ 3 closed form, walks) on cyclic digraphs against the exact DFS value;
//!   the betweenness definition/algorithm; the enumeration budget; the number of times.
//!
//! Graphs are seeded uniform random DAGs / digraphs with n ∈ {10 … 3000} and mean out-degree
//! d ∈ {2, 4, 8}; n = 3000 exceeds the request limit (2000), so inputs are built directly.
#![allow(missing_docs)] // criterion macros generate undocumented items
#![allow(clippy::unwrap_used)] // benchmarks: a panic is the failure report

#[path = "support/mod.rs"]
mod support;

#[path = "../tests/support/component_importance.rs"]
mod synthetic_request;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use mechcalc::calc::component_importance::centrality::kendall_tau_b;
use mechcalc::calc::component_importance::compute::{self, PropagationAlgorithm};
use mechcalc::calc::component_importance::error::Work;
use mechcalc::calc::component_importance::graph::Digraph;
use mechcalc::calc::component_importance::input::{
    Betweenness, ComponentImportanceInput, Paths, WeightSpec,
};
use mechcalc::calc::component_importance::structure::{self, LevelMode};
use mechcalc::calc::component_importance::synthetic::random_edges;
use mechcalc::calc::component_importance::weights::variable_weights;
use mechcalc::calc::component_importance::wire::{
    BetweennessMode, ComponentImportanceRequest, Outputs,
};
use mechcalc::calc::component_importance::{ComponentImportanceOutput, propagation, run};
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const PAPER_WC: [f64; 2] = [0.520_614, 0.479_386];
const SIZES: [usize; 6] = [10, 30, 100, 300, 1000, 3000];
const DEGREES: [f64; 3] = [2.0, 4.0, 8.0];
/// Skip an exact DFS whose estimated path count n·d^K exceeds this (it would take > ~1 s).
const DFS_PATH_LIMIT: f64 = 3e7;

#[derive(Clone, Copy)]
struct Case {
    n: usize,
    d: f64,
    acyclic: bool,
    seed: u64,
    k: usize,
    method: Paths,
    betweenness: Betweenness,
    n_times: usize,
}

impl Case {
    fn dag(n: usize, d: f64, k: usize) -> Self {
        Self {
            n,
            d,
            acyclic: true,
            seed: 1000 + n as u64 + (d as u64) * 7,
            k,
            method: Paths::Exact,
            betweenness: Betweenness::AllSimplePaths,
            n_times: 1,
        }
    }

    fn cyclic(n: usize, d: f64, k: usize) -> Self {
        Self {
            acyclic: false,
            betweenness: Betweenness::ShortestPaths,
            ..Self::dag(n, d, k)
        }
    }
}

/// A validated-equivalent input built directly (n may exceed the request limit).
fn input(c: &Case) -> ComponentImportanceInput {
    let edges = random_edges(c.n, c.d, c.acyclic, c.seed);
    let (graph, edge_csr) = Digraph::from_edges(c.n, &edges).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed ^ 0xbe7c);
    let weibull = (0..c.n)
        .map(|_| {
            Some((
                rng.random_range(2000.0..30000.0),
                rng.random_range(0.5..1.5),
            ))
        })
        .collect();
    let mode_sum = (0..c.n)
        .map(|_| Some(rng.random_range(0.05..0.5)))
        .collect();
    let times_h: Vec<f64> = (0..c.n_times).map(|i| 500.0 * (i + 1) as f64).collect();
    ComponentImportanceInput {
        ids: (0..c.n).map(|i| format!("C{i}")).collect(),
        graph,
        edge_csr,
        weibull,
        mode_sum,
        efficiency_override: vec![None; c.n],
        level_override: vec![None; c.n],
        f_override: vec![None; times_h.len()],
        ri_override: vec![None; times_h.len()],
        times_h,
        q_in: 0.25,
        o_out: 0.75,
        weights: WeightSpec::Fixed(PAPER_WC),
        path_cap: c.k,
        path_method: c.method,
        levels: LevelMode::Paper,
        betweenness: c.betweenness,
        max_simple_paths: 20_000_000,
        outputs: Outputs::default().into(),
        warnings: Vec::new(),
    }
}

fn paper_request() -> ComponentImportanceRequest {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/api/component_importance/machining_center.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

// ---------------------------------------------------------------------------------------------
// criterion timing groups
// ---------------------------------------------------------------------------------------------

fn bench_paper(c: &mut Criterion) {
    let mut g = c.benchmark_group("component_importance/paper");
    let one = paper_request();
    g.bench_function("run_2_times", |b| {
        b.iter(|| run(black_box(one.clone()), &Budget::unlimited()).unwrap());
    });
    let mut ten = paper_request();
    ten.overrides.clear();
    ten.times_h = (1..=10).map(|i| 400.0 * f64::from(i)).collect();
    g.bench_function("run_10_times_weibull", |b| {
        b.iter(|| run(black_box(ten.clone()), &Budget::unlimited()).unwrap());
    });
    let mut all = paper_request();
    all.outputs = Outputs {
        matrices: true,
        indices: true,
        reliability: true,
        centralities: true,
    };
    g.bench_function("run_2_times_all_outputs", |b| {
        b.iter(|| run(black_box(all.clone()), &Budget::unlimited()).unwrap());
    });
    g.finish();
}

fn bench_requests(c: &mut Criterion) {
    let mut g = c.benchmark_group("component_importance/request_d4_k3");
    for n in [100usize, 1000, 3000] {
        for (label, case) in [
            ("dag", Case::dag(n, 4.0, 3)),
            ("cyclic_shortest", Case::cyclic(n, 4.0, 3)),
        ] {
            let inp = input(&case);
            g.bench_with_input(BenchmarkId::new(label, n), &inp, |b, inp| {
                b.iter(|| compute(black_box(inp)));
            });
        }
    }
    g.finish();
}

fn bench_methods(c: &mut Criterion) {
    let mut g = c.benchmark_group("component_importance/stage_n1000_d4");
    let dag = input(&Case::dag(1000, 4.0, 3));
    let cyc = input(&Case::cyclic(1000, 4.0, 3));
    g.bench_function("betweenness_dag_counting", |b| {
        b.iter(|| {
            structure::simple_path_betweenness_dag(
                &dag.graph,
                &Budget::unlimited(),
                &mut Work::default(),
            )
            .unwrap()
        });
    });
    g.bench_function("betweenness_brandes_cyclic", |b| {
        b.iter(|| {
            structure::shortest_path_betweenness(
                &cyc.graph,
                &Budget::unlimited(),
                &mut Work::default(),
            )
            .unwrap()
        });
    });
    let st = compute(&cyc).structure;
    let x: Vec<f64> = (0..1000)
        .map(|i| 0.05 + 0.3 * ((i * 37 % 101) as f64) / 101.0)
        .collect();
    for (name, algo) in [
        (
            "propagation_k3_closed_form",
            PropagationAlgorithm::ClosedFormK3,
        ),
        ("propagation_k3_dfs", PropagationAlgorithm::SimplePathDfs),
        ("propagation_k3_walks", PropagationAlgorithm::Walks),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                compute::index(
                    &cyc.graph,
                    &st.he,
                    &st.he_row_sum,
                    black_box(&x),
                    3,
                    algo,
                    u64::MAX,
                    &Budget::unlimited(),
                    &mut Work::default(),
                )
                .unwrap()
            });
        });
    }
    g.finish();
}

fn compute(inp: &ComponentImportanceInput) -> ComponentImportanceOutput {
    mechcalc::calc::component_importance::compute(inp, &Budget::unlimited()).unwrap()
}

// ---------------------------------------------------------------------------------------------
// accuracy-vs-cost sweeps
// ---------------------------------------------------------------------------------------------

/// Wall-clock median and worst of several runs, and the mean on-CPU time of this thread per run
/// (from `/proc/thread-self/schedstat`; the shared 2-core machine is heavily loaded, so wall
/// time includes waiting for a core while CPU time does not).
#[derive(Clone, Copy)]
struct Timing {
    median_ms: f64,
    worst_ms: f64,
    cpu_ms: Option<f64>,
}

impl std::fmt::Display for Timing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = |x: f64| {
            if x < 1.0 {
                format!("{x:.4}")
            } else {
                format!("{x:.2}")
            }
        };
        write!(
            f,
            "{} / {} / {}",
            p(self.median_ms),
            p(self.worst_ms),
            self.cpu_ms.map_or("—".to_owned(), p)
        )
    }
}

/// On-CPU time of the calling thread [ns], if the kernel exposes it.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Time `f`: at least 3 runs, more for fast functions (about 0.3 s in total, at most 31 runs),
/// then the mean CPU time per run over a separate loop of at least 0.25 s (the kernel's CPU
/// accounting advances in scheduler ticks, so short totals would read as 0).
fn timed<T>(mut f: impl FnMut() -> T) -> (Timing, T) {
    let t0 = Instant::now();
    let mut last = f();
    let first = t0.elapsed();
    let reps = (Duration::from_millis(300).as_secs_f64() / first.as_secs_f64().max(1e-7))
        .clamp(3.0, 31.0) as usize;
    let mut v = vec![first.as_secs_f64() * 1e3];
    for _ in 1..reps {
        let t = Instant::now();
        last = f();
        v.push(t.elapsed().as_secs_f64() * 1e3);
    }
    v.sort_by(f64::total_cmp);
    let cpu0 = thread_cpu_ns();
    let t1 = Instant::now();
    let mut runs = 0u32;
    while runs < 3 || t1.elapsed() < Duration::from_millis(250) {
        black_box(f());
        runs += 1;
    }
    let cpu_ms = cpu0
        .zip(thread_cpu_ns())
        .map(|(a, b)| (b - a) as f64 / 1e6 / f64::from(runs));
    (
        Timing {
            median_ms: v[v.len() / 2],
            worst_ms: v[v.len() - 1],
            cpu_ms,
        },
        last,
    )
}

fn normalize(raw: &[f64]) -> Vec<f64> {
    let s: f64 = raw.iter().sum();
    if s > 0.0 {
        raw.iter().map(|r| r / s).collect()
    } else {
        vec![0.0; raw.len()]
    }
}

fn ci_of(fp1: &[f64], fp2: &[f64]) -> Vec<f64> {
    fp1.iter()
        .zip(fp2)
        .map(|(&a, &b)| variable_weights([a, b], PAPER_WC).1)
        .collect()
}

fn max_abs(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn fmt_e(x: f64) -> String {
    if x == 0.0 {
        "0".to_owned()
    } else {
        format!("{x:.1e}")
    }
}

/// K on DAGs: full request time, error of normalized fp and CI against the K = ∞ sum and against
/// K = 3, Kendall τ_b of CI vs the K = ∞ ranking, the reported bound.
fn sweep_k_dag() {
    println!(
        "\n### K (path_cap) on random DAGs — full request (`compute`), 1 time, all-simple-path betweenness\n"
    );
    println!(
        "| n | d | m | longest path | K | median / worst / CPU ms | max abs Δfp vs K=∞ | max abs ΔCI vs K=∞ | τ_b vs K=∞ | max abs ΔCI vs K=3 | bound ρ^K/(1−ρ) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for &n in &SIZES {
        for &d in &DEGREES {
            let mut rows = Vec::new();
            for k in 1..=6 {
                let inp = input(&Case::dag(n, d, k));
                let (tm, out) = timed(|| compute(&inp));
                let g = &inp.graph;
                let topo = g.topological_order().unwrap();
                let t = &out.times[0];
                let full = |x: &[f64]| {
                    let p: Vec<f64> = (0..g.m())
                        .map(|e| x[g.tail(e)] * out.structure.he[e])
                        .collect();
                    normalize(&propagation::dag_total_sum(g, &topo, &p))
                };
                let (r1, r2) = (full(&t.f), full(&t.ri));
                let ci_ref = ci_of(&r1, &r2);
                let dfp = max_abs(&t.probability.fp, &r1).max(max_abs(&t.risk.fp, &r2));
                let dci = max_abs(&t.ci, &ci_ref);
                let tau = kendall_tau_b(&t.ci, &ci_ref).unwrap_or(f64::NAN);
                let bound = t
                    .probability
                    .tail_bound
                    .unwrap_or(f64::INFINITY)
                    .max(t.risk.tail_bound.unwrap_or(f64::INFINITY));
                rows.push((
                    k,
                    tm,
                    dfp,
                    dci,
                    tau,
                    t.ci.clone(),
                    bound,
                    g.m(),
                    out.longest_path_edges.unwrap_or(0),
                ));
            }
            let ci_k3 = rows[2].5.clone();
            for (k, tm, dfp, dci, tau, ci, bound, m, lp) in rows {
                let mark = if k == 3 { " (default)" } else { "" };
                println!(
                    "| {n} | {d} | {m} | {lp} | {k}{mark} | {tm} | {} | {} | {tau:.6} | {} | {} |",
                    fmt_e(dfp),
                    fmt_e(dci),
                    fmt_e(max_abs(&ci, &ci_k3)),
                    fmt_e(bound)
                );
            }
        }
    }
}

/// Propagation methods on cyclic digraphs (probability index, structure from shortest-path
/// betweenness): time of one index evaluation and error of the normalized index against the
/// exact DFS value at the same K.
fn sweep_methods_cyclic() {
    println!(
        "\n### Propagation method on random cyclic digraphs — one index (F at 500 h), stage time only\n"
    );
    println!(
        "| n | d | K | DFS exact ms | closed form (K≤3) ms | walks ms | max abs Δfp closed form vs DFS | max abs Δfp walks vs exact | τ_b walks vs exact | bound |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for &n in &SIZES {
        for &d in &DEGREES {
            let inp = input(&Case::cyclic(n, d, 3));
            let out = compute(&inp);
            let g = &inp.graph;
            let st = &out.structure;
            let x = &out.times[0].f;
            let run_algo = |algo, k| {
                compute::index(
                    g,
                    &st.he,
                    &st.he_row_sum,
                    x,
                    k,
                    algo,
                    u64::MAX,
                    &Budget::unlimited(),
                    &mut Work::default(),
                )
                .unwrap()
            };
            for k in 1..=6usize {
                let est = n as f64 * d.powi(k as i32);
                let dfs = (est <= DFS_PATH_LIMIT)
                    .then(|| timed(|| run_algo(PropagationAlgorithm::SimplePathDfs, k)));
                let cf =
                    (k <= 3).then(|| timed(|| run_algo(PropagationAlgorithm::ClosedFormK3, k)));
                let (wt, walks) = timed(|| run_algo(PropagationAlgorithm::Walks, k));
                let exact = dfs
                    .as_ref()
                    .map(|t| t.1.fp.clone())
                    .or_else(|| cf.as_ref().map(|t| t.1.fp.clone()));
                let show = |o: &Option<(Timing, _)>| {
                    o.as_ref().map_or("—".to_owned(), |(t, _)| t.to_string())
                };
                let cf_err = match (&dfs, &cf) {
                    (Some(a), Some(b)) => fmt_e(max_abs(&a.1.fp, &b.1.fp)),
                    _ => "—".to_owned(),
                };
                let (werr, wtau) =
                    exact
                        .as_ref()
                        .map_or(("—".to_owned(), "—".to_owned()), |e| {
                            (
                                fmt_e(max_abs(&walks.fp, e)),
                                format!("{:.6}", kendall_tau_b(&walks.fp, e).unwrap_or(f64::NAN)),
                            )
                        });
                let mark = if k == 3 { " (default)" } else { "" };
                println!(
                    "| {n} | {d} | {k}{mark} | {} | {} | {wt} | {cf_err} | {werr} | {wtau} | {} |",
                    show(&dfs),
                    show(&cf),
                    walks.tail_bound.map_or("void".to_owned(), fmt_e)
                );
            }
        }
    }
}

/// Betweenness algorithms: DAG path counting vs DFS enumeration vs Brandes, and the effect of
/// the (different) shortest-path definition on CI.
fn sweep_betweenness() {
    println!(
        "\n### Betweenness on random DAGs — stage time; CI effect of the shortest-path definition (K = 3, 1 time)\n"
    );
    println!(
        "| n | d | simple paths | DAG counting ms | DFS enumeration ms | max rel Δ counting vs DFS | Brandes ms | max abs ΔCI shortest vs all-simple | τ_b |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &n in &SIZES {
        for &d in &DEGREES {
            let case = Case::dag(n, d, 3);
            let inp = input(&case);
            let g = &inp.graph;
            let topo = g.topological_order().unwrap();
            let (dt, bdag) = timed(|| {
                structure::simple_path_betweenness_dag(
                    g,
                    &Budget::unlimited(),
                    &mut Work::default(),
                )
                .unwrap()
            });
            let paths = count_paths(g, &topo);
            let dfs = (paths <= 2e7).then(|| {
                timed(|| {
                    structure::simple_path_betweenness_enumerated(
                        g,
                        u64::MAX,
                        &Budget::unlimited(),
                        &mut Work::default(),
                    )
                    .unwrap()
                })
            });
            let (bt, _) = timed(|| {
                structure::shortest_path_betweenness(g, &Budget::unlimited(), &mut Work::default())
                    .unwrap()
            });
            let exact = compute(&inp);
            let sp = compute(&input(&Case {
                betweenness: Betweenness::ShortestPaths,
                ..case
            }));
            let dci = max_abs(&exact.times[0].ci, &sp.times[0].ci);
            let tau = kendall_tau_b(&exact.times[0].ci, &sp.times[0].ci).unwrap_or(f64::NAN);
            let (dfs_t, dfs_err) =
                dfs.as_ref()
                    .map_or(("—".to_owned(), "—".to_owned()), |(t, b)| {
                        let rel = b
                            .iter()
                            .zip(&bdag)
                            .map(|(x, y)| (x - y).abs() / y.abs().max(1e-300))
                            .fold(0.0, f64::max);
                        (t.to_string(), fmt_e(rel))
                    });
            println!(
                "| {n} | {d} | {paths:.3e} | {dt} | {dfs_t} | {dfs_err} | {bt} | {} | {tau:.6} |",
                fmt_e(dci)
            );
        }
    }
}

fn count_paths(g: &Digraph, topo: &[usize]) -> f64 {
    // Σ_v (simple paths ending at v): q(v) = Σ_{u∈pred(v)} (1 + q(u)).
    let mut q = vec![0.0f64; g.n()];
    for &v in topo {
        q[v] = g.pred(v).iter().map(|&u| 1.0 + q[u]).sum();
    }
    q.iter().sum()
}

/// (label, edges, n).
type LabelledGraph = (String, Vec<(usize, usize)>, usize);

/// Enumeration budget: cost of all-simple-path betweenness on cyclic digraphs.
fn sweep_enumeration_budget() {
    println!("\n### max_simple_paths — all-simple-path enumeration on cyclic digraphs\n");
    println!(
        "| graph | n | m | simple paths | enumeration ms | CPU ns per path (2 passes) | Brandes ms | max abs ΔCI shortest vs all-simple | τ_b |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut cases: Vec<LabelledGraph> = Vec::new();
    for n in [7usize, 8, 9, 10] {
        let mut e = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if i != j {
                    e.push((i, j));
                }
            }
        }
        cases.push((format!("complete K{n}"), e, n));
    }
    for n in [10usize, 14, 18, 22, 26] {
        cases.push((
            format!("random d=3 seed {}", 77 + n),
            random_edges(n, 3.0, false, 77 + n as u64),
            n,
        ));
    }
    for (label, edges, n) in cases {
        let (g, _) = Digraph::from_edges(n, &edges).unwrap();
        let mut w = Work::default();
        if structure::simple_path_betweenness_enumerated(
            &g,
            100_000_000,
            &Budget::unlimited(),
            &mut w,
        )
        .is_err()
        {
            println!("| {label} | {n} | {} | > 1e8 | — | — | — | — | — |", g.m());
            continue;
        }
        let paths = w.paths / 2;
        let (et, _) = timed(|| {
            structure::simple_path_betweenness_enumerated(
                &g,
                u64::MAX,
                &Budget::unlimited(),
                &mut Work::default(),
            )
            .unwrap()
        });
        let (bt, _) = timed(|| {
            structure::shortest_path_betweenness(&g, &Budget::unlimited(), &mut Work::default())
                .unwrap()
        });
        let mut case = Case::cyclic(n, 3.0, 3);
        case.betweenness = Betweenness::AllSimplePaths;
        let mut a = input(&case);
        let (g2, csr) = Digraph::from_edges(n, &edges).unwrap();
        a.graph = g2;
        a.edge_csr = csr;
        a.max_simple_paths = 100_000_000;
        let exact = compute(&a);
        a.betweenness = Betweenness::ShortestPaths;
        let sp = compute(&a);
        let per_path = et.cpu_ms.unwrap_or(et.median_ms) * 1e6 / (2.0 * paths as f64);
        println!(
            "| {label} | {n} | {} | {paths} | {et} | {per_path:.1} | {bt} | {} | {:.6} |",
            g.m(),
            fmt_e(max_abs(&exact.times[0].ci, &sp.times[0].ci)),
            kendall_tau_b(&exact.times[0].ci, &sp.times[0].ci).unwrap_or(f64::NAN)
        );
    }
}

/// Number of times per request and the acceptance targets.
fn sweep_times_and_acceptance() {
    println!("\n### Times per request and acceptance targets (K = 3)\n");
    println!("| request | median / worst / CPU ms | target |");
    println!("|---|---|---|");
    let paper = paper_request();
    let (t, _) = timed(|| run(paper.clone(), &Budget::unlimited()).unwrap());
    println!(
        "| paper machining center (n = 10, 2 times, `run`: validation + compute + response) | {t} | < 1 ms |"
    );
    let mut ten = paper_request();
    ten.overrides.clear();
    ten.times_h = (1..=10).map(|i| 400.0 * f64::from(i)).collect();
    let (t, _) = timed(|| run(ten.clone(), &Budget::unlimited()).unwrap());
    println!("| paper machining center, 10 times (`run`) | {t} | < 1 ms |");
    let r50 = synthetic_request::random_request(50, 3.0, true, 5);
    let (t, _) = timed(|| run(r50.clone(), &Budget::unlimited()).unwrap());
    println!("| random DAG n = 50, d = 3, 2 times (`run`) | {t} | < 1 ms |");
    let mut r50c = synthetic_request::random_request(50, 3.0, false, 5);
    r50c.options.betweenness = BetweennessMode::ShortestPaths;
    let (t, _) = timed(|| run(r50c.clone(), &Budget::unlimited()).unwrap());
    println!("| random cyclic n = 50, d = 3, shortest paths, 2 times (`run`) | {t} | < 1 ms |");
    for (label, acyclic) in [
        ("DAG, all-simple-path betweenness", true),
        ("cyclic, shortest-path betweenness", false),
    ] {
        for n in [100usize, 1000, 2000, 3000] {
            for nt in [1usize, 10] {
                let mut c = if acyclic {
                    Case::dag(n, 4.0, 3)
                } else {
                    Case::cyclic(n, 4.0, 3)
                };
                c.n_times = nt;
                let inp = input(&c);
                let (t, _) = timed(|| compute(&inp));
                let target = if n == 1000 { "< 100 ms" } else { "" };
                println!("| {label}, n = {n}, d = 4, {nt} time(s) (`compute`) | {t} | {target} |");
            }
        }
    }
}

fn sweeps(_: &mut Criterion) {
    if support::sweep_filters("sweep").is_none() {
        return;
    }
    println!("\n## component_importance accuracy-vs-cost sweeps (release build)");
    sweep_times_and_acceptance();
    sweep_k_dag();
    sweep_methods_cyclic();
    sweep_betweenness();
    sweep_enumeration_budget();
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = bench_paper, bench_requests, bench_methods, sweeps
}
criterion_main!(benches);
