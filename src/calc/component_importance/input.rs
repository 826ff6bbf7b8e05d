//! Validation of a [`ComponentImportanceRequest`] into a [`ComponentImportanceInput`]
//! (spec §2): every offending field is collected with its JSON pointer, then the request fails
//! once. Units stay as on the wire (hours, 1/h): the method is not unit-invariant (spec §6 H4).

use std::collections::{BTreeMap, HashMap};

use super::graph::Digraph;
use super::structure::LevelMode;
use super::wire::{
    BETA, BetweennessMode, ComponentImportanceRequest, ComponentSpec, ConstantWeights, ETA_H,
    FailureMode, LEVEL, LevelsMode, MAX_SIMPLE_PATHS, NON_NEGATIVE, Options, Outputs, PATH_CAP,
    PROBABILITY, PathMethod, TIME_H, WEIGHT,
};
use crate::calc::{CalcFailure, Range, Validator};

/// Minimum number of components (one edge needs two).
pub const MIN_COMPONENTS: usize = 2;
/// Maximum number of components (spec §2).
pub const MAX_COMPONENTS: usize = 2000;
/// Maximum id length in characters (spec §2).
pub const MAX_ID_CHARS: usize = 64;
/// Maximum number of evaluation times (spec §2).
pub const MAX_TIMES: usize = 1000;
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

/// Which paths the propagation sum runs over (the request's `options.path_method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Paths {
    /// Simple paths only (paper); exact.
    Exact,
    /// Walks (matrix powers): equal to `Exact` on a DAG, an upper bound with cycles.
    Walks,
}

/// Which edge betweenness is used (the request's `options.betweenness`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Betweenness {
    /// All simple paths, own pair excluded (paper Table 1).
    AllSimplePaths,
    /// Brandes shortest-path edge betweenness.
    ShortestPaths,
}

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

fn weight_pair(v: &mut Validator, pointer: &str, w: &[f64]) -> Option<[f64; 2]> {
    if w.len() != 2 {
        v.push(
            pointer,
            format!(
                "constant weights must be 2 numbers (probability, risk), got {}",
                w.len()
            ),
        );
        return None;
    }
    let mut ok = true;
    for (k, &x) in w.iter().enumerate() {
        let p = format!("{pointer}/{k}");
        ok &= v.range(&p, "weight", x, WEIGHT);
    }
    if ok && (w[0] + w[1] - 1.0).abs() > SUM_TOL {
        v.push(
            pointer,
            format!(
                "weights must sum to 1 (±{SUM_TOL:e}), got {} + {} = {}",
                w[0],
                w[1],
                w[0] + w[1]
            ),
        );
        ok = false;
    }
    ok.then(|| [w[0], w[1]])
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

/// The component count and the ids; returns the index of every valid first occurrence.
fn ids<'a>(v: &mut Validator, components: &'a [ComponentSpec]) -> HashMap<&'a str, usize> {
    let n = components.len();
    v.ensure(
        (MIN_COMPONENTS..=MAX_COMPONENTS).contains(&n),
        "/components",
        || format!("needs {MIN_COMPONENTS} to {MAX_COMPONENTS} components, got {n}"),
    );
    let mut index_of: HashMap<&str, usize> = HashMap::with_capacity(n);
    for (i, c) in components.iter().enumerate() {
        let p = format!("/components/{i}/id");
        let len = c.id.chars().count();
        if len == 0 || len > MAX_ID_CHARS {
            v.push(
                &p,
                format!("id must have 1 to {MAX_ID_CHARS} characters, got {len}"),
            );
        } else if let Some(&j) = index_of.get(c.id.as_str()) {
            v.push(
                &p,
                format!("duplicate id \"{}\" (first at /components/{j}/id)", c.id),
            );
        } else {
            index_of.insert(c.id.as_str(), i);
        }
    }
    index_of
}

/// The evaluation times.
fn times(v: &mut Validator, times_h: &[f64]) {
    let nt = times_h.len();
    v.ensure((1..=MAX_TIMES).contains(&nt), "/times_h", || {
        format!("needs 1 to {MAX_TIMES} times, got {nt}")
    });
    for (k, &t) in times_h.iter().enumerate() {
        // t = 0 makes F = 0 (every index 0) and λ infinite for β < 1 (spec §6 H1).
        v.range(&format!("/times_h/{k}"), "", t, TIME_H);
    }
}

