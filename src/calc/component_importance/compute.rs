//! The whole method of spec §3: structure once, then reliability, propagation indices, weights
//! and ranking per time; optional centralities. Pure and deterministic.

use super::centrality;
use super::error::{ComponentImportanceError, Work};
use super::graph::Digraph;
use super::input::{Betweenness, ComponentImportanceInput, Finding, Paths, WeightSpec};
use super::propagation::{self, LengthSums};
use super::reliability::{failure_probability, hazard_rate};
use super::structure::{self, Structure};
use super::weights::{entropy_weights, rank_descending, variable_weights};
use crate::numerics::Budget;

/// Normalized indices must sum to 1 to this tolerance in the final check (n ≤ 2000 terms of
/// rounding 1e-16 each, far below it).
const NORMALIZATION_CHECK_TOL: f64 = 1e-9;
/// At most this many ids are named in one warning (the count is always given).
const MAX_IDS_IN_WARNING: usize = 10;

/// How the edge betweenness was computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BetweennessAlgorithm {
    /// Path counting on a DAG (exact, polynomial).
    DagPathCounting,
    /// Depth-first enumeration of all simple paths (exact, budgeted).
    SimplePathEnumeration,
    /// Brandes shortest-path betweenness.
    BrandesShortestPaths,
}

impl BetweennessAlgorithm {
    /// Wire label.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::DagPathCounting => "dag_path_counting",
            Self::SimplePathEnumeration => "simple_path_enumeration",
            Self::BrandesShortestPaths => "brandes_shortest_paths",
        }
    }
}

/// How the propagation sums were computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PropagationAlgorithm {
    /// Mat-vec walk sums on a DAG (= simple paths, exact).
    DagWalks,
    /// K ≤ 3 closed form on a cyclic graph (exact).
    ClosedFormK3,
    /// Depth-first enumeration on a cyclic graph (exact, budgeted).
    SimplePathDfs,
    /// Walk sums on a cyclic graph (upper bound).
    Walks,
}

impl PropagationAlgorithm {
    /// Wire label.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::DagWalks => "dag_walks",
            Self::ClosedFormK3 => "closed_form_k3",
            Self::SimplePathDfs => "simple_path_dfs",
            Self::Walks => "walks",
        }
    }
}

/// One index (probability or risk) at one time.
#[derive(Debug, Clone)]
pub struct IndexOutput {
    /// Normalized index fp^u_i (all 0 if the raw column is 0).
    pub fp: Vec<f64>,
    /// Raw index; `None` when it exceeds the f64 range (normalized values stay exact).
    pub raw: Option<Vec<f64>>,
    /// ln of the raw index (−∞ for 0).
    pub ln_raw: Vec<f64>,
    /// ln ρ, ρ = max_i Σ_j P_ij.
    pub ln_rho: f64,
    /// Truncation bound ρ^K/(1−ρ) (`None` when ρ ≥ 1).
    pub tail_bound: Option<f64>,
}

/// Everything at one time.
#[derive(Debug, Clone)]
pub struct TimeOutput {
    /// t \[h\].
    pub time_h: f64,
    /// F_i(t) used.
    pub f: Vec<f64>,
    /// λ_i(t) [1/h] (0 without Weibull data).
    pub lambda: Vec<f64>,
    /// RI_i(t) used [1/h].
    pub ri: Vec<f64>,
    /// Probability index (u = 1).
    pub probability: IndexOutput,
    /// Risk index (u = 2).
    pub risk: IndexOutput,
    /// Variable weights ω_b¹(i).
    pub weights_probability: Vec<f64>,
    /// Variable weights ω_b²(i).
    pub weights_risk: Vec<f64>,
    /// CI_i(t).
    pub ci: Vec<f64>,
    /// Rank (1 = most important).
    pub rank: Vec<u32>,
}

