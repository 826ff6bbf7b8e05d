//! Wire types of `POST /v1/component-importance` (spec §2, §4, §8: the JSON example is the
//! contract). Times and Weibull scales are in hours, rates per hour: the method is not invariant
//! to the unit of the risk rate (spec §6 H4), so the paper's unit is kept on the wire and inside.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::calc::Range;
use crate::numerics::SolverReport;

/// Request: one fault graph, one or more operating ages.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::ComponentImportanceRequest)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "components": [
        {"id": "S", "weibull": {"eta_h": 7832.7, "beta": 0.6414}, "mode_sum": 0.1450546},
        {"id": "M", "weibull": {"eta_h": 2458.1, "beta": 1.3117}, "mode_sum": 0.1415337},
        {"id": "J", "weibull": {"eta_h": 2606.4, "beta": 1.2949}, "mode_sum": 0.1721013},
        {"id": "NC", "weibull": {"eta_h": 7912.4, "beta": 0.5422}, "mode_sum": 0.5},
        {"id": "D", "weibull": {"eta_h": 8905.1, "beta": 0.6556}, "mode_sum": 0.1249006},
        {"id": "V", "weibull": {"eta_h": 7935.7, "beta": 0.7712}, "mode_sum": 0.2998578},
        {"id": "G", "weibull": {"eta_h": 27503.4, "beta": 0.5243}, "mode_sum": 0.2617428},
        {"id": "L", "weibull": {"eta_h": 8161.5, "beta": 0.7910}, "mode_sum": 0.3283729},
        {"id": "W", "weibull": {"eta_h": 4145.7, "beta": 0.9101}, "mode_sum": 0.1369623},
        {"id": "K", "weibull": {"eta_h": 5960.8, "beta": 0.9314}, "mode_sum": 0.5}
    ],
    "edges": [["S","M"],["S","J"],["NC","S"],["NC","J"],["D","S"],["D","M"],["V","S"],["V","NC"],
              ["V","W"],["G","S"],["G","M"],["L","S"],["L","M"],["L","J"],["W","J"],["K","J"]],
    "times_h": [500, 2000]
}))]
pub struct ComponentImportanceRequest {
    /// Components in output order (also the tie-break order of the ranking); 2–2000 entries.
    #[rule(min_items = MIN_COMPONENTS, max_items = MAX_COMPONENTS)]
    pub components: Vec<ComponentSpec>,
    /// Directed fault-propagation edges `[from_id, to_id]`: a fault of `from` directly causes a
    /// fault of `to` (paper adjacency A). At least one; no self-loops, no duplicates.
    #[rule(min_items = 1)]
    pub edges: Vec<[String; 2]>,
    /// Operating ages t at which the importance is evaluated \[h\]; 1–1000 values, each > 0.
    #[rule(items = TIME_H, min_items = 1, max_items = MAX_TIMES)]
    pub times_h: Vec<f64>,
    /// Per-time replacements of the Weibull-derived F_i(t) and RI_i(t) (reproduce paper inputs).
    #[serde(
        default,
        deserialize_with = "crate::calc::rules::null_default",
        skip_serializing_if = "Vec::is_empty"
    )]
    pub overrides: Vec<TimeOverride>,
    /// Method options (defaults reproduce the paper).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub options: Options,
    /// Which optional outputs to compute and return.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub outputs: Outputs,
    /// Wall-clock limit for this request \[ms\], queueing included (capped by the service limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = crate::calc::common::TIME_LIMIT_MS)]
    #[schema(nullable = false, example = 2000)]
    pub time_limit_ms: Option<u64>,
}

impl crate::calc::common::TimeLimited for ComponentImportanceRequest {
    fn time_limit(&self) -> Option<std::time::Duration> {
        self.time_limit_ms.map(std::time::Duration::from_millis)
    }
}