/// One quantity of an override (`ptr` = `/overrides/{k}/F` or `/overrides/{k}/RI`): the valid
/// values per component of `n`.
fn override_values(
    v: &mut Validator,
    (ptr, name, range): (&str, &str, Range),
    values: &BTreeMap<String, f64>,
    index_of: &HashMap<&str, usize>,
    n: usize,
) -> Vec<Option<f64>> {
    let mut out = vec![None; n];
    for (id, &x) in values {
        let p = format!("{ptr}/{}", pointer_token(id));
        match index_of.get(id.as_str()) {
            None => v.push(p, format!("unknown component id \"{id}\"")),
            Some(&i) => {
                if v.range(&p, name, x, range) {
                    out[i] = Some(x);
                }
            }
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
        if !v.finite(&pt, o.time_h) {
            continue;
        }
        let ts = find_time(&req.times_h, o.time_h);
        if ts.is_empty() {
            v.push(
                &pt,
                format!("override time {} h is not one of times_h", o.time_h),
            );
            continue;
        }
        if let Some(prev) = override_of_time[ts[0]] {
            v.push(
                &pt,
                format!(
                    "second override for time {} h (first at /overrides/{prev})",
                    o.time_h
                ),
            );
            continue;
        }
        let pf = format!("/overrides/{k}/F");
        let fo = override_values(v, (&pf, "F", PROBABILITY), &o.f, index_of, n);
        let pr = format!("/overrides/{k}/RI");
        let ro = override_values(v, (&pr, "RI [1/h]", NON_NEGATIVE), &o.ri, index_of, n);
        for &t in &ts {
            override_of_time[t] = Some(k);
            f_override[t] = Some(fo.clone());
            ri_override[t] = Some(ro.clone());
        }
    }
    (f_override, ri_override)
}

/// The Weibull data of component `c` (`base` = `/components/{i}`); `covered`: the overrides give
/// both F and RI at every time, so the data may be absent.
fn weibull(v: &mut Validator, base: &str, c: &ComponentSpec, covered: bool) -> Option<(f64, f64)> {
    match c.weibull {
        Some(w) => {
            let ok_eta = v.range(&format!("{base}/weibull/eta_h"), "", w.eta_h, ETA_H);
            let ok_beta = v.range(&format!("{base}/weibull/beta"), "", w.beta, BETA);
            (ok_eta && ok_beta).then_some((w.eta_h, w.beta))
        }
        None if covered => None,
        None => {
            v.push(
                format!("{base}/weibull"),
                format!(
                    "component \"{}\" needs Weibull data (eta_h, beta) unless overrides give \
                     both F and RI at every time",
                    c.id
                ),
            );
            None
        }
    }
}

/// S = Σ α·impact of the failure modes of component `id` at `p` (warns when Σα is not 1).
fn failure_modes(
    v: &mut Validator,
    p: String,
    modes: &[FailureMode],
    id: &str,
    warnings: &mut Vec<Finding>,
) -> Option<f64> {
    if modes.is_empty() {
        v.push(&p, "needs at least one failure mode".to_owned());
    }
    let mut ok = !modes.is_empty();
    let (mut sum_alpha, mut s) = (0.0, 0.0);
    for (m, fm) in modes.iter().enumerate() {
        ok &= v.range(&format!("{p}/{m}/alpha"), "", fm.alpha, PROBABILITY);
        let pi = format!("{p}/{m}/impact");
        ok &= v.range(&pi, "impact", fm.impact, NON_NEGATIVE);
        sum_alpha += fm.alpha;
        s += fm.alpha * fm.impact;
    }
    if ok && !s.is_finite() {
        v.push(&p, "sum of alpha·impact exceeds the f64 range".to_owned());
        ok = false;
    }
    if !ok {
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
            v.push(
                format!("{base}/mode_sum"),
                "give either failure_modes or mode_sum, not both".to_owned(),
            );
            None
        }
        (None, Some(s)) => {
            let p = format!("{base}/mode_sum");
            v.range(&p, "mode_sum", s, NON_NEGATIVE).then_some(s)
        }
        (Some(modes), None) => {
            failure_modes(v, format!("{base}/failure_modes"), modes, &c.id, warnings)
        }
        (None, None) if ri_all => None,
        (None, None) => {
            v.push(
                format!("{base}/failure_modes"),
                format!(
                    "component \"{}\" needs failure_modes or mode_sum (RI = λ·Σα·impact) \
                     unless overrides give RI at every time",
                    c.id
                ),
            );
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
        efficiency_override: vec![None; n],
        level_override: vec![None; n],
        warnings: Vec::new(),
    };
    for (i, c) in components.iter().enumerate() {
        let base = format!("/components/{i}");
        let f_all = all_times(f_override, i);
        let ri_all = all_times(ri_override, i);
        d.weibull[i] = weibull(v, &base, c, f_all && ri_all);
        d.mode_sum[i] = mode_sum(v, &base, c, ri_all, &mut d.warnings);
        if let Some(x) = c.efficiency_override {
            let p = format!("{base}/efficiency_override");
            if v.range(&p, "efficiency_override", x, NON_NEGATIVE) {
                d.efficiency_override[i] = Some(x);
            }
        }
        if let Some(h) = c.level_override
            && v.uint(
                &format!("{base}/level_override"),
                "level_override",
                u64::from(h),
                LEVEL,
            )
        {
            d.level_override[i] = Some(h);
        }
    }
    d
}

/// The edges as component index pairs; `None` when any edge is invalid.
fn edges(
    v: &mut Validator,
    req_edges: &[[String; 2]],
    index_of: &HashMap<&str, usize>,
) -> Option<Vec<(usize, usize)>> {
    v.ensure(!req_edges.is_empty(), "/edges", || {
        "needs at least one edge (without edges every index is 0)".to_owned()
    });
    let mut edges: Vec<(usize, usize)> = Vec::with_capacity(req_edges.len());
    let mut edges_ok = true;
    let mut seen: HashMap<(usize, usize), usize> = HashMap::with_capacity(req_edges.len());
    for (k, [a, b]) in req_edges.iter().enumerate() {
        let ia = index_of.get(a.as_str()).copied();
        let ib = index_of.get(b.as_str()).copied();
        for (end, id, index) in [(0, a, ia), (1, b, ib)] {
            if index.is_none() {
                v.push(
                    format!("/edges/{k}/{end}"),
                    format!("unknown component id \"{id}\""),
                );
            }
        }
        let (Some(ia), Some(ib)) = (ia, ib) else {
            edges_ok = false;
            continue;
        };
        if ia == ib {
            v.push(
                format!("/edges/{k}"),
                format!("self-loop \"{a}\" -> \"{a}\": a component cannot propagate to itself"),
            );
            edges_ok = false;
            continue;
        }
        if let Some(&first) = seen.get(&(ia, ib)) {
            v.push(
                format!("/edges/{k}"),
                format!("duplicate edge \"{a}\" -> \"{b}\" (first at /edges/{first})"),
            );
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
            let p = "/options/constant_weights/entropy_at_h";
            let t = if v.finite(p, e.entropy_at_h) {
                let ts = find_time(times_h, e.entropy_at_h);
                if ts.is_empty() {
                    v.push(
                        p,
                        format!("entropy time {} h is not one of times_h", e.entropy_at_h),
                    );
                }
                ts.first().copied()
            } else {
                None
            };
            s.zip(t)
                .map(|(subjective, time_index)| WeightSpec::Entropy {
                    subjective,
                    time_index,
                })
        }
    }
}

/// The options: Q and O, the constant weights, K and the enumeration budget; returns the weights.
fn options(v: &mut Validator, o: &Options, times_h: &[f64]) -> Option<WeightSpec> {
    let ok_q = v.range("/options/q_in", "", o.q_in, PROBABILITY);
    let ok_o = v.range("/options/o_out", "", o.o_out, PROBABILITY);
    if ok_q && ok_o && (o.q_in + o.o_out - 1.0).abs() > SUM_TOL {
        v.push(
            "/options/o_out",
            format!(
                "Q + O must equal 1 (±{SUM_TOL:e}), got {} + {} = {}",
                o.q_in,
                o.o_out,
                o.q_in + o.o_out
            ),
        );
    }
    let weights = weights(v, &o.constant_weights, times_h);
    v.uint(
        "/options/path_cap",
        "path_cap K",
        u64::from(o.path_cap),
        PATH_CAP,
    );
    v.range(
        "/options/max_simple_paths",
        "",
        o.max_simple_paths,
        MAX_SIMPLE_PATHS,
    );
    weights
}

impl TryFrom<ComponentImportanceRequest> for ComponentImportanceInput {
    type Error = CalcFailure;

    fn try_from(req: ComponentImportanceRequest) -> Result<Self, CalcFailure> {
        let mut v = Validator::new();
        let _ = crate::calc::common::time_limit(&mut v, req.time_limit_ms);
        let index_of = ids(&mut v, &req.components);
        times(&mut v, &req.times_h);
        let (f_override, ri_override) = overrides(&mut v, &req, &index_of);
        let data = components(&mut v, &req.components, (&f_override, &ri_override));
        let edges = edges(&mut v, &req.edges, &index_of);
        let weights = options(&mut v, &req.options, &req.times_h);
        v.finish()?;
        // Everything below was validated above; the fallbacks are unreachable.
        let (Some(weights), Some(edges)) = (weights, edges) else {
            return Err(CalcFailure::general(
                crate::calc::ProblemClass::InvalidInput,
                "INVALID_INPUT",
                "invalid options",
            ));
        };
        let (graph, edge_csr) = Digraph::from_edges(req.components.len(), &edges).map_err(|e| {
            CalcFailure::general(
                crate::calc::ProblemClass::InvalidInput,
                "INVALID_INPUT",
                format!("invalid edge list: {e:?}"),
            )
        })?;
        let o = &req.options;
        // max_simple_paths ∈ [1e3, 1e8] (validated): the cast is exact after rounding down.
        let max_simple_paths = o.max_simple_paths.floor() as u64;
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
            q_in: o.q_in,
            o_out: o.o_out,
            weights,
            path_cap: o.path_cap as usize,
            path_method: match o.path_method {
                PathMethod::Exact => Paths::Exact,
                PathMethod::Walks => Paths::Walks,
            },
            levels: match o.levels {
                LevelsMode::Paper => LevelMode::Paper,
                LevelsMode::Ism => LevelMode::Ism,
            },
            betweenness: match o.betweenness {
                BetweennessMode::AllSimplePaths => Betweenness::AllSimplePaths,
                BetweennessMode::ShortestPaths => Betweenness::ShortestPaths,
            },
            max_simple_paths,
            outputs: req.outputs.into(),
            warnings: data.warnings,
        })
    }
}
