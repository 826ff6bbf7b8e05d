//! Time-independent structure of the fault graph (spec §3.1–3.6): distances and node efficiency,
//! edge betweenness over all simple paths (or shortest paths), ISM hierarchy levels, the
//! hierarchy-weighted degree T and the edge-influence matrix HE.

use super::error::{ComponentImportanceError, Work};
use super::graph::Digraph;
use crate::numerics::Budget;

/// Path counts above this are treated as overflowing and the source is recounted in log space
/// (spec §6 H3; f64 ends at 1.8e308 and sums of a few such counts must stay finite).
pub const PATH_COUNT_LIMIT: f64 = 1e300;

/// Check the time budget every this many enumerated paths (an `Instant::now()` costs ~25 ns).
const PATHS_PER_BUDGET_CHECK: u64 = 4096;

/// Brandes path counts are rescaled by an exact power of two once a BFS level exceeds 2^512.
const SIGMA_RESCALE_EXP: i32 = 512;

/// Hop distances from every node (spec §3.1) summarised per node.
#[derive(Debug, Clone)]
pub struct Reach {
    /// Node efficiency I_i = (1/n) Σ_{j≠i reachable} 1/d_ij (paper Eq. 1).
    pub efficiency: Vec<f64>,
    /// r_i: number of nodes reachable from i, including i.
    pub reach: Vec<usize>,
    /// Σ_j d_ij over the nodes reachable from i \[hops\].
    pub dist_sum: Vec<f64>,
}

/// BFS from every node: node efficiency (Eq. 1) and outward reach/distance sums.
///
/// Summation per node runs by increasing distance (Σ_d count_d / d), so structurally identical
/// nodes get bit-identical values.
///
/// # Errors
/// [`ComponentImportanceError::Stopped`] when the budget runs out.
pub fn distances(
    g: &Digraph,
    budget: &Budget,
    work: &mut Work,
) -> Result<Reach, ComponentImportanceError> {
    let n = g.n();
    let mut dist = vec![usize::MAX; n];
    let mut queue: Vec<usize> = Vec::with_capacity(n);
    let mut efficiency = vec![0.0; n];
    let mut reach = vec![1usize; n];
    let mut dist_sum = vec![0.0; n];
    let n_f = to_f64(n);
    for s in 0..n {
        work.passes += 1;
        work.check(budget, "distances (BFS)")?;
        queue.clear();
        queue.push(s);
        dist[s] = 0;
        let mut head = 0;
        let mut level_count: Vec<usize> = Vec::new();
        while head < queue.len() {
            let v = queue[head];
            head += 1;
            let dv = dist[v];
            for &w in g.succ(v) {
                if dist[w] == usize::MAX {
                    dist[w] = dv + 1;
                    if level_count.len() < dv + 1 {
                        level_count.push(0);
                    }
                    level_count[dv] += 1;
                    queue.push(w);
                }
            }
        }
        let mut eff = 0.0;
        let mut dsum = 0.0;
        for (k, &c) in level_count.iter().enumerate() {
            let d = to_f64(k + 1);
            eff += to_f64(c) / d;
            dsum += to_f64(c) * d;
        }
        efficiency[s] = eff / n_f;
        reach[s] = queue.len();
        dist_sum[s] = dsum;
        for &v in &queue {
            dist[v] = usize::MAX;
        }
    }
    Ok(Reach {
        efficiency,
        reach,
        dist_sum,
    })
}

/// Streaming log-sum-exp accumulator.
#[derive(Debug, Clone, Copy)]
struct LogSum {
    max: f64,
    sum: f64,
}

impl LogSum {
    const EMPTY: Self = Self {
        max: f64::NEG_INFINITY,
        sum: 0.0,
    };

    fn add(&mut self, x: f64) {
        if x == f64::NEG_INFINITY {
            return;
        }
        if x > self.max {
            self.sum = self.sum.mul_add((self.max - x).exp(), 1.0);
            self.max = x;
        } else {
            self.sum += (x - self.max).exp();
        }
    }

    fn value(self) -> f64 {
        if self.max == f64::NEG_INFINITY {
            f64::NEG_INFINITY
        } else {
            self.max + self.sum.ln()
        }
    }
}