/// One component (node of the fault graph).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::ComponentSpec)]
#[serde(deny_unknown_fields)]
pub struct ComponentSpec {
    /// Unique label, 1–64 characters.
    #[rule(min_length = 1, max_length = MAX_ID_CHARS)]
    #[schema(example = "S")]
    pub id: String,
    /// Two-parameter Weibull life distribution (paper Table 4). Required unless `overrides`
    /// give both F and RI of this component at every time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub weibull: Option<Weibull>,
    /// Failure modes {α, impact} (paper Table 5). Required unless `mode_sum` is given (or RI is
    /// overridden at every time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(min_items = 1)]
    pub failure_modes: Option<Vec<FailureMode>>,
    /// S_i = Σ α·impact given directly [–]; replaces `failure_modes`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = NON_NEGATIVE)]
    pub mode_sum: Option<f64>,
    /// Replaces the computed node efficiency I_i (Eq. 1) [–]; needed to reproduce the paper
    /// (it uses 0.20 for D and G, spec §3.11-2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = NON_NEGATIVE)]
    pub efficiency_override: Option<f64>,
    /// Replaces the hierarchy number h_i (1 = most upstream) [–].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = LEVEL)]
    pub level_override: Option<u32>,
}

/// Weibull parameters.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::Weibull)]
#[serde(deny_unknown_fields)]
pub struct Weibull {
    /// Scale η \[h\] (same unit as `times_h`); finite, > 0.
    #[rule(range = ETA_H)]
    #[schema(example = 7832.7)]
    pub eta_h: f64,
    /// Shape β [–]; 0.05 ≤ β ≤ 20.
    #[rule(range = BETA)]
    #[schema(example = 0.6414)]
    pub beta: f64,
}

/// One failure mode of a component (paper Table 5).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::FailureMode)]
#[serde(deny_unknown_fields)]
pub struct FailureMode {
    /// α: share of this mode among the component's faults [–], in [0, 1].
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.142857)]
    pub alpha: f64,
    /// ANP influence degree of the mode [–], ≥ 0.
    #[rule(range = NON_NEGATIVE)]
    #[schema(example = 0.07288)]
    pub impact: f64,
}

/// Replacements of F_i(t) and RI_i(t) at one time (keys are component ids).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::TimeOverride)]
#[serde(deny_unknown_fields)]
pub struct TimeOverride {
    /// The time \[h\]; must be one of `times_h`.
    pub time_h: f64,
    /// Failure probability F_i(t) [–] per id, in [0, 1].
    #[serde(
        rename = "F",
        default,
        deserialize_with = "crate::calc::rules::null_default",
        skip_serializing_if = "BTreeMap::is_empty"
    )]
    #[rule(values = PROBABILITY)]
    pub f: BTreeMap<String, f64>,
    /// Failure-mode risk RI_i(t) [1/h] per id, ≥ 0.
    #[serde(
        rename = "RI",
        default,
        deserialize_with = "crate::calc::rules::null_default",
        skip_serializing_if = "BTreeMap::is_empty"
    )]
    #[rule(values = NON_NEGATIVE)]
    pub ri: BTreeMap<String, f64>,
}

/// Constant weights ω_c of the two indices: a pair `[ω_c¹, ω_c²]` (probability, risk) or the
/// entropy mode `{subjective: [w1, w2], entropy_at_h: t0}` (ω_c = ½(ω_subj + ω_entropy(t0))).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::ConstantWeights)]
#[serde(untagged)]
pub enum ConstantWeights {
    /// `[ω_c¹, ω_c²]`, each > 0, sum 1.
    #[rule(items = WEIGHT, min_items = 2, max_items = 2)]
    Fixed(Vec<f64>),
    /// Average of subjective weights and entropy weights at one of the requested times.
    Entropy(EntropyWeights),
}

impl Default for ConstantWeights {
    fn default() -> Self {
        Self::Fixed(vec![0.520_614, 0.479_386])
    }
}

/// Entropy-based constant weights (spec §3.9).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::EntropyWeights)]
#[serde(deny_unknown_fields)]
pub struct EntropyWeights {
    /// Subjective (e.g. Delphi) weights `[w1, w2]`, each > 0, sum 1.
    #[rule(items = WEIGHT, min_items = 2, max_items = 2)]
    pub subjective: Vec<f64>,
    /// The time t0 \[h\] whose normalized indices define the entropy weights; one of `times_h`.
    pub entropy_at_h: f64,
}

/// Which simple paths the propagation sum runs over.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = component_importance::PathMethod)]
#[serde(rename_all = "snake_case")]
pub enum PathMethod {
    /// Simple paths only (paper); exact.
    #[default]
    Exact,
    /// Walks (matrix powers): equal to `exact` on a DAG, an upper bound with cycles.
    Walks,
}

/// How hierarchy numbers are assigned.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = component_importance::LevelsMode)]
#[serde(rename_all = "snake_case")]
pub enum LevelsMode {
    /// ISM levels with sources lifted to level 1 (reproduces paper Table 2).
    #[default]
    Paper,
    /// Plain reversed ISM levels.
    Ism,
}