/// Standard centralities (spec §3.10).
#[derive(Debug, Clone)]
pub struct CentralityOutput {
    /// Out-degree.
    pub out_degree: Vec<f64>,
    /// In-degree.
    pub in_degree: Vec<f64>,
    /// Normalized node betweenness.
    pub betweenness: Vec<f64>,
    /// Outward closeness.
    pub closeness_out: Vec<f64>,
    /// Reversed PageRank.
    pub pagerank_reversed: Vec<f64>,
    /// Kendall τ_b vs CI per time: [out, in, betweenness, closeness, pagerank].
    pub tau_b: Vec<[Option<f64>; 5]>,
}

/// The computed result (domain form).
#[derive(Debug, Clone)]
pub struct ComponentImportanceOutput {
    /// Time-independent structure.
    pub structure: Structure,
    /// Whether the graph is acyclic.
    pub is_dag: bool,
    /// Longest path in edges (DAG only).
    pub longest_path_edges: Option<usize>,
    /// Betweenness algorithm used.
    pub betweenness_algorithm: BetweennessAlgorithm,
    /// Propagation algorithm used.
    pub propagation_algorithm: PropagationAlgorithm,
    /// ω_c used.
    pub constant_weights: [f64; 2],
    /// Per time.
    pub times: Vec<TimeOutput>,
    /// Optional centralities.
    pub centralities: Option<CentralityOutput>,
    /// Warnings (validation warnings first).
    pub warnings: Vec<Finding>,
    /// Work done.
    pub work: Work,
}

fn warn(code: &str, detail: String, pointer: Option<String>) -> Finding {
    Finding {
        code: code.to_owned(),
        detail,
        pointer,
    }
}

fn id_list(ids: &[String], which: &[usize]) -> String {
    let mut s: Vec<String> = which
        .iter()
        .take(MAX_IDS_IN_WARNING)
        .map(|&i| format!("\"{}\"", ids[i]))
        .collect();
    if which.len() > MAX_IDS_IN_WARNING {
        s.push(format!("and {} more", which.len() - MAX_IDS_IN_WARNING));
    }
    s.join(", ")
}

/// Longest path (edges) of a DAG.
fn longest_path(g: &Digraph, topo: &[usize]) -> usize {
    let mut len = vec![0usize; g.n()];
    for &v in topo.iter().rev() {
        len[v] = g.succ(v).iter().map(|&w| len[w] + 1).max().unwrap_or(0);
    }
    len.into_iter().max().unwrap_or(0)
}

/// The time-independent part of a run.
#[derive(Debug, Clone)]
pub struct StructureParts {
    /// B, I, levels, T, Hc, HE.
    pub structure: Structure,
    /// How B was computed.
    pub algorithm: BetweennessAlgorithm,
    /// Distance summaries (when efficiency or centralities needed them).
    pub reach: Option<structure::Reach>,
    /// Unnormalized shortest-path node betweenness (when the Brandes pass ran).
    pub node_betweenness: Option<Vec<f64>>,
}

/// Compute the time-independent structure (spec §3.1–3.6). One Brandes pass serves the
/// shortest-path betweenness, the distances and the comparison centralities when any of them is
/// needed; otherwise a plain BFS gives the distances.
///
/// # Errors
/// Budget and enumeration failures of the betweenness stage.
pub fn compute_structure(
    input: &ComponentImportanceInput,
    is_dag: bool,
    budget: &Budget,
    work: &mut Work,
) -> Result<StructureParts, ComponentImportanceError> {
    let g = &input.graph;
    let need_bfs =
        input.efficiency_override.iter().any(Option::is_none) || input.outputs.centralities;
    let brandes = if input.betweenness == Betweenness::ShortestPaths || input.outputs.centralities {
        Some(structure::shortest_path_betweenness(g, budget, work)?)
    } else {
        None
    };
    let reach = match &brandes {
        Some(b) => Some(b.reach.clone()),
        None if need_bfs => Some(structure::distances(g, budget, work)?),
        None => None,
    };
    let efficiency_computed = reach
        .as_ref()
        .map_or_else(|| vec![0.0; g.n()], |r| r.efficiency.clone());
    let efficiency: Vec<f64> = efficiency_computed
        .iter()
        .zip(&input.efficiency_override)
        .map(|(&c, o)| o.unwrap_or(c))
        .collect();
    let (betweenness, algorithm) = match (input.betweenness, is_dag, &brandes) {
        (Betweenness::ShortestPaths, _, Some(b)) => {
            (b.edge.clone(), BetweennessAlgorithm::BrandesShortestPaths)
        }
        (_, true, _) => (
            structure::simple_path_betweenness_dag(g, budget, work)?,
            BetweennessAlgorithm::DagPathCounting,
        ),
        (_, false, _) => (
            structure::simple_path_betweenness_enumerated(g, input.max_simple_paths, budget, work)?,
            BetweennessAlgorithm::SimplePathEnumeration,
        ),
    };
    let levels = structure::hierarchy_levels(g, input.levels, &input.level_override);
    let s = structure::assemble(
        g,
        efficiency_computed,
        efficiency,
        betweenness,
        levels,
        input.q_in,
        input.o_out,
    );
    Ok(StructureParts {
        structure: s,
        algorithm,
        reach,
        node_betweenness: brandes.map(|b| b.node),
    })
}

