//! The rules between fields of a [`ComponentImportanceRequest`] (spec §2), turning it into a
//! [`ComponentImportanceInput`]. Every per-field rule (counts, id lengths, ranges of times, Weibull
//! data, shares, options) is declared on the wire types and checked at the door; what is left here
//! is what JSON Schema cannot state (ids unique and known, edges, override times, sums), each rule
//! with its own code ([`CROSS_FIELD_RULES`]). Units stay as on the wire (hours, 1/h): the method is
//! not unit-invariant (spec §6 H4).

use std::collections::{BTreeMap, HashMap};

use super::error::{
    BUDGET_RULE, HAZARD_RATE_RULE, NUMERICAL_RULE, PROPAGATION_PATH_BUDGET_RULE,
    SIMPLE_PATH_BUDGET_RULE,
};
use super::graph::{Digraph, GraphError};
use super::structure::LevelMode;
use super::wire::{
    ComponentImportanceRequest, ComponentSpec, ConstantWeights, DEFAULT_MAX_SIMPLE_PATHS,
    DEFAULT_O_OUT, DEFAULT_PATH_CAP, DEFAULT_Q_IN, FailureMode, Options, Outputs,
};
pub use super::wire::{MAX_COMPONENTS, MAX_ID_CHARS, MAX_TIMES, MIN_COMPONENTS};
use crate::calc::rules::{ensure_rule, rule};
use crate::calc::{CalcFailure, Validator};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/component-importance` and the failures of its
    /// computation, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid DUPLICATE_ID ["/components/*/id"] "Component ids are unique.";
    invalid UNKNOWN_ID("UNKNOWN_COMPONENT_ID") ["/edges/*/0", "/edges/*/1", "/overrides/*/F/*",
        "/overrides/*/RI/*"]
        "Every id named by an edge or an override key is the id of a component.";
    invalid SELF_LOOP ["/edges/*"]
        "No edge joins a component to itself (a component cannot propagate to itself).";
    invalid DUPLICATE_EDGE ["/edges/*"]
        "No edge [from, to] is given twice (its weight would be ambiguous).";
    invalid OVERRIDE_TIME ["/overrides/*/time_h", "/times_h"]
        "Each override's time_h is one of times_h (within 1e-12 relative), and no two overrides \
         name the same time.";
    invalid WEIBULL_REQUIRED ["/components/*/weibull", "/overrides"]
        "A component has weibull data unless the overrides give both its F and its RI at every time.";
    invalid MODE_DATA_REQUIRED ["/components/*/failure_modes", "/components/*/mode_sum",
        "/overrides"]
        "A component has failure_modes or mode_sum unless the overrides give its RI at every time.";
    invalid MODE_DATA_CONFLICT ["/components/*/failure_modes", "/components/*/mode_sum"]
        "A component gives failure_modes or mode_sum, not both.";
    invalid MODE_SUM_OVERFLOW ["/components/*/failure_modes"]
        "The sum of alpha·impact over a component's failure modes is finite in f64.";
    invalid Q_PLUS_O ["/options/q_in", "/options/o_out"]
        "q_in + o_out = 1 within 1e-9 (defaults 0.25 and 0.75).";
    invalid WEIGHT_SUM ["/options/constant_weights", "/options/constant_weights/subjective"]
        "The two constant (or subjective) weights sum to 1 within 1e-9.";
    invalid ENTROPY_TIME ["/options/constant_weights/entropy_at_h", "/times_h"]
        "constant_weights.entropy_at_h is one of times_h (within 1e-12 relative).";
    listed SIMPLE_PATH_BUDGET_RULE;
    listed PROPAGATION_PATH_BUDGET_RULE;
    listed BUDGET_RULE;
    listed HAZARD_RATE_RULE;
    listed NUMERICAL_RULE;
    listed crate::calc::common::RESPONSE_TOO_LARGE_RULE;
}

/// Q + O = 1 and Σω_c = 1 are checked to this absolute tolerance (spec §2).
pub const SUM_TOL: f64 = 1e-9;
/// Σα of a component may differ from 1 by this much before a warning (spec §2).
pub const ALPHA_SUM_WARN_TOL: f64 = 1e-3;
/// An override or entropy time matches a requested time when equal to this relative tolerance
/// (both come from the same JSON text; the tolerance only absorbs decimal round trips).
pub const TIME_MATCH_REL_TOL: f64 = 1e-12;

/// How ω_c is obtained.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WeightSpec {
    /// Given directly.
    Fixed([f64; 2]),
    /// ½(subjective + entropy weights of the indices at time index `time_index`).
    Entropy {
        /// Subjective weights.
        subjective: [f64; 2],
        /// Index into `times_h`.
        time_index: usize,
    },
}

/// A validated request (domain form).
#[derive(Debug, Clone)]
pub struct ComponentImportanceInput {
    /// Component ids in input order.
    pub ids: Vec<String>,
    /// The fault graph.
    pub graph: Digraph,
    /// For every request edge, its CSR edge index in `graph`.
    pub edge_csr: Vec<usize>,
    /// Weibull (η \[h\], β) per component, if given.
    pub weibull: Vec<Option<(f64, f64)>>,
    /// S_i = Σ α·impact per component, if given.
    pub mode_sum: Vec<Option<f64>>,
    /// `efficiency_override` per component.
    pub efficiency_override: Vec<Option<f64>>,
    /// `level_override` per component.
    pub level_override: Vec<Option<u32>>,
    /// Evaluation times \[h\].
    pub times_h: Vec<f64>,
    /// Per time: F overrides per component (`None` for times without overrides).
    pub f_override: Vec<Option<Vec<Option<f64>>>>,
    /// Per time: RI overrides [1/h] per component.
    pub ri_override: Vec<Option<Vec<Option<f64>>>>,
    /// Q.
    pub q_in: f64,
    /// O.
    pub o_out: f64,
    /// Constant weights.
    pub weights: WeightSpec,
    /// K.
    pub path_cap: usize,
    /// Simple paths or walks.
    pub path_method: Paths,
    /// Level mode.
    pub levels: LevelMode,
    /// Betweenness definition.
    pub betweenness: Betweenness,
    /// Enumeration budget.
    pub max_simple_paths: u64,
    /// Output flags.
    pub outputs: OutputFlags,
    /// Warnings found during validation.
    pub warnings: Vec<Finding>,
}

/// Which paths the propagation sum runs over: the request's `options.path_method`.
pub use super::wire::PathMethod as Paths;

/// Which edge betweenness is used: the request's `options.betweenness`.
pub use super::wire::BetweennessMode as Betweenness;

/// The optional output groups asked for (the request's `outputs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputFlags {
    /// Time-independent matrices.
    pub matrices: bool,
    /// The indices and their weights per time.
    pub indices: bool,
    /// F, λ and RI per time.
    pub reliability: bool,
    /// The five centralities and their Kendall τ-b against CI.
    pub centralities: bool,
}