/// Edge betweenness over all simple paths on a DAG by path counting (spec §3.3, exact):
/// B_ij = Σ_{e≠f} π(e,i)·π(j,f)/π(e,f) − 1/π(i,j).
///
/// Per source e, restricted to the nodes reachable from e (found by a depth-first search whose
/// reverse postorder is a topological order of them): a forward DP gives π(e,·); a backward DP
/// gives g(j) = Σ_f π(j,f)/π(e,f) = 1/π(e,j) + Σ_{k∈succ(j)} g(k); then B_ij += π(e,i)·g(j),
/// where for i = e the own pair (e, j) is left out by using Σ_{k∈succ(j)} g(k) instead of g(j).
/// Cost O(Σ_e edges reachable from e) ≤ O(n·m). Sources whose counts exceed
/// [`PATH_COUNT_LIMIT`] are recounted in log space (spec §6 H3).
///
/// `g` must be acyclic. Returns B per CSR edge.
///
/// # Errors
/// [`ComponentImportanceError::Stopped`] when the budget runs out.
pub fn simple_path_betweenness_dag(
    g: &Digraph,
    budget: &Budget,
    work: &mut Work,
) -> Result<Vec<f64>, ComponentImportanceError> {
    let n = g.n();
    let mut b = vec![0.0; g.m()];
    let mut pi = vec![0.0; n];
    let mut gsum = vec![0.0; n];
    let mut tail_sum = vec![0.0; n];
    let mut mark = vec![false; n];
    let mut reached: Vec<usize> = Vec::with_capacity(n);
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for e in 0..n {
        work.passes += 1;
        work.check(budget, "simple-path betweenness (DAG counting)")?;
        // Reachable set in topological order: reverse DFS postorder.
        reached.clear();
        mark[e] = true;
        stack.push((e, g.out_edges(e).start));
        while let Some(top) = stack.last_mut() {
            let v = top.0;
            if top.1 < g.out_edges(v).end {
                let w = g.head(top.1);
                top.1 += 1;
                if !mark[w] {
                    mark[w] = true;
                    stack.push((w, g.out_edges(w).start));
                }
            } else {
                reached.push(v);
                stack.pop();
            }
        }
        reached.reverse();
        for &v in &reached {
            pi[v] = 0.0;
        }
        pi[e] = 1.0;
        let mut overflow = false;
        for &v in &reached {
            let pv = pi[v];
            overflow |= pv > PATH_COUNT_LIMIT;
            for &w in g.succ(v) {
                pi[w] += pv;
            }
        }
        if overflow {
            dag_source_log_space(g, e, &reached, &mark, &mut b);
        } else {
            for &j in reached.iter().skip(1).rev() {
                let mut t = 0.0;
                for &k in g.succ(j) {
                    t += gsum[k];
                }
                tail_sum[j] = t;
                gsum[j] = 1.0 / pi[j] + t;
            }
            for &i in &reached {
                let pi_i = pi[i];
                for ed in g.out_edges(i) {
                    let j = g.head(ed);
                    b[ed] += if i == e { tail_sum[j] } else { pi_i * gsum[j] };
                }
            }
        }
        for &v in &reached {
            mark[v] = false;
        }
    }
    Ok(b)
}

/// One source of [`simple_path_betweenness_dag`] in log space (path counts beyond f64).
fn dag_source_log_space(g: &Digraph, e: usize, reached: &[usize], mark: &[bool], b: &mut [f64]) {
    let n = g.n();
    let mut lpi = vec![f64::NEG_INFINITY; n];
    let mut lg = vec![f64::NEG_INFINITY; n];
    let mut ltail = vec![f64::NEG_INFINITY; n];
    lpi[e] = 0.0;
    for &v in reached.iter().skip(1) {
        let mut acc = LogSum::EMPTY;
        for &u in g.pred(v) {
            if mark[u] {
                acc.add(lpi[u]);
            }
        }
        lpi[v] = acc.value();
    }
    for &j in reached.iter().skip(1).rev() {
        let mut t = LogSum::EMPTY;
        for &k in g.succ(j) {
            t.add(lg[k]);
        }
        ltail[j] = t.value();
        t.add(-lpi[j]);
        lg[j] = t.value();
    }
    for &i in reached {
        for ed in g.out_edges(i) {
            let j = g.head(ed);
            b[ed] += if i == e {
                ltail[j].exp()
            } else {
                (lpi[i] + lg[j]).exp()
            };
        }
    }
}