/// Per-length propagation sums for edge values `p` with the chosen algorithm.
///
/// # Errors
/// Budget and enumeration failures of the DFS.
pub fn propagation_sums(
    g: &Digraph,
    p: &[f64],
    k: usize,
    algo: PropagationAlgorithm,
    max_paths: u64,
    budget: &Budget,
    work: &mut Work,
) -> Result<LengthSums, ComponentImportanceError> {
    Ok(match algo {
        PropagationAlgorithm::DagWalks | PropagationAlgorithm::Walks => {
            propagation::walk_sums(g, p, k)
        }
        PropagationAlgorithm::ClosedFormK3 => propagation::path_sums_closed_form(g, p, k)
            .ok_or_else(|| ComponentImportanceError::Inconsistent {
                what: format!("closed form requested for K = {k} > 3"),
            })?,
        PropagationAlgorithm::SimplePathDfs => {
            propagation::path_sums_dfs(g, p, k, max_paths, budget, work)?
        }
    })
}

/// One index at one time from the node values x (F or RI), spec §3.8–3.9 step 1.
///
/// # Errors
/// Budget and enumeration failures of the DFS.
#[expect(
    clippy::too_many_arguments,
    reason = "the graph, its weights and the enumeration limits of one index computation"
)]
pub fn index(
    g: &Digraph,
    he: &[f64],
    he_row_sum: &[f64],
    x: &[f64],
    k: usize,
    algo: PropagationAlgorithm,
    max_paths: u64,
    budget: &Budget,
    work: &mut Work,
) -> Result<IndexOutput, ComponentImportanceError> {
    let n = g.n();
    let c = x.iter().copied().fold(0.0, f64::max);
    if c <= 0.0 {
        return Ok(IndexOutput {
            fp: vec![0.0; n],
            raw: Some(vec![0.0; n]),
            ln_raw: vec![f64::NEG_INFINITY; n],
            ln_rho: f64::NEG_INFINITY,
            tail_bound: Some(0.0),
        });
    }
    let xs: Vec<f64> = x.iter().map(|&v| v / c).collect();
    let p: Vec<f64> = (0..g.m()).map(|e| xs[g.tail(e)] * he[e]).collect();
    let sums = propagation_sums(g, &p, k, algo, max_paths, budget, work)?;
    let ln_c = c.ln();
    let ln_raw = propagation::log_index(&sums, ln_c);
    let fp = propagation::normalize_log(&ln_raw).unwrap_or_else(|| vec![0.0; n]);
    let raw: Vec<f64> = ln_raw.iter().map(|l| l.exp()).collect();
    let raw = raw.iter().all(|r| r.is_finite()).then_some(raw);
    let row_max = xs
        .iter()
        .zip(he_row_sum)
        .map(|(a, b)| a * b)
        .fold(0.0, f64::max);
    let ln_rho = ln_c + row_max.ln();
    Ok(IndexOutput {
        fp,
        raw,
        ln_raw,
        ln_rho,
        tail_bound: propagation::tail_bound(ln_rho, k),
    })
}