impl From<Outputs> for OutputFlags {
    fn from(o: Outputs) -> Self {
        Self {
            matrices: o.matrices,
            indices: o.indices,
            reliability: o.reliability,
            centralities: o.centralities,
        }
    }
}

/// A non-fatal finding of validation or computation (a response warning).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// Stable code, e.g. `ALPHA_SUM`.
    pub code: String,
    /// Human-readable explanation.
    pub detail: String,
    /// JSON pointer into the request, where the finding is tied to a field.
    pub pointer: Option<String>,
}

/// Escape a string for use as a JSON-pointer token (RFC 6901).
fn pointer_token(s: &str) -> String {
    s.replace('~', "~0").replace('/', "~1")
}

fn times_match(a: f64, b: f64) -> bool {
    (a - b).abs() <= TIME_MATCH_REL_TOL * a.abs().max(b.abs())
}

/// The pair's sum (each weight positive and the count 2: checked at the door).
fn weight_pair(v: &mut Validator, pointer: &str, w: &[f64]) -> Option<[f64; 2]> {
    let &[a, b] = w else { return None };
    ensure_rule!(v, (a + b - 1.0).abs() <= SUM_TOL, WEIGHT_SUM, pointer;
        "weights must sum to 1 (±{SUM_TOL:e}), got {a} + {b} = {}", a + b)
    .then_some([a, b])
}

/// Per time: the overrides of one quantity (F or RI) per component (`None` for times without
/// overrides).
type PerTime = Vec<Option<Vec<Option<f64>>>>;

/// The validated per-component data of the request.
struct ComponentData {
    weibull: Vec<Option<(f64, f64)>>,
    mode_sum: Vec<Option<f64>>,
    efficiency_override: Vec<Option<f64>>,
    level_override: Vec<Option<u32>>,
    warnings: Vec<Finding>,
}