/// A DFS frame of [`walk_simple_paths`]: (node, next CSR edge, CSR edge into node, accumulated
/// child sums).
type Frame = (usize, usize, usize, f64);

/// Depth-first walk over the simple paths from `e` (every node on the current path marked in
/// `on_path`): `extend(w)` before each path is extended by node `w` (an error stops the walk),
/// `leave(stack, frame)` after `frame`'s node is taken off the path (`stack` holds its parents).
fn walk_simple_paths<E>(
    g: &Digraph,
    e: usize,
    stack: &mut Vec<Frame>,
    on_path: &mut [bool],
    mut extend: impl FnMut(usize) -> Result<(), E>,
    mut leave: impl FnMut(&mut Vec<Frame>, Frame),
) -> Result<(), E> {
    stack.push((e, g.out_edges(e).start, usize::MAX, 0.0));
    on_path[e] = true;
    while let Some(top) = stack.last_mut() {
        let v = top.0;
        if top.1 < g.out_edges(v).end {
            let ed = top.1;
            top.1 += 1;
            let w = g.head(ed);
            if on_path[w] {
                continue;
            }
            extend(w)?;
            on_path[w] = true;
            stack.push((w, g.out_edges(w).start, ed, 0.0));
        } else {
            let frame = *top;
            on_path[v] = false;
            stack.pop();
            leave(stack, frame);
        }
    }
    Ok(())
}

/// Edge betweenness over all simple paths by depth-first enumeration (any digraph, spec §3.3).
///
/// Per source e, a first DFS counts π(e,f) for every f; a second DFS accumulates, for each path p
/// (a DFS node), s(p) = Σ over p and its extensions q of 1/π(e, end(q)), and adds s(p) to B of
/// p's last edge (for a one-edge path e→j, its own term 1/π(e,j) is left out: the own pair).
/// Cost 2 × (number of simple paths). Fails when the number of simple paths exceeds `max_paths`.
///
/// # Errors
/// [`ComponentImportanceError::SimplePathBudget`] beyond `max_paths`;
/// [`ComponentImportanceError::Stopped`] when the caller's budget runs out.
pub fn simple_path_betweenness_enumerated(
    g: &Digraph,
    max_paths: u64,
    budget: &Budget,
    work: &mut Work,
) -> Result<Vec<f64>, ComponentImportanceError> {
    const STAGE: &str = "simple-path betweenness (enumeration)";
    let n = g.n();
    let mut b = vec![0.0; g.m()];
    let mut cnt = vec![0.0f64; n];
    let mut on_path = vec![false; n];
    let mut enumerated = 0u64;
    let mut stack: Vec<Frame> = Vec::new();
    for e in 0..n {
        work.passes += 1;
        work.check(budget, STAGE)?;
        // Pass 1: count simple paths from e to every f.
        let mut touched: Vec<usize> = Vec::new();
        stack.clear();
        walk_simple_paths(
            g,
            e,
            &mut stack,
            &mut on_path,
            |w| {
                if cnt[w] == 0.0 {
                    touched.push(w);
                }
                cnt[w] += 1.0;
                enumerated += 1;
                work.paths += 1;
                if enumerated > max_paths {
                    return Err(ComponentImportanceError::SimplePathBudget {
                        enumerated,
                        budget: max_paths,
                    });
                }
                if work.paths.is_multiple_of(PATHS_PER_BUDGET_CHECK) {
                    work.check(budget, STAGE)?;
                }
                Ok(())
            },
            |_, _| {},
        )?;
        // Pass 2: accumulate s(p) along the DFS tree.
        walk_simple_paths(
            g,
            e,
            &mut stack,
            &mut on_path,
            |_| {
                work.paths += 1;
                if work.paths.is_multiple_of(PATHS_PER_BUDGET_CHECK) {
                    work.check(budget, STAGE)?;
                }
                Ok(())
            },
            |stack, (v, _, e_in, acc)| {
                let depth_one = stack.len() == 1;
                if let Some(parent) = stack.last_mut() {
                    let full = 1.0 / cnt[v] + acc;
                    // Depth 1 (parent is the source): the path e→v is the own pair of edge e→v.
                    b[e_in] += if depth_one { acc } else { full };
                    parent.3 += full;
                }
            },
        )?;
        for &w in &touched {
            cnt[w] = 0.0;
        }
    }
    Ok(b)
}