/// Which edge betweenness is used.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = component_importance::BetweennessMode)]
#[serde(rename_all = "snake_case")]
pub enum BetweennessMode {
    /// All simple paths, own pair excluded (paper Table 1); exponential on cyclic graphs.
    #[default]
    AllSimplePaths,
    /// Brandes shortest-path edge betweenness: a different measure, O(n·m).
    ShortestPaths,
}

/// Method options. Every field is optional (`null` = absent); the defaults reproduce the paper.
#[derive(Debug, Clone, Default, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::Options)]
#[serde(deny_unknown_fields)]
pub struct Options {
    /// In-degree coefficient Q [–] (Eq. 4), in [0, 1]; Q + O = 1. Default 0.25.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.25, default = 0.25)]
    pub q_in: Option<f64>,
    /// Out-degree coefficient O [–] (Eq. 4), in [0, 1]; Q + O = 1. Default 0.75.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = PROBABILITY)]
    #[schema(example = 0.75, default = 0.75)]
    pub o_out: Option<f64>,
    /// Constant weights ω_c (probability, risk); default the paper's [0.520614, 0.479386].
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub constant_weights: ConstantWeights,
    /// K: maximal path length (edges) in the propagation sum, 1–8. Default 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = PATH_CAP)]
    #[schema(example = 3, default = 3)]
    pub path_cap: Option<u32>,
    /// Simple paths (`exact`, default) or walks.
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub path_method: PathMethod,
    /// Hierarchy level mode (default `paper`).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub levels: LevelsMode,
    /// Edge betweenness definition (default `all_simple_paths`).
    #[serde(default, deserialize_with = "crate::calc::rules::null_default")]
    pub betweenness: BetweennessMode,
    /// Enumeration budget (number of simple paths) on graphs with cycles, 1e3–1e8. Default 2e6.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[rule(range = MAX_SIMPLE_PATHS)]
    #[schema(example = 2_000_000.0, default = 2_000_000.0)]
    pub max_simple_paths: Option<f64>,
}

/// Default in-degree coefficient Q (paper).
pub const DEFAULT_Q_IN: f64 = 0.25;
/// Default out-degree coefficient O (paper).
pub const DEFAULT_O_OUT: f64 = 0.75;
/// Default path cap K (paper).
pub const DEFAULT_PATH_CAP: u32 = 3;
/// Default enumeration budget of simple paths.
pub const DEFAULT_MAX_SIMPLE_PATHS: f64 = 2e6;

/// Optional outputs (off by default except the cheap indices); `null` = absent.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, ToSchema, crate::calc::Rules)]
#[schema(as = component_importance::Outputs)]
#[serde(deny_unknown_fields, default)]
pub struct Outputs {
    /// Return the time-independent structure (B, I, levels, T, Hc, HE): O(n + m) payload.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub matrices: bool,
    /// Return raw and normalized indices, variable weights and truncation bounds per time
    /// (default true).
    #[serde(deserialize_with = "crate::calc::rules::null_true")]
    pub indices: bool,
    /// Return F, λ and RI per time.
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub reliability: bool,
    /// Compute standard centralities and Kendall τ_b against CI (extra O(n·m) work).
    #[serde(deserialize_with = "crate::calc::rules::null_default")]
    pub centralities: bool,
}

impl Default for Outputs {
    fn default() -> Self {
        Self {
            matrices: false,
            indices: true,
            reliability: false,
            centralities: false,
        }
    }
}

/// Response.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::ComponentImportanceResponse)]
pub struct ComponentImportanceResponse {
    /// Component ids in input order (the order of every per-component array).
    pub components: Vec<String>,
    /// One entry per requested time, in request order.
    pub results: Vec<TimeResult>,
    /// Non-fatal findings (Σα ≠ 1, isolated components, void truncation bounds, ...).
    pub warnings: Vec<Warning>,
    /// Graph facts, algorithms used and cost.
    pub meta: Meta,
    /// Time-independent structure (`outputs.matrices`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub matrices: Option<Matrices>,
    /// Standard centralities (`outputs.centralities`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub centralities: Option<Centralities>,
}