/// F, λ [1/h] and RI [1/h] per component.
type Rates = (Vec<f64>, Vec<f64>, Vec<f64>);

/// F, λ and RI of every component at time `t` (index `ti`), overrides applied.
fn reliability_at(
    input: &ComponentImportanceInput,
    ti: usize,
    t: f64,
) -> Result<Rates, ComponentImportanceError> {
    let n = input.graph.n();
    let mut f = vec![0.0; n];
    let mut lambda = vec![0.0; n];
    let mut ri = vec![0.0; n];
    for i in 0..n {
        let fo = input.f_override[ti].as_ref().and_then(|r| r[i]);
        let ro = input.ri_override[ti].as_ref().and_then(|r| r[i]);
        if let Some((eta, beta)) = input.weibull[i] {
            lambda[i] = hazard_rate(t, eta, beta);
            f[i] = failure_probability(t, eta, beta);
        }
        if let Some(x) = fo {
            f[i] = x;
        }
        ri[i] = match ro {
            Some(x) => x,
            None => lambda[i] * input.mode_sum[i].unwrap_or(0.0),
        };
        if !lambda[i].is_finite() || !ri[i].is_finite() {
            return Err(ComponentImportanceError::RateOverflow {
                component: i,
                id: input.ids[i].clone(),
                time_index: ti,
                time_h: t,
                lambda: lambda[i],
                ri: ri[i],
            });
        }
    }
    Ok((f, lambda, ri))
}

/// The findings about the two indices at time `t` (index `ti`).
fn index_warnings(
    warnings: &mut Vec<Finding>,
    ti: usize,
    t: f64,
    probability: &IndexOutput,
    risk: &IndexOutput,
) {
    for (name, ix) in [("probability", probability), ("risk", risk)] {
        if ix.ln_raw.iter().all(|l| *l == f64::NEG_INFINITY) {
            warnings.push(warn(
                "ZERO_INDEX",
                format!(
                    "the {name} index is 0 for every component at t = {t} h (no component \
                     with an out-edge has a positive {}); its normalized values are 0",
                    if name == "risk" { "RI" } else { "F" }
                ),
                Some(format!("/times_h/{ti}")),
            ));
        } else if ix.tail_bound.is_none() {
            warnings.push(warn(
                "TRUNCATION_BOUND_VOID",
                format!(
                    "{name} index at t = {t} h: row-sum norm rho = {:.6e} >= 1, so the \
                     truncation bound rho^K/(1-rho) of the path cap is void (the K-capped sum \
                     is still finite)",
                    ix.ln_rho.exp()
                ),
                Some(format!("/times_h/{ti}")),
            ));
        }
        if ix.raw.is_none() {
            warnings.push(warn(
                "RAW_INDEX_OVERFLOW",
                format!(
                    "the raw {name} index at t = {t} h exceeds the f64 range and is omitted; \
                     normalized values are computed in log space and exact"
                ),
                Some(format!("/times_h/{ti}")),
            ));
        }
    }
}

/// The comparison centralities and their Kendall τ-b against CI at every time.
fn centralities(
    input: &ComponentImportanceInput,
    node_betweenness: Option<Vec<f64>>,
    reach: Option<&structure::Reach>,
    times: &[TimeOutput],
    budget: &Budget,
    work: &mut Work,
) -> Result<CentralityOutput, ComponentImportanceError> {
    let g = &input.graph;
    let n = g.n();
    let node_bc = match node_betweenness {
        Some(b) => b,
        None => structure::shortest_path_betweenness(g, budget, work)?.node,
    };
    let pr = centrality::pagerank_reversed(g, budget, work)?;
    let closeness = reach.map_or_else(|| vec![0.0; n], centrality::outward_closeness);
    let out_degree: Vec<f64> = (0..n).map(|i| structure::to_f64(g.out_degree(i))).collect();
    let in_degree: Vec<f64> = (0..n).map(|i| structure::to_f64(g.in_degree(i))).collect();
    let betweenness = centrality::normalized_node_betweenness(&node_bc);
    let tau_b = times
        .iter()
        .map(|t| {
            [&out_degree, &in_degree, &betweenness, &closeness, &pr]
                .map(|m| centrality::kendall_tau_b(m, &t.ci))
        })
        .collect();
    Ok(CentralityOutput {
        out_degree,
        in_degree,
        betweenness,
        closeness_out: closeness,
        pagerank_reversed: pr,
        tau_b,
    })
}