/// The indices of `times_h` that match `t`.
fn find_time(times_h: &[f64], t: f64) -> Vec<usize> {
    times_h
        .iter()
        .enumerate()
        .filter(|&(_, &x)| x.is_finite() && times_match(x, t))
        .map(|(k, _)| k)
        .collect()
}

/// Whether the overrides give a value for component `i` at every time.
fn all_times(ov: &[Option<Vec<Option<f64>>>], i: usize) -> bool {
    ov.iter()
        .all(|t| t.as_ref().is_some_and(|row| row[i].is_some()))
}

/// The ids (count and lengths checked at the door); returns the index of every first occurrence.
fn ids<'a>(v: &mut Validator, components: &'a [ComponentSpec]) -> HashMap<&'a str, usize> {
    let mut index_of: HashMap<&str, usize> = HashMap::with_capacity(components.len());
    for (i, c) in components.iter().enumerate() {
        if let Some(&j) = index_of.get(c.id.as_str()) {
            rule!(v, DUPLICATE_ID, format!("/components/{i}/id");
                "duplicate id \"{}\" (first at /components/{j}/id)", c.id);
        } else {
            index_of.insert(c.id.as_str(), i);
        }
    }
    index_of
}

/// One quantity of an override (`ptr` = `/overrides/{k}/F` or `/overrides/{k}/RI`; the values'
/// ranges are checked at the door): the values per component of `n`.
fn override_values(
    v: &mut Validator,
    ptr: &str,
    values: &BTreeMap<String, f64>,
    index_of: &HashMap<&str, usize>,
    n: usize,
) -> Vec<Option<f64>> {
    let mut out = vec![None; n];
    for (id, &x) in values {
        match index_of.get(id.as_str()) {
            None => rule!(v, UNKNOWN_ID, format!("{ptr}/{}", pointer_token(id));
                "unknown component id \"{id}\""),
            Some(&i) => out[i] = Some(x),
        }
    }
    out
}

/// The F and RI overrides per time.
fn overrides(
    v: &mut Validator,
    req: &ComponentImportanceRequest,
    index_of: &HashMap<&str, usize>,
) -> (PerTime, PerTime) {
    let (n, nt) = (req.components.len(), req.times_h.len());
    let mut f_override: PerTime = vec![None; nt];
    let mut ri_override: PerTime = vec![None; nt];
    let mut override_of_time: Vec<Option<usize>> = vec![None; nt];
    for (k, o) in req.overrides.iter().enumerate() {
        let pt = format!("/overrides/{k}/time_h");
        let ts = find_time(&req.times_h, o.time_h);
        if ts.is_empty() {
            rule!(v, OVERRIDE_TIME, &pt; "override time {} h is not one of times_h", o.time_h);
            continue;
        }
        if let Some(prev) = override_of_time[ts[0]] {
            rule!(v, OVERRIDE_TIME, &pt;
                "second override for time {} h (first at /overrides/{prev})", o.time_h);
            continue;
        }
        let fo = override_values(v, &format!("/overrides/{k}/F"), &o.f, index_of, n);
        let ro = override_values(v, &format!("/overrides/{k}/RI"), &o.ri, index_of, n);
        for &t in &ts {
            override_of_time[t] = Some(k);
            f_override[t] = Some(fo.clone());
            ri_override[t] = Some(ro.clone());
        }
    }
    (f_override, ri_override)
}

/// The Weibull data of component `c` (`base` = `/components/{i}`; ranges checked at the door);
/// `covered`: the overrides give both F and RI at every time, so the data may be absent.
fn weibull(v: &mut Validator, base: &str, c: &ComponentSpec, covered: bool) -> Option<(f64, f64)> {
    if let Some(w) = c.weibull {
        return Some((w.eta_h, w.beta));
    }
    ensure_rule!(v, covered, WEIBULL_REQUIRED, format!("{base}/weibull");
        "component \"{}\" needs Weibull data (eta_h, beta) unless overrides give \
             both F and RI at every time",
        c.id);
    None
}