/// Results at one time t.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::TimeResult)]
pub struct TimeResult {
    /// The time t \[h\].
    pub time_h: f64,
    /// Comprehensive importance CI_i(t) [–] (Eq. 18).
    pub ci: Vec<f64>,
    /// Rank by CI (1 = most important; ties keep input order).
    pub rank: Vec<u32>,
    /// Normalized probability index fp¹_i [–] (`outputs.indices`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fp_probability: Option<Vec<f64>>,
    /// Normalized risk index fp²_i [–] (`outputs.indices`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fp_risk: Option<Vec<f64>>,
    /// Raw probability index Σ_paths Π F·HE [–] (`outputs.indices`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fp_probability_raw: Option<Vec<f64>>,
    /// Raw risk index Σ_paths Π RI·HE [products of 1/h] (`outputs.indices`; omitted with a
    /// warning if it exceeds f64).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fp_risk_raw: Option<Vec<f64>>,
    /// Variable weight ω_b¹(i) of the probability index [–] (`outputs.indices`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights_probability: Option<Vec<f64>>,
    /// Variable weight ω_b²(i) of the risk index [–] (`outputs.indices`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights_risk: Option<Vec<f64>>,
    /// Relative truncation bound of the K-capped sums (`outputs.indices`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub tail_bound: Option<TailBound>,
    /// F_i(t) used [–] (`outputs.reliability`).
    #[serde(rename = "F", default, skip_serializing_if = "Option::is_none")]
    pub f: Option<Vec<f64>>,
    /// Weibull hazard rate λ_i(t) [1/h] (`outputs.reliability`; 0 where no Weibull data).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda_per_h: Option<Vec<f64>>,
    /// Failure-mode risk RI_i(t) used [1/h] (`outputs.reliability`).
    #[serde(rename = "RI_per_h", default, skip_serializing_if = "Option::is_none")]
    pub ri_per_h: Option<Vec<f64>>,
    /// Kendall τ_b of each centrality against CI at this time (`outputs.centralities`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(nullable = false)]
    pub kendall_tau_b: Option<KendallTau>,
}

/// Relative truncation bound ρ^K/(1−ρ) against the K = ∞ walk sum, ρ = max_i Σ_j P_ij;
/// `null` when ρ ≥ 1 (bound void).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::TailBound)]
pub struct TailBound {
    /// Bound for the probability index.
    pub probability: Option<f64>,
    /// Bound for the risk index.
    pub risk: Option<f64>,
}

/// A non-fatal finding.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::Warning)]
pub struct Warning {
    /// Stable code, e.g. `ALPHA_SUM`, `ISOLATED_COMPONENTS`, `TRUNCATION_BOUND_VOID`.
    pub code: String,
    /// Human-readable explanation.
    pub detail: String,
    /// JSON pointer into the request, where the finding is tied to a field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pointer: Option<String>,
}

/// Graph facts and cost.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::Meta)]
pub struct Meta {
    /// Whether the graph is acyclic.
    pub is_dag: bool,
    /// Number of components.
    pub n: usize,
    /// Number of edges.
    pub m: usize,
    /// Number of ISM level sets m_L.
    pub n_levels: u32,
    /// Edges of the longest path (DAG only): any path_cap ≥ this is exact (no truncation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub longest_path_edges: Option<usize>,
    /// Simple paths enumerated by depth-first search (0 when counted polynomially on a DAG).
    pub simple_paths_enumerated: u64,
    /// Betweenness definition used: `all_simple_paths` (paper Table 1) or `shortest_paths`
    /// (Brandes; a different measure that does not reproduce Table 1).
    pub betweenness: BetweennessMode,
    /// How the betweenness was computed: `dag_path_counting`, `simple_path_enumeration` or
    /// `brandes_shortest_paths`.
    pub betweenness_algorithm: String,
    /// How the propagation sums were computed: `dag_walks` (exact on a DAG),
    /// `closed_form_k3` (exact), `simple_path_dfs` (exact) or `walks` (upper bound with cycles).
    pub propagation_algorithm: String,
    /// Path cap K used.
    pub path_cap: u32,
    /// Constant weights ω_c used (probability, risk).
    pub constant_weights: [f64; 2],
    /// How the budgeted work ended: iterations = per-source passes, evaluations = enumerated
    /// simple paths.
    pub report: SolverReport,
    /// Wall-clock time of the whole calculation \[ms\].
    pub elapsed_ms: f64,
}