/// Shortest-path betweenness (Brandes 2001/2008), directed, unnormalized, with the hop-distance
/// summaries of the same BFS runs.
#[derive(Debug, Clone)]
pub struct ShortestPathBetweenness {
    /// Edge betweenness per CSR edge (no own-pair exclusion).
    pub edge: Vec<f64>,
    /// Node betweenness per node (unnormalized).
    pub node: Vec<f64>,
    /// Efficiency, reach and distance sums from the same breadth-first searches.
    pub reach: Reach,
}

/// Brandes' algorithm with level-synchronous BFS. The forward pass records the edges of the
/// shortest-path DAG, so the dependency accumulation visits only those (in reverse discovery
/// order, deepest level first). Path counts σ are rescaled per BFS level by exact powers of two,
/// so they never overflow (a layered graph of width 3 and 650 levels has 3^650 shortest paths).
/// Also returns the distance summaries of [`distances`] (one BFS per source serves both).
///
/// # Errors
/// [`ComponentImportanceError::Stopped`] when the budget runs out.
pub fn shortest_path_betweenness(
    g: &Digraph,
    budget: &Budget,
    work: &mut Work,
) -> Result<ShortestPathBetweenness, ComponentImportanceError> {
    let n = g.n();
    let n_f = to_f64(n);
    let mut edge = vec![0.0; g.m()];
    let mut node = vec![0.0; n];
    let mut efficiency = vec![0.0; n];
    let mut reach = vec![1usize; n];
    let mut dist_sum = vec![0.0; n];
    let mut dist = vec![usize::MAX; n];
    let mut sigma = vec![0.0f64; n];
    let mut delta = vec![0.0f64; n];
    let mut order: Vec<usize> = Vec::with_capacity(n);
    let mut dag: Vec<usize> = Vec::new();
    let mut level_start: Vec<usize> = Vec::new();
    let mut level_exp: Vec<i32> = Vec::new();
    let threshold = 2f64.powi(SIGMA_RESCALE_EXP);
    for s in 0..n {
        work.passes += 1;
        work.check(budget, "shortest-path betweenness (Brandes)")?;
        order.clear();
        dag.clear();
        level_start.clear();
        level_exp.clear();
        order.push(s);
        dist[s] = 0;
        sigma[s] = 1.0;
        level_start.push(0);
        level_exp.push(0);
        let mut rescaled = false;
        let mut d = 0usize;
        loop {
            let (lo, hi) = (level_start[d], order.len());
            if lo == hi {
                break;
            }
            level_start.push(hi);
            for k in lo..hi {
                let v = order[k];
                let sv = sigma[v];
                for ed in g.out_edges(v) {
                    let w = g.head(ed);
                    if dist[w] == usize::MAX {
                        dist[w] = d + 1;
                        sigma[w] = 0.0;
                        order.push(w);
                    }
                    if dist[w] == d + 1 {
                        sigma[w] += sv;
                        dag.push(ed);
                    }
                }
            }
            let mut exp = level_exp[d];
            let new = &order[hi..];
            if new.iter().any(|&w| sigma[w] > threshold) {
                let f = 2f64.powi(-SIGMA_RESCALE_EXP);
                for &w in new {
                    sigma[w] *= f;
                }
                exp += SIGMA_RESCALE_EXP;
                rescaled = true;
            }
            level_exp.push(exp);
            d += 1;
        }
        // Distance summaries: level l (≥ 1) holds level_start[l+1] − level_start[l] nodes.
        let (mut eff, mut dsum) = (0.0, 0.0);
        for l in 1..d {
            let c = to_f64(level_start[l + 1] - level_start[l]);
            let lf = to_f64(l);
            eff += c / lf;
            dsum += c * lf;
        }
        efficiency[s] = eff / n_f;
        reach[s] = order.len();
        dist_sum[s] = dsum;
        // Dependency accumulation over the shortest-path DAG, deepest edges first.
        for &v in &order {
            delta[v] = 0.0;
        }
        for &ed in dag.iter().rev() {
            let (v, w) = (g.tail(ed), g.head(ed));
            let mut c = sigma[v] / sigma[w] * (1.0 + delta[w]);
            if rescaled {
                c *= 2f64.powi(level_exp[dist[v]] - level_exp[dist[w]]);
            }
            edge[ed] += c;
            delta[v] += c;
        }
        for &v in &order[1..] {
            node[v] += delta[v];
        }
        for &v in &order {
            dist[v] = usize::MAX;
        }
    }
    Ok(ShortestPathBetweenness {
        edge,
        node,
        reach: Reach {
            efficiency,
            reach,
            dist_sum,
        },
    })
}