/// S = Σ α·impact of the failure modes of component `id` at `p` (warns when Σα is not 1; the
/// count and the ranges are checked at the door).
fn failure_modes(
    v: &mut Validator,
    p: String,
    modes: &[FailureMode],
    id: &str,
    warnings: &mut Vec<Finding>,
) -> Option<f64> {
    let sum_alpha: f64 = modes.iter().map(|m| m.alpha).sum();
    let s: f64 = modes.iter().map(|m| m.alpha * m.impact).sum();
    if !s.is_finite() {
        rule!(v, MODE_SUM_OVERFLOW, &p; "sum of alpha·impact exceeds the f64 range");
        return None;
    }
    if (sum_alpha - 1.0).abs() > ALPHA_SUM_WARN_TOL {
        warnings.push(Finding {
            code: "ALPHA_SUM".to_owned(),
            detail: format!("failure-mode shares of \"{id}\" sum to {sum_alpha:.6}, not 1"),
            pointer: Some(p),
        });
    }
    Some(s)
}

/// S of component `c`, from `failure_modes` or `mode_sum`; `ri_all`: the overrides give RI at
/// every time, so both may be absent.
fn mode_sum(
    v: &mut Validator,
    base: &str,
    c: &ComponentSpec,
    ri_all: bool,
    warnings: &mut Vec<Finding>,
) -> Option<f64> {
    match (&c.failure_modes, c.mode_sum) {
        (Some(_), Some(_)) => {
            rule!(v, MODE_DATA_CONFLICT, format!("{base}/mode_sum");
                "give either failure_modes or mode_sum, not both");
            None
        }
        (None, Some(s)) => Some(s),
        (Some(modes), None) => {
            failure_modes(v, format!("{base}/failure_modes"), modes, &c.id, warnings)
        }
        (None, None) => {
            ensure_rule!(v, ri_all, MODE_DATA_REQUIRED, format!("{base}/failure_modes");
                "component \"{}\" needs failure_modes or mode_sum (RI = λ·Σα·impact) \
                         unless overrides give RI at every time",
                c.id);
            None
        }
    }
}

/// The data of every component: Weibull, S, efficiency and level overrides.
fn components(
    v: &mut Validator,
    components: &[ComponentSpec],
    (f_override, ri_override): (&PerTime, &PerTime),
) -> ComponentData {
    let n = components.len();
    let mut d = ComponentData {
        weibull: vec![None; n],
        mode_sum: vec![None; n],
        efficiency_override: components.iter().map(|c| c.efficiency_override).collect(),
        level_override: components.iter().map(|c| c.level_override).collect(),
        warnings: Vec::new(),
    };
    for (i, c) in components.iter().enumerate() {
        let base = format!("/components/{i}");
        let f_all = all_times(f_override, i);
        let ri_all = all_times(ri_override, i);
        d.weibull[i] = weibull(v, &base, c, f_all && ri_all);
        d.mode_sum[i] = mode_sum(v, &base, c, ri_all, &mut d.warnings);
    }
    d
}

/// The edges as component index pairs (at least one: checked at the door); `None` when any edge
/// is invalid.
fn edges(
    v: &mut Validator,
    req_edges: &[[String; 2]],
    index_of: &HashMap<&str, usize>,
) -> Option<Vec<(usize, usize)>> {
    let mut edges: Vec<(usize, usize)> = Vec::with_capacity(req_edges.len());
    let mut edges_ok = true;
    let mut seen: HashMap<(usize, usize), usize> = HashMap::with_capacity(req_edges.len());
    for (k, [a, b]) in req_edges.iter().enumerate() {
        let ia = index_of.get(a.as_str()).copied();
        let ib = index_of.get(b.as_str()).copied();
        for (end, id, index) in [(0, a, ia), (1, b, ib)] {
            if index.is_none() {
                rule!(v, UNKNOWN_ID, format!("/edges/{k}/{end}"); "unknown component id \"{id}\"");
            }
        }
        let (Some(ia), Some(ib)) = (ia, ib) else {
            edges_ok = false;
            continue;
        };
        if ia == ib {
            rule!(v, SELF_LOOP, format!("/edges/{k}");
                "self-loop \"{a}\" -> \"{a}\": a component cannot propagate to itself");
            edges_ok = false;
            continue;
        }
        if let Some(&first) = seen.get(&(ia, ib)) {
            rule!(v, DUPLICATE_EDGE, format!("/edges/{k}");
                "duplicate edge \"{a}\" -> \"{b}\" (first at /edges/{first})");
            edges_ok = false;
            continue;
        }
        seen.insert((ia, ib), k);
        edges.push((ia, ib));
    }
    edges_ok.then_some(edges)
}