/// An edge value.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::EdgeValue)]
pub struct EdgeValue {
    /// Source id.
    pub from: String,
    /// Target id.
    pub to: String,
    /// Value.
    pub value: f64,
}

/// Time-independent structure (spec §4), edges in request order.
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::Matrices)]
pub struct Matrices {
    /// Edge betweenness B_ij (Table 1 for `all_simple_paths`).
    pub edge_betweenness: Vec<EdgeValue>,
    /// Node efficiency I_i used (after overrides) [–] (Eq. 1).
    pub efficiency: Vec<f64>,
    /// Hierarchy numbers h_i (1 = most upstream).
    pub levels: Vec<u32>,
    /// Level weights H_i (Eq. 3).
    pub level_weights: Vec<f64>,
    /// Normalized hierarchy-weighted degree T_i (Eq. 4, Table 2).
    #[serde(rename = "T")]
    pub t: Vec<f64>,
    /// Contribution matrix Hc_ij = B_ij/ΣB (Eq. 5).
    #[serde(rename = "Hc")]
    pub hc: Vec<EdgeValue>,
    /// Edge-influence matrix HE_ij (Eq. 6, off-diagonal).
    #[serde(rename = "HE")]
    pub he: Vec<EdgeValue>,
    /// The paper's printed diagonal T_i·I_i/ΣI (display only; not used in propagation).
    #[serde(rename = "HE_diag_display")]
    pub he_diag_display: Vec<f64>,
}

/// Standard centralities of the unweighted graph (spec §3.10).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::Centralities)]
pub struct Centralities {
    /// Out-degree.
    pub out_degree: Vec<f64>,
    /// In-degree.
    pub in_degree: Vec<f64>,
    /// Node betweenness (Brandes, directed), normalized by (n−1)(n−2).
    pub betweenness: Vec<f64>,
    /// Outward closeness (Wasserman–Faust on the reversed graph).
    pub closeness_out: Vec<f64>,
    /// PageRank on the reversed graph (α = 0.85).
    pub pagerank_reversed: Vec<f64>,
}

/// Kendall τ_b of each centrality against CI (`null` where undefined: a constant vector).
#[derive(Debug, Clone, Serialize, ToSchema)]
#[schema(as = component_importance::KendallTau)]
pub struct KendallTau {
    /// τ_b(out-degree, CI).
    pub out_degree: Option<f64>,
    /// τ_b(in-degree, CI).
    pub in_degree: Option<f64>,
    /// τ_b(betweenness, CI).
    pub betweenness: Option<f64>,
    /// τ_b(outward closeness, CI).
    pub closeness_out: Option<f64>,
    /// τ_b(reversed PageRank, CI).
    pub pagerank_reversed: Option<f64>,
}

// The per-field rules of this module's wire types (`#[rule]` on the fields read these).
/// Minimum number of components (one edge needs two).
pub const MIN_COMPONENTS: usize = 2;
/// Maximum number of components (spec §2).
pub const MAX_COMPONENTS: usize = 2000;
/// Maximum id length in characters (spec §2).
pub const MAX_ID_CHARS: usize = 64;
/// Maximum number of evaluation times (spec §2).
pub const MAX_TIMES: usize = 1000;
/// An operating time \[h\]: positive (t = 0 makes every index 0, spec §6 H1).
pub const TIME_H: Range = Range::FINITE.gt(0.0);
/// A constant weight of the probability/risk pair: positive (the pair sums to 1).
pub const WEIGHT: Range = Range::FINITE.gt(0.0);

/// A probability or share in [0, 1] (F override, failure-mode α, the pair Q/O) [–].
pub const PROBABILITY: Range = Range::closed(0.0, 1.0);
/// A quantity that may be zero (RI override [1/h], mode sum, impact, efficiency override).
pub const NON_NEGATIVE: Range = Range::FINITE.min(0.0);
/// Weibull scale η \[h\]: positive.
pub const ETA_H: Range = Range::FINITE.gt(0.0);
/// Weibull shape β [–] (spec §2).
pub const BETA: Range = Range::closed(0.05, 20.0);
/// Level override [–]: a level ≥ 1.
pub const LEVEL: Range = Range::INTEGER.min(1.0);
/// Path cap K [–] (spec §2).
pub const PATH_CAP: Range = Range::int(1, 8);
/// Enumeration budget of simple paths [–] (spec §2).
pub const MAX_SIMPLE_PATHS: Range = Range::closed(1e3, 1e8);