/// Per time: the variable weights, CI and the ranking, from reliability and the two indices.
fn combine(per_time: Vec<PerTime>, constant_weights: [f64; 2], n: usize) -> Vec<TimeOutput> {
    let mut times = Vec::with_capacity(per_time.len());
    for (t, f, lambda, ri, probability, risk) in per_time {
        let mut wp = vec![0.0; n];
        let mut wr = vec![0.0; n];
        let mut ci = vec![0.0; n];
        for i in 0..n {
            let (w, c) = variable_weights([probability.fp[i], risk.fp[i]], constant_weights);
            wp[i] = w[0];
            wr[i] = w[1];
            ci[i] = c;
        }
        let rank = rank_descending(&ci);
        times.push(TimeOutput {
            time_h: t,
            f,
            lambda,
            ri,
            probability,
            risk,
            weights_probability: wp,
            weights_risk: wr,
            ci,
            rank,
        });
    }
    times
}

/// One time's reliability (F, λ, RI) and its two indices, before weighting.
type PerTime = (f64, Vec<f64>, Vec<f64>, Vec<f64>, IndexOutput, IndexOutput);

/// The findings about the graph as a whole: walks on a cyclic graph, isolated components.
fn graph_warnings(
    input: &ComponentImportanceInput,
    propagation_algorithm: PropagationAlgorithm,
    warnings: &mut Vec<Finding>,
) {
    let g = &input.graph;
    let n = g.n();
    if propagation_algorithm == PropagationAlgorithm::Walks {
        warnings.push(warn(
            "WALKS_UPPER_BOUND",
            "path_method \"walks\" on a graph with cycles counts walks that revisit components: \
             the raw indices are upper bounds of the simple-path values (use \"exact\" for the \
             paper's definition; path_cap <= 3 is exact in polynomial time)"
                .to_owned(),
            Some("/options/path_method".to_owned()),
        ));
    }
    let isolated: Vec<usize> = (0..n)
        .filter(|&i| g.in_degree(i) == 0 && g.out_degree(i) == 0)
        .collect();
    if !isolated.is_empty() {
        warnings.push(warn(
            "ISOLATED_COMPONENTS",
            format!(
                "{} component(s) have no edges and get CI = 0: {}",
                isolated.len(),
                id_list(&input.ids, &isolated)
            ),
            None,
        ));
    }
}