/// The constant weights ω_c: fixed, or subjective + entropy at one of `times_h`.
fn weights(v: &mut Validator, w: &ConstantWeights, times_h: &[f64]) -> Option<WeightSpec> {
    match w {
        ConstantWeights::Fixed(w) => {
            weight_pair(v, "/options/constant_weights", w).map(WeightSpec::Fixed)
        }
        ConstantWeights::Entropy(e) => {
            let s = weight_pair(v, "/options/constant_weights/subjective", &e.subjective);
            let t = find_time(times_h, e.entropy_at_h).first().copied();
            if t.is_none() {
                rule!(v, ENTROPY_TIME, "/options/constant_weights/entropy_at_h";
                    "entropy time {} h is not one of times_h", e.entropy_at_h);
            }
            s.zip(t)
                .map(|(subjective, time_index)| WeightSpec::Entropy {
                    subjective,
                    time_index,
                })
        }
    }
}

/// The options with their defaults: Q and O (their sum), the constant weights; returns the
/// weights. (Each option's range is checked at the door.)
fn options(v: &mut Validator, o: &Options, times_h: &[f64]) -> Option<WeightSpec> {
    let q = o.q_in.unwrap_or(DEFAULT_Q_IN);
    let out = o.o_out.unwrap_or(DEFAULT_O_OUT);
    ensure_rule!(v, (q + out - 1.0).abs() <= SUM_TOL, Q_PLUS_O, "/options/o_out";
        "Q + O must equal 1 (±{SUM_TOL:e}), got {q} + {out} = {}", q + out);
    weights(v, &o.constant_weights, times_h)
}

/// The failure of a graph the edge rules above admitted (unreachable: the same rules).
fn graph_failure(e: &GraphError) -> CalcFailure {
    match *e {
        GraphError::OutOfRange { index } => {
            UNKNOWN_ID.fail(format!("/edges/{index}"), "edge names an unknown component")
        }
        GraphError::SelfLoop { index } => {
            SELF_LOOP.fail(format!("/edges/{index}"), "self-loop edge")
        }
        GraphError::Duplicate { index, first } => DUPLICATE_EDGE.fail(
            format!("/edges/{index}"),
            format!("duplicate edge (first at /edges/{first})"),
        ),
    }
}

impl TryFrom<ComponentImportanceRequest> for ComponentImportanceInput {
    type Error = CalcFailure;

    fn try_from(req: ComponentImportanceRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let index_of = ids(&mut v, &req.components);
        let (f_override, ri_override) = overrides(&mut v, &req, &index_of);
        let data = components(&mut v, &req.components, (&f_override, &ri_override));
        let edges = edges(&mut v, &req.edges, &index_of);
        let weights = options(&mut v, &req.options, &req.times_h);
        v.finish()?;
        // `finish` succeeded: the weights and edges were admitted by the rules above (the pair
        // of weights holds two numbers when the door was passed).
        let (Some(weights), Some(edges)) = (weights, edges) else {
            return Err(crate::calc::rules::door_skipped(
                "/options/constant_weights",
            ));
        };
        let (graph, edge_csr) =
            Digraph::from_edges(req.components.len(), &edges).map_err(|e| graph_failure(&e))?;
        let o = &req.options;
        // max_simple_paths ∈ [1e3, 1e8] (the door): the cast is exact after rounding down.
        let max_simple_paths = o
            .max_simple_paths
            .unwrap_or(DEFAULT_MAX_SIMPLE_PATHS)
            .floor() as u64;
        Ok(Self {
            ids: req.components.into_iter().map(|c| c.id).collect(),
            graph,
            edge_csr,
            weibull: data.weibull,
            mode_sum: data.mode_sum,
            efficiency_override: data.efficiency_override,
            level_override: data.level_override,
            times_h: req.times_h,
            f_override,
            ri_override,
            q_in: o.q_in.unwrap_or(DEFAULT_Q_IN),
            o_out: o.o_out.unwrap_or(DEFAULT_O_OUT),
            weights,
            path_cap: o.path_cap.unwrap_or(DEFAULT_PATH_CAP) as usize,
            path_method: o.path_method,
            levels: o.levels,
            betweenness: o.betweenness,
            max_simple_paths,
            outputs: req.outputs.into(),
            warnings: data.warnings,
        })
    }
}