/// How hierarchy numbers are derived from the ISM partition (spec §3.4): the request's
/// `options.levels`.
pub use super::wire::LevelsMode as LevelMode;

/// Hierarchy numbers (spec §3.4).
#[derive(Debug, Clone)]
pub struct Levels {
    /// h_i (1 = most upstream), after the paper lift and overrides.
    pub h: Vec<u32>,
    /// m_L: number of ISM level sets.
    pub n_levels: u32,
}

/// ISM partition of the reachability matrix (spec §3.4). The ISM step "keep i if R_S(i) ⊆ A_S(i)"
/// peels the sink strongly connected components of the remaining graph, so the set number k_i is
/// 1 + the longest chain of components from i's component to a sink of the condensation; it is
/// computed in O(n + m) on Tarjan's components instead of on the n×n matrix.
#[must_use]
pub fn hierarchy_levels(g: &Digraph, mode: LevelMode, overrides: &[Option<u32>]) -> Levels {
    let n = g.n();
    let (comp, n_comp) = g.strongly_connected_components();
    // Component ids are sinks-first: every inter-component edge goes to a lower id.
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n_comp];
    for (v, &c) in comp.iter().enumerate() {
        members[c].push(v);
    }
    let mut k = vec![1u32; n_comp];
    for c in 0..n_comp {
        let mut kc = 1u32;
        for &v in &members[c] {
            for &w in g.succ(v) {
                let cw = comp[w];
                if cw != c {
                    kc = kc.max(k[cw] + 1);
                }
            }
        }
        k[c] = kc;
    }
    let n_levels = k.iter().copied().max().unwrap_or(1);
    let mut h: Vec<u32> = (0..n).map(|v| n_levels + 1 - k[comp[v]]).collect();
    if mode == LevelMode::Paper {
        for (v, hv) in h.iter_mut().enumerate() {
            if g.in_degree(v) == 0 {
                *hv = 1;
            }
        }
    }
    for (hv, o) in h.iter_mut().zip(overrides) {
        if let Some(x) = o {
            *hv = *x;
        }
    }
    Levels { h, n_levels }
}

/// Level weights H_i = (1/h_i) / Σ_{l=1}^{m_L} 1/l (paper Eq. 3).
#[must_use]
pub fn level_weights(levels: &Levels) -> Vec<f64> {
    let denom: f64 = (1..=levels.n_levels).map(|l| 1.0 / f64::from(l)).sum();
    levels
        .h
        .iter()
        .map(|&h| 1.0 / f64::from(h) / denom)
        .collect()
}

/// Hierarchy-weighted degree T_i = T_i^raw / Σ T^raw,
/// T_i^raw = Q·Σ_{k∈pred(i)} H_k + O·Σ_{j∈succ(i)} H_j (paper Eq. 4, normalized as Table 2).
#[must_use]
pub fn hierarchy_degree(g: &Digraph, h: &[f64], q: f64, o: f64) -> Vec<f64> {
    let raw: Vec<f64> = (0..g.n())
        .map(|i| {
            let sin: f64 = g.pred(i).iter().map(|&k| h[k]).sum();
            let sout: f64 = g.succ(i).iter().map(|&j| h[j]).sum();
            q.mul_add(sin, o * sout)
        })
        .collect();
    let total: f64 = raw.iter().sum();
    if total > 0.0 {
        raw.iter().map(|r| r / total).collect()
    } else {
        vec![0.0; raw.len()]
    }
}