/// Run the whole method.
///
/// # Errors
/// [`ComponentImportanceError`] for over-budget enumeration, an exhausted time budget, a hazard
/// rate beyond f64, or a failed final consistency check.
pub fn compute(
    input: &ComponentImportanceInput,
    budget: &Budget,
) -> Result<ComponentImportanceOutput, ComponentImportanceError> {
    let g = &input.graph;
    let n = g.n();
    let mut work = Work::default();
    let mut warnings = input.warnings.clone();
    let topo = g.topological_order();
    let is_dag = topo.is_some();
    let StructureParts {
        structure: st,
        algorithm: betweenness_algorithm,
        reach,
        node_betweenness,
    } = compute_structure(input, is_dag, budget, &mut work)?;
    let k = input.path_cap;
    let propagation_algorithm = match (input.path_method, is_dag) {
        (_, true) => PropagationAlgorithm::DagWalks,
        (Paths::Walks, false) => PropagationAlgorithm::Walks,
        (Paths::Exact, false) if k <= 3 => PropagationAlgorithm::ClosedFormK3,
        (Paths::Exact, false) => PropagationAlgorithm::SimplePathDfs,
    };
    graph_warnings(input, propagation_algorithm, &mut warnings);

    // Per time: reliability and the two indices.
    let mut per_time = Vec::with_capacity(input.times_h.len());
    for (ti, &t) in input.times_h.iter().enumerate() {
        work.check(budget, "per-time indices")?;
        let (f, lambda, ri) = reliability_at(input, ti, t)?;
        let probability = index(
            g,
            &st.he,
            &st.he_row_sum,
            &f,
            k,
            propagation_algorithm,
            input.max_simple_paths,
            budget,
            &mut work,
        )?;
        let risk = index(
            g,
            &st.he,
            &st.he_row_sum,
            &ri,
            k,
            propagation_algorithm,
            input.max_simple_paths,
            budget,
            &mut work,
        )?;
        index_warnings(&mut warnings, ti, t, &probability, &risk);
        per_time.push((t, f, lambda, ri, probability, risk));
    }

    // Constant weights.
    let constant_weights = match input.weights {
        WeightSpec::Fixed(w) => w,
        WeightSpec::Entropy {
            subjective,
            time_index,
        } => {
            let (_, _, _, _, p, r) = &per_time[time_index];
            if let Some(e) = entropy_weights(&p.fp, &r.fp) {
                [0.5 * (subjective[0] + e[0]), 0.5 * (subjective[1] + e[1])]
            } else {
                warnings.push(warn(
                    "ENTROPY_WEIGHTS_UNDEFINED",
                    "both index columns carry no entropy information at entropy_at_h (uniform \
                     or zero); the subjective weights are used alone"
                        .to_owned(),
                    Some("/options/constant_weights/entropy_at_h".to_owned()),
                ));
                subjective
            }
        }
    };

    let times = combine(per_time, constant_weights, n);

    let centralities = if input.outputs.centralities {
        Some(centralities(
            input,
            node_betweenness,
            reach.as_ref(),
            &times,
            budget,
            &mut work,
        )?)
    } else {
        None
    };

    let out = ComponentImportanceOutput {
        structure: st,
        is_dag,
        longest_path_edges: topo.as_deref().map(|t| longest_path(g, t)),
        betweenness_algorithm,
        propagation_algorithm,
        constant_weights,
        times,
        centralities,
        warnings,
        work,
    };
    verify(&out)?;
    Ok(out)
}

/// Final check before returning (Ruckig-style): finite numbers, normalized columns sum to 1,
/// CI between the two indices and at most their ω_c-weighted arithmetic mean.
fn verify(out: &ComponentImportanceOutput) -> Result<(), ComponentImportanceError> {
    let bad = |what: String| Err(ComponentImportanceError::Inconsistent { what });
    let s = &out.structure;
    if !s
        .he
        .iter()
        .chain(&s.t)
        .chain(&s.betweenness)
        .chain(&s.efficiency)
        .all(|x| x.is_finite())
    {
        return bad("non-finite structure value".to_owned());
    }
    for t in &out.times {
        for (name, ix) in [("probability", &t.probability), ("risk", &t.risk)] {
            let sum: f64 = ix.fp.iter().sum();
            let zero = ix.fp.iter().all(|&x| x == 0.0);
            if !ix.fp.iter().all(|x| x.is_finite())
                || (!zero && (sum - 1.0).abs() > NORMALIZATION_CHECK_TOL)
            {
                return bad(format!("{name} index at t = {} h sums to {sum}", t.time_h));
            }
        }
        for i in 0..t.ci.len() {
            let (a, b) = (t.probability.fp[i], t.risk.fp[i]);
            let ci = t.ci[i];
            let arith = out.constant_weights[0].mul_add(a, out.constant_weights[1] * b);
            let tol = NORMALIZATION_CHECK_TOL * a.max(b);
            if !ci.is_finite()
                || ci < a.min(b) - tol
                || ci > a.max(b) + tol
                || ci > arith + tol
                || !(t.weights_probability[i] + t.weights_risk[i] - 1.0)
                    .abs()
                    .is_finite()
            {
                return bad(format!(
                    "CI of component {i} at t = {} h is {ci} for indices {a}, {b}",
                    t.time_h
                ));
            }
        }
    }
    Ok(())
}