/// Everything of §3.1–3.6 that does not depend on time.
#[derive(Debug, Clone)]
pub struct Structure {
    /// Eq. 1 node efficiency as computed (before overrides).
    pub efficiency_computed: Vec<f64>,
    /// Node efficiency used (after `efficiency_override`).
    pub efficiency: Vec<f64>,
    /// Edge betweenness per CSR edge (definition chosen by the betweenness mode).
    pub betweenness: Vec<f64>,
    /// ΣB.
    pub sum_b: f64,
    /// ΣI (of the efficiency used).
    pub sum_i: f64,
    /// Hierarchy numbers.
    pub levels: Levels,
    /// Level weights H_i.
    pub level_weights: Vec<f64>,
    /// Normalized hierarchy-weighted degree T_i.
    pub t: Vec<f64>,
    /// Contribution matrix Hc per CSR edge (Eq. 5).
    pub hc: Vec<f64>,
    /// Edge-influence matrix HE per CSR edge (Eq. 6, zero diagonal).
    pub he: Vec<f64>,
    /// The paper's printed diagonal T_i·I_i/ΣI (display only, not used for propagation).
    pub he_diag_display: Vec<f64>,
    /// Σ_j HE_ij per node.
    pub he_row_sum: Vec<f64>,
}

/// Combine efficiency, betweenness and hierarchy into Hc and HE (paper Eqs. 5, 6).
#[must_use]
pub fn assemble(
    g: &Digraph,
    efficiency_computed: Vec<f64>,
    efficiency: Vec<f64>,
    betweenness: Vec<f64>,
    levels: Levels,
    q: f64,
    o: f64,
) -> Structure {
    let level_weights = level_weights(&levels);
    let t = hierarchy_degree(g, &level_weights, q, o);
    let sum_b: f64 = betweenness.iter().sum();
    let sum_i: f64 = efficiency.iter().sum();
    let ratio = |x: f64, total: f64| if total > 0.0 { x / total } else { 0.0 };
    // I_i/ΣI on values scaled by max I, so that overrides near f64::MAX cannot overflow ΣI.
    let max_i = efficiency.iter().copied().fold(0.0, f64::max);
    let scaled_sum_i: f64 = if max_i > 0.0 {
        efficiency.iter().map(|x| x / max_i).sum()
    } else {
        0.0
    };
    let hc: Vec<f64> = betweenness.iter().map(|&b| ratio(b, sum_b)).collect();
    let mut he = vec![0.0; g.m()];
    let mut he_row_sum = vec![0.0; g.n()];
    let mut he_diag_display = vec![0.0; g.n()];
    for i in 0..g.n() {
        let ii = if max_i > 0.0 {
            ratio(efficiency[i] / max_i, scaled_sum_i)
        } else {
            0.0
        };
        he_diag_display[i] = t[i] * ii;
        let mut row = 0.0;
        for e in g.out_edges(i) {
            he[e] = t[i] * (ii + hc[e]);
            row += he[e];
        }
        he_row_sum[i] = row;
    }
    Structure {
        efficiency_computed,
        efficiency,
        betweenness,
        sum_b,
        sum_i,
        levels,
        level_weights,
        t,
        hc,
        he,
        he_diag_display,
        he_row_sum,
    }
}

/// `usize` → `f64` for counts (exact below 2^53; counts here are far smaller).
pub(crate) fn to_f64(x: usize) -> f64 {
    x as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_space_source_matches_plain() {
        // Small DAG: force the log-space path for every source and compare.
        let edges = [(0, 1), (0, 2), (1, 2), (1, 3), (2, 3), (3, 4), (2, 4)];
        let (g, _) = Digraph::from_edges(5, &edges).unwrap();
        let topo = g.topological_order().unwrap();
        let mut w = Work::default();
        let plain = simple_path_betweenness_dag(&g, &Budget::unlimited(), &mut w).unwrap();
        let mut logb = vec![0.0; g.m()];
        let mut pos = [0; 5];
        for (k, &v) in topo.iter().enumerate() {
            pos[v] = k;
        }
        for e in 0..5 {
            let mut mark = vec![false; 5];
            let mut reached = vec![e];
            mark[e] = true;
            for &v in &topo[pos[e] + 1..] {
                if g.pred(v).iter().any(|&u| mark[u]) {
                    mark[v] = true;
                    reached.push(v);
                }
            }
            dag_source_log_space(&g, e, &reached, &mark, &mut logb);
        }
        for (a, b) in plain.iter().zip(&logb) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn logsum() {
        let mut s = LogSum::EMPTY;
        for x in [1.0f64, 2.0, 3.0] {
            s.add(x.ln());
        }
        assert!((s.value().exp() - 6.0).abs() < 1e-12);
    }
}
