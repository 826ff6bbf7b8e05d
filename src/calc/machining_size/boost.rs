//! Second-order gradient boosting of regression trees with XGBoost's squared-error semantics
//! (spec §3): centred targets in f64, trees grown level by level over pre-sorted columns
//! ("exact", XGBoost's colmaker) or over per-feature bins ("hist"), L1/L2 leaf regularisation,
//! XGBoost's split threshold 1e-6 (`kRtEps`) and its γ pruning with the un-halved loss change.
//!
//! Growing level by level gives the same trees as the spec's depth-first description (a node's
//! split depends only on its own rows) and numbers the nodes breadth-first as XGBoost does. The
//! split search of one level runs over the sampled features with [`par_map`] when the level is
//! large enough to pay for it; the per-feature results are reduced in ascending feature order, so
//! the trees are bit-identical for any thread count.

use crate::numerics::{Budget, StopReason, par_map};

use super::data::Matrix;
use super::model::{LEAF, Model, ModelSource, Node, Routing, Tree};
use super::rng;

/// XGBoost's minimum loss change of a split (`kRtEps`).
pub const KRT_EPS: f64 = 1e-6;

/// Two loss changes closer than this (relative to max(1, |best|)) are a tie; the first found
/// wins (spec §3 step 4, hazard 3).
const TIE_REL: f64 = 1e-12;

/// Smallest level (rows scanned × features) worth splitting over threads: below it the
/// scheduling costs more than the scan (benches/RESULTS.md, machining_size thread sweep).
const PAR_MIN_WORK: usize = 60_000;

/// `pos` entry of a row that no node of the current level holds (not a training row of this
/// model, or its node is finished).
const NONE: u32 = 0x7FFF_FFFF;
/// `pos` flag of a training row left out of this tree by row subsampling: it is routed like the
/// others (its margin must be updated) but never counted in the split search.
const UNSAMPLED: u32 = 0x8000_0000;

/// Split-search method (spec §2.1 `tree_method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Every boundary between distinct values; θ = midpoint.
    Exact,
    /// Boundaries between bins (at most `max_bin` per feature); θ = the bin's upper cut.
    Hist {
        /// Most bins per feature.
        max_bin: usize,
    },
}

/// Boosting parameters (spec §2.1 `params`), validated.
#[derive(Debug, Clone, PartialEq)]
pub struct BoostParams {
    /// Boosting rounds.
    pub n_estimators: usize,
    /// Tree depth.
    pub max_depth: usize,
    /// η.
    pub learning_rate: f64,
    /// λ.
    pub reg_lambda: f64,
    /// α.
    pub reg_alpha: f64,
    /// γ.
    pub gamma: f64,
    /// Minimum hessian sum per child.
    pub min_child_weight: f64,
    /// Fraction of features per tree.
    pub colsample_bytree: f64,
    /// Fraction of rows per tree.
    pub subsample: f64,
    /// Seed of column and row sampling.
    pub seed: u64,
    /// Intercept; `None` → mean of the training targets.
    pub base_score: Option<f64>,
    /// Split search.
    pub method: Method,
}

/// Soft threshold T_α(G) = sign(G)·max(|G| − α, 0).
#[must_use]
pub fn soft_threshold(g: f64, alpha: f64) -> f64 {
    if g > alpha {
        g - alpha
    } else if g < -alpha {
        g + alpha
    } else {
        0.0
    }
}

impl BoostParams {
    /// XGBoost's own defaults (η 0.3, λ 1, α 0, γ 0, min_child_weight 1, no sampling, seed 0,
    /// base score the target mean, exact splits) with `n_estimators` rounds of depth
    /// `max_depth`: the parameters of a comparison with XGBoost run as it comes. The service's
    /// defaults are the paper's Table 2 (`wire::TrainParams`).
    #[must_use]
    pub const fn xgboost(n_estimators: usize, max_depth: usize) -> Self {
        Self {
            n_estimators,
            max_depth,
            learning_rate: 0.3,
            reg_lambda: 1.0,
            reg_alpha: 0.0,
            gamma: 0.0,
            min_child_weight: 1.0,
            colsample_bytree: 1.0,
            subsample: 1.0,
            seed: 0,
            base_score: None,
            method: Method::Exact,
        }
    }

    /// score(G, H) = T_α(G)²/(H + λ); 0 when H < min_child_weight or H ≤ 0 (XGBoost's CalcGain).
    #[must_use]
    pub fn score(&self, g: f64, h: f64) -> f64 {
        if h < self.min_child_weight || h <= 0.0 {
            return 0.0;
        }
        let t = soft_threshold(g, self.reg_alpha);
        t * t / (h + self.reg_lambda)
    }

    /// w = −T_α(G)/(H + λ); 0 when H < min_child_weight or H ≤ 0 (XGBoost's CalcWeight).
    #[must_use]
    pub fn weight(&self, g: f64, h: f64) -> f64 {
        if h < self.min_child_weight || h <= 0.0 {
            return 0.0;
        }
        -soft_threshold(g, self.reg_alpha) / (h + self.reg_lambda)
    }

    /// Features drawn per tree from `d` candidates: ⌊colsample·d⌋ (the validator rejects 0).
    #[must_use]
    pub fn features_per_tree(&self, d: usize) -> usize {
        let k = (self.colsample_bytree * d as f64).floor() as usize;
        k.clamp(1, d.max(1))
    }

    /// Rows drawn per tree from `n` training rows: max(1, ⌊subsample·n⌋).
    #[must_use]
    pub fn rows_per_tree(&self, n: usize) -> usize {
        let k = (self.subsample * n as f64).floor() as usize;
        k.clamp(1, n.max(1))
    }
}

/// Pre-sorted columns for the exact method: for each candidate feature, every row of the matrix
/// in ascending order of its value, and the values in that order (12 bytes per cell): the split
/// search reads both sequentially.
#[derive(Debug, Clone)]
pub struct ExactIndex {
    n_rows: usize,
    order: Vec<u32>,
    vals: Vec<f64>,
}

impl ExactIndex {
    /// Sorts every candidate feature's column (in parallel over features).
    #[must_use]
    pub fn build(x: &Matrix, features: &[usize], threads: usize) -> Self {
        let n = x.n_rows();
        let parts = par_map(threads, features, |_, &f| {
            let col = x.col(f);
            let mut idx = super::data::all_rows(n);
            idx.sort_unstable_by(|&a, &b| {
                col[a as usize].total_cmp(&col[b as usize]).then(a.cmp(&b))
            });
            let vals: Vec<f64> = idx.iter().map(|&r| col[r as usize]).collect();
            (idx, vals)
        });
        let mut order = Vec::with_capacity(n * features.len());
        let mut vals = Vec::with_capacity(n * features.len());
        for (o, v) in parts {
            order.extend(o);
            vals.extend(v);
        }
        Self {
            n_rows: n,
            order,
            vals,
        }
    }

    fn order(&self, k: usize) -> &[u32] {
        &self.order[k * self.n_rows..(k + 1) * self.n_rows]
    }

    fn vals(&self, k: usize) -> &[f64] {
        &self.vals[k * self.n_rows..(k + 1) * self.n_rows]
    }
}

/// Binned columns for the hist method: per candidate feature the interior cut values
/// `c_1 < … < c_{B−1}` (from the training rows) and every row's bin `#{c ≤ x}` (2 bytes per cell).
#[derive(Debug, Clone)]
pub struct HistIndex {
    n_rows: usize,
    bins: Vec<u16>,
    cuts: Vec<Vec<f64>>,
}

impl HistIndex {
    /// Cuts from the training rows `rows` (quantiles; every distinct value its own bin when a
    /// feature has at most `max_bin` of them), bins for every row of `x`.
    #[must_use]
    pub fn build(
        x: &Matrix,
        rows: &[u32],
        features: &[usize],
        max_bin: usize,
        threads: usize,
    ) -> Self {
        let n = x.n_rows();
        let parts = par_map(threads, features, |_, &f| {
            let col = x.col(f);
            let cuts = cut_points(rows.iter().map(|&r| col[r as usize]).collect(), max_bin);
            let bins: Vec<u16> = col
                .iter()
                .map(|&v| u16::try_from(cuts.partition_point(|&c| c <= v)).unwrap_or(u16::MAX))
                .collect();
            (cuts, bins)
        });
        let mut bins = Vec::with_capacity(n * features.len());
        let mut cuts = Vec::with_capacity(features.len());
        for (c, b) in parts {
            cuts.push(c);
            bins.extend(b);
        }
        Self {
            n_rows: n,
            bins,
            cuts,
        }
    }

    fn bins(&self, k: usize) -> &[u16] {
        &self.bins[k * self.n_rows..(k + 1) * self.n_rows]
    }
}

/// Interior cut values of one feature: the distinct values after the first when there are at
/// most `max_bin` of them, else the values at the ranks ⌈q·n/max_bin⌉ (q = 1..max_bin−1),
/// deduplicated (unit hessians: weighted quantiles are plain quantiles).
fn cut_points(mut v: Vec<f64>, max_bin: usize) -> Vec<f64> {
    v.sort_unstable_by(f64::total_cmp);
    let mut distinct: Vec<f64> = Vec::new();
    for &x in &v {
        if distinct.last().is_none_or(|&l| x > l) {
            distinct.push(x);
        }
    }
    if distinct.len() <= max_bin {
        return distinct.into_iter().skip(1).collect();
    }
    let n = v.len();
    let mut cuts: Vec<f64> = Vec::with_capacity(max_bin);
    for q in 1..max_bin {
        let idx = (q * n).div_ceil(max_bin).min(n - 1);
        let c = v[idx];
        if c > v[0] && cuts.last().is_none_or(|&l| c > l) {
            cuts.push(c);
        }
    }
    cuts
}

/// The split-search index of one model.
#[derive(Debug, Clone)]
pub enum SplitIndex {
    /// Pre-sorted columns.
    Exact(ExactIndex),
    /// Binned columns.
    Hist(HistIndex),
}

impl SplitIndex {
    /// The index `method` searches, over `features` of `x` (the hist cuts from rows `rows`).
    #[must_use]
    pub fn build(
        method: Method,
        x: &Matrix,
        rows: &[u32],
        features: &[usize],
        threads: usize,
    ) -> Self {
        match method {
            Method::Exact => Self::Exact(ExactIndex::build(x, features, threads)),
            Method::Hist { max_bin } => {
                Self::Hist(HistIndex::build(x, rows, features, max_bin, threads))
            }
        }
    }
}

/// What one model trains on: rows `rows` of `x` with targets `y` (indexed like `x`'s rows),
/// candidate features `features` (original column indices, ascending), and the index built over
/// those features.
#[derive(Debug, Clone, Copy)]
pub struct TrainData<'a> {
    /// All rows (the model uses `rows` of them).
    pub x: &'a Matrix,
    /// Targets of every row of `x`.
    pub y: &'a [f64],
    /// Training rows, ascending.
    pub rows: &'a [u32],
    /// Candidate features (original indices, ascending).
    pub features: &'a [usize],
    /// Split index over `features`.
    pub index: &'a SplitIndex,
}

/// A trained ensemble.
#[derive(Debug, Clone)]
pub struct Boosted {
    /// Intercept.
    pub base_score: f64,
    /// Trees in round order.
    pub trees: Vec<Tree>,
    /// How training stopped.
    pub stop: StopReason,
}

impl Boosted {
    /// The model these trees make, for rows of `n_features` columns named `feature_names`
    /// (f64 routing: a native model compares thresholds in f64).
    #[must_use]
    pub fn into_model(self, n_features: usize, feature_names: Vec<String>) -> Model {
        Model {
            base_score: self.base_score,
            n_features,
            feature_names,
            routing: Routing::F64,
            source: ModelSource::Native,
            trees: self.trees,
        }
    }
}

/// Trains an ensemble on `data` (spec §3). Checks the budget before every round; returns the
/// trees built so far with the stop reason when it is spent. Stops early with
/// [`StopReason::Converged`] when a round produced one zero leaf while every feature and row
/// was used: every further round would build the same no-op tree.
#[must_use]
pub fn boost(data: &TrainData<'_>, p: &BoostParams, budget: &Budget, threads: usize) -> Boosted {
    let n = data.x.n_rows();
    let m = data.rows.len();
    let base = p.base_score.unwrap_or_else(|| {
        data.rows.iter().map(|&r| data.y[r as usize]).sum::<f64>() / m.max(1) as f64
    });
    let mut ws = Workspace {
        yc: data.y.iter().map(|&y| y - base).collect(),
        margin: vec![0.0; n],
        row: vec![RowState { g: 0.0, pos: NONE }; n],
        node_of: vec![0; n],
        inv: (0..=m)
            .map(|c| {
                let h = c as f64 + p.reg_lambda;
                if h > 0.0 { 1.0 / h } else { 0.0 }
            })
            .collect(),
    };
    let mut rng = rng::stream(p.seed, rng::STREAM_SAMPLING);
    let d = data.features.len();
    let k_cols = p.features_per_tree(d);
    let k_rows = p.rows_per_tree(m);
    let deterministic = k_cols == d && k_rows == m;
    let mut trees = Vec::with_capacity(p.n_estimators);
    let mut stop = StopReason::Completed;
    for _ in 0..p.n_estimators {
        if let Some(reason) = budget.check(trees.len() as u64) {
            stop = reason;
            break;
        }
        // Round counts are far below 2^53: exact in f64.
        budget.progress(trees.len() as f64 / p.n_estimators as f64, None);
        let cols: Vec<usize> = if k_cols == d {
            (0..d).collect()
        } else {
            rng::sample_sorted(&mut rng, d, k_cols)
        };
        let sampled: Option<Vec<bool>> = (k_rows < m).then(|| {
            let mut s = vec![false; n];
            for i in rng::sample_sorted(&mut rng, m, k_rows) {
                s[data.rows[i] as usize] = true;
            }
            s
        });
        for &r in data.rows {
            let r = r as usize;
            ws.row[r].g = ws.margin[r] - ws.yc[r];
        }
        let tree = grow(data, p, &mut ws, &cols, sampled.as_deref(), threads);
        let no_op = tree.nodes.len() == 1 && tree.nodes[0].value == 0.0;
        trees.push(tree);
        if no_op && deterministic {
            stop = StopReason::Converged;
            break;
        }
    }
    Boosted {
        base_score: base,
        trees,
        stop,
    }
}

/// Per-row state of one model, indexed by the rows of `x`.
struct Workspace {
    /// Centred targets y − base.
    yc: Vec<f64>,
    /// Σ tree outputs so far (margin without base).
    margin: Vec<f64>,
    /// Gradient and level slot of every row, side by side: the split search reads both for each
    /// entry of a sorted column, so one cache line serves both.
    row: Vec<RowState>,
    /// The row's node in the tree under construction.
    node_of: Vec<u32>,
    /// 1/(c + λ) for every row count c: hessians are 1, so H is a count and the split search
    /// multiplies instead of dividing twice per boundary (scores agree with the division to
    /// 1 ulp; the tie tolerance absorbs that).
    inv: Vec<f64>,
}

/// Gradient (hessian 1) and level slot of one row.
#[derive(Debug, Clone, Copy)]
struct RowState {
    /// g = margin − yc.
    g: f64,
    /// Slot of the row's node in the current level (or [`NONE`], with [`UNSAMPLED`]).
    pos: u32,
}

/// A node under construction.
#[derive(Debug, Clone, Copy)]
struct BNode {
    /// Σ g of its sampled rows.
    g: f64,
    /// Its sampled rows (= Σ h).
    n: u32,
    depth: usize,
    /// Chosen split, if any (cleared by pruning).
    split: Option<Split>,
    /// Children ids (valid once split, kept after pruning to map rows).
    left: u32,
    right: u32,
}

#[derive(Debug, Clone, Copy)]
struct Split {
    feature: usize,
    threshold: f64,
    gain: f64,
}

/// The best boundary of one node over one feature.
#[derive(Debug, Clone, Copy)]
struct Cand {
    gain: f64,
    /// Threshold θ.
    threshold: f64,
    /// Σ g and count of the left child.
    gl: f64,
    nl: u32,
}

/// score(G, H) of a child with H = `count` ≥ min_child_weight rows: T_α(G)²·(1/(H + λ)).
fn fast_score(g: f64, count: u32, inv: &[f64], alpha: f64) -> f64 {
    let t = soft_threshold(g, alpha);
    t * t * inv[count as usize]
}

/// Whether a candidate with loss change `gain` replaces `best` (strictly better beyond the tie
/// tolerance; the first found keeps a tie).
fn better(gain: f64, best: Option<&Cand>) -> bool {
    best.is_none_or(|b| gain > b.gain + TIE_REL * b.gain.abs().max(1.0))
}

/// The midpoint of two consecutive distinct values, nudged up to `hi` when rounding put it on
/// `lo` (adjacent floats), so that `x < θ` sends exactly the values ≤ `lo` left.
fn midpoint(lo: f64, hi: f64) -> f64 {
    let m = lo * 0.5 + hi * 0.5;
    if m > lo { m } else { hi }
}

/// Sums of the nodes of one level, by slot.
struct Level {
    g: Vec<f64>,
    n: Vec<u32>,
    parent_score: Vec<f64>,
}

/// Grows one tree over the sampled candidate features `cols` (positions in `data.features`)
/// and the sampled rows (`None`: all training rows), prunes it, and adds its output to the
/// margins of all training rows.
fn grow(
    data: &TrainData<'_>,
    p: &BoostParams,
    ws: &mut Workspace,
    cols: &[usize],
    sampled: Option<&[bool]>,
    threads: usize,
) -> Tree {
    let (mut g0, mut n0) = (0.0, 0u32);
    for &r in data.rows {
        let r = r as usize;
        ws.node_of[r] = 0;
        if sampled.is_none_or(|s| s[r]) {
            ws.row[r].pos = 0;
            g0 += ws.row[r].g;
            n0 += 1;
        } else {
            ws.row[r].pos = UNSAMPLED;
        }
    }
    let mut nodes = vec![BNode {
        g: g0,
        n: n0,
        depth: 0,
        split: None,
        left: LEAF,
        right: LEAF,
    }];
    let expandable = |b: &BNode| b.depth < p.max_depth && b.n >= 2;
    let mut level: Vec<u32> = if expandable(&nodes[0]) {
        vec![0]
    } else {
        Vec::new()
    };
    while !level.is_empty() {
        let stats = Level {
            g: level.iter().map(|&i| nodes[i as usize].g).collect(),
            n: level.iter().map(|&i| nodes[i as usize].n).collect(),
            parent_score: level
                .iter()
                .map(|&i| {
                    let b = &nodes[i as usize];
                    p.score(b.g, f64::from(b.n))
                })
                .collect(),
        };
        let best = search_level(data, p, ws, cols, &stats, threads);
        // Children of each slot: their slot in the next level, or NONE.
        let mut next: Vec<u32> = Vec::new();
        let mut child_slot: Vec<(u32, u32)> = vec![(NONE, NONE); level.len()];
        for (s, c) in best.iter().enumerate() {
            let Some(c) = c.filter(|c| c.gain > KRT_EPS) else {
                continue;
            };
            let id = level[s] as usize;
            let (k, depth) = (c.feature, nodes[id].depth + 1);
            let left = u32::try_from(nodes.len()).unwrap_or(LEAF);
            let (gl, nl) = (c.cand.gl, c.cand.nl);
            let parent = nodes[id];
            nodes.push(BNode {
                g: gl,
                n: nl,
                depth,
                split: None,
                left: LEAF,
                right: LEAF,
            });
            nodes.push(BNode {
                g: parent.g - gl,
                n: parent.n - nl,
                depth,
                split: None,
                left: LEAF,
                right: LEAF,
            });
            let b = &mut nodes[id];
            b.split = Some(Split {
                feature: data.features[k],
                threshold: c.cand.threshold,
                gain: c.cand.gain,
            });
            b.left = left;
            b.right = left + 1;
            let mut slot_of = |child: u32| {
                if expandable(&nodes[child as usize]) {
                    next.push(child);
                    u32::try_from(next.len() - 1).unwrap_or(NONE)
                } else {
                    NONE
                }
            };
            child_slot[s] = (slot_of(left), slot_of(left + 1));
        }
        route(data, ws, &level, &nodes, &child_slot);
        level = next;
    }
    finish_tree(data, p, ws, nodes)
}

/// A slot's best split over all sampled features.
#[derive(Debug, Clone, Copy)]
struct Best {
    /// Position in `cols`.
    feature: usize,
    cand: Cand,
}

impl std::ops::Deref for Best {
    type Target = Cand;
    fn deref(&self) -> &Cand {
        &self.cand
    }
}

/// Best candidate per slot of the level, over the sampled features in ascending order.
fn search_level(
    data: &TrainData<'_>,
    p: &BoostParams,
    ws: &Workspace,
    cols: &[usize],
    st: &Level,
    threads: usize,
) -> Vec<Option<Best>> {
    let scan = |_: usize, &k: &usize| -> Vec<Option<Cand>> {
        match data.index {
            SplitIndex::Exact(ix) => scan_exact(ix.order(k), ix.vals(k), ws, st, p),
            SplitIndex::Hist(ix) => scan_hist(ix.bins(k), &ix.cuts[k], data.rows, ws, st, p),
        }
    };
    let rows_scanned = match data.index {
        SplitIndex::Exact(_) => data.x.n_rows(),
        SplitIndex::Hist(_) => data.rows.len(),
    };
    let per_feature: Vec<Vec<Option<Cand>>> =
        if threads > 1 && cols.len() > 1 && rows_scanned * cols.len() >= PAR_MIN_WORK {
            par_map(threads, cols, scan)
        } else {
            cols.iter().enumerate().map(|(i, k)| scan(i, k)).collect()
        };
    let mut best: Vec<Option<Best>> = vec![None; st.g.len()];
    for (i, res) in per_feature.iter().enumerate() {
        for (s, c) in res.iter().enumerate() {
            if let Some(c) = c
                && better(c.gain, best[s].as_ref().map(|b| &b.cand))
            {
                best[s] = Some(Best {
                    feature: i,
                    cand: *c,
                });
            }
        }
    }
    // Map positions in `cols` back to candidate positions.
    for b in best.iter_mut().flatten() {
        b.feature = cols[b.feature];
    }
    best
}

/// Exact search over one pre-sorted column: every boundary between consecutive distinct values of
/// each node's sampled rows, ascending.
fn scan_exact(
    order: &[u32],
    vals: &[f64],
    ws: &Workspace,
    st: &Level,
    p: &BoostParams,
) -> Vec<Option<Cand>> {
    #[derive(Clone, Copy)]
    struct Acc {
        gl: f64,
        nl: u32,
        last: f64,
        best: Option<Cand>,
    }
    let nslots = st.g.len();
    let mut acc = vec![
        Acc {
            gl: 0.0,
            nl: 0,
            last: 0.0,
            best: None,
        };
        nslots
    ];
    let limit = u32::try_from(nslots).unwrap_or(NONE);
    for (&r, &x) in order.iter().zip(vals) {
        let RowState { g, pos: s } = ws.row[r as usize];
        if s >= limit {
            continue;
        }
        let s = s as usize;
        let a = &mut acc[s];
        if a.nl > 0 && x > a.last {
            let nr = st.n[s] - a.nl;
            let (hl, hr) = (f64::from(a.nl), f64::from(nr));
            if hl >= p.min_child_weight && hr >= p.min_child_weight {
                let gain = fast_score(a.gl, a.nl, &ws.inv, p.reg_alpha)
                    + fast_score(st.g[s] - a.gl, nr, &ws.inv, p.reg_alpha)
                    - st.parent_score[s];
                if better(gain, a.best.as_ref()) {
                    a.best = Some(Cand {
                        gain,
                        threshold: midpoint(a.last, x),
                        gl: a.gl,
                        nl: a.nl,
                    });
                }
            }
        }
        a.gl += g;
        a.nl += 1;
        a.last = x;
    }
    acc.into_iter().map(|a| a.best).collect()
}

/// Histogram search over one binned column: the boundary after every non-empty bin of each
/// node, ascending; θ = that bin's upper cut.
fn scan_hist(
    bins: &[u16],
    cuts: &[f64],
    rows: &[u32],
    ws: &Workspace,
    st: &Level,
    p: &BoostParams,
) -> Vec<Option<Cand>> {
    let nslots = st.g.len();
    let nb = cuts.len() + 1;
    let mut hist = vec![(0.0f64, 0u32); nslots * nb];
    let limit = u32::try_from(nslots).unwrap_or(NONE);
    for &r in rows {
        let r = r as usize;
        let RowState { g, pos: s } = ws.row[r];
        if s >= limit {
            continue;
        }
        let h = &mut hist[s as usize * nb + usize::from(bins[r])];
        h.0 += g;
        h.1 += 1;
    }
    let mut out = vec![None; nslots];
    for (s, best) in out.iter_mut().enumerate() {
        let (mut gl, mut nl) = (0.0, 0u32);
        for (j, &(gb, nbin)) in hist[s * nb..(s + 1) * nb - 1].iter().enumerate() {
            gl += gb;
            nl += nbin;
            let nr = st.n[s] - nl;
            if nbin == 0 || nl == 0 || nr == 0 {
                continue;
            }
            let (hl, hr) = (f64::from(nl), f64::from(nr));
            if hl >= p.min_child_weight && hr >= p.min_child_weight {
                let gain = fast_score(gl, nl, &ws.inv, p.reg_alpha)
                    + fast_score(st.g[s] - gl, nr, &ws.inv, p.reg_alpha)
                    - st.parent_score[s];
                if better(gain, best.as_ref()) {
                    *best = Some(Cand {
                        gain,
                        threshold: cuts[j],
                        gl,
                        nl,
                    });
                }
            }
        }
    }
    out
}

/// Sends every training row of a split node to its child (`x < θ` → left), as prediction will.
fn route(
    data: &TrainData<'_>,
    ws: &mut Workspace,
    level: &[u32],
    nodes: &[BNode],
    child_slot: &[(u32, u32)],
) {
    let limit = u32::try_from(level.len()).unwrap_or(NONE);
    for &r in data.rows {
        let r = r as usize;
        let p = ws.row[r].pos;
        let s = p & !UNSAMPLED;
        if s >= limit {
            continue;
        }
        let b = &nodes[level[s as usize] as usize];
        let Some(split) = b.split else {
            ws.row[r].pos = NONE | (p & UNSAMPLED);
            continue;
        };
        let (left, (ls, rs)) = (
            data.x.get(r, split.feature) < split.threshold,
            child_slot[s as usize],
        );
        ws.node_of[r] = if left { b.left } else { b.right };
        ws.row[r].pos = (if left { ls } else { rs }) | (p & UNSAMPLED);
    }
}

/// Leaf values, γ pruning, compaction to a breadth-first [`Tree`], and the margin update.
fn finish_tree(
    data: &TrainData<'_>,
    p: &BoostParams,
    ws: &mut Workspace,
    mut nodes: Vec<BNode>,
) -> Tree {
    // γ pruning, bottom-up: a split whose children are both leaves and whose (un-halved) loss
    // change is below γ becomes a leaf (XGBoost's TreePruner).
    if p.gamma > 0.0 {
        for i in (0..nodes.len()).rev() {
            let Some(split) = nodes[i].split else {
                continue;
            };
            let (l, r) = (nodes[i].left as usize, nodes[i].right as usize);
            if nodes[l].split.is_none() && nodes[r].split.is_none() && split.gain < p.gamma {
                nodes[i].split = None;
            }
        }
    }
    // Representative of every node: itself, or the pruned ancestor that became its leaf.
    let mut rep: Vec<u32> = (0..nodes.len())
        .map(|i| u32::try_from(i).unwrap_or(LEAF))
        .collect();
    for i in 0..nodes.len() {
        let b = nodes[i];
        if b.left == LEAF {
            continue;
        }
        let up = if b.split.is_none() || rep[i] as usize != i {
            rep[i]
        } else {
            LEAF
        };
        for c in [b.left, b.right] {
            if up != LEAF {
                rep[c as usize] = up;
            }
        }
    }
    // Compaction: breadth-first over the surviving nodes.
    let mut new_id = vec![LEAF; nodes.len()];
    let mut order: Vec<usize> = vec![0];
    new_id[0] = 0;
    let mut head = 0;
    while head < order.len() {
        let i = order[head];
        head += 1;
        if nodes[i].split.is_some() {
            for c in [nodes[i].left as usize, nodes[i].right as usize] {
                new_id[c] = u32::try_from(order.len()).unwrap_or(LEAF);
                order.push(c);
            }
        }
    }
    let out: Vec<Node> = order
        .iter()
        .map(|&i| {
            let b = &nodes[i];
            let value = p.learning_rate * p.weight(b.g, f64::from(b.n));
            match b.split {
                Some(s) => Node {
                    left: new_id[b.left as usize],
                    right: new_id[b.right as usize],
                    feature: u32::try_from(s.feature).unwrap_or(0),
                    threshold: s.threshold,
                    default_left: false,
                    value,
                    cover: f64::from(b.n),
                    loss_change: s.gain,
                },
                None => Node::leaf(value, f64::from(b.n)),
            }
        })
        .collect();
    for &r in data.rows {
        let r = r as usize;
        let leaf = new_id[rep[ws.node_of[r] as usize] as usize] as usize;
        ws.margin[r] += out[leaf].value;
    }
    Tree { nodes: out }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hand-checkable stump of spec T1: one round, depth 1, η 1.
    fn params() -> BoostParams {
        BoostParams {
            learning_rate: 1.0,
            ..BoostParams::xgboost(1, 1)
        }
    }

    fn train(p: &BoostParams) -> Boosted {
        let x = Matrix::from_rows(vec![vec![1.0], vec![2.0], vec![3.0], vec![4.0]], 1);
        let y = [1.0, 2.0, 3.0, 10.0];
        let rows = super::super::data::all_rows(4);
        let features = [0usize];
        let index = SplitIndex::build(p.method, &x, &rows, &features, 1);
        let data = TrainData {
            x: &x,
            y: &y,
            rows: &rows,
            features: &features,
            index: &index,
        };
        boost(&data, p, &Budget::unlimited(), 1)
    }

    fn predict(b: &Boosted, x: f64) -> f64 {
        b.base_score + b.trees.iter().map(|t| t.predict(&[x])).sum::<f64>()
    }

    #[test]
    fn t1_hand_checked_split() {
        let b = train(&params());
        let root = b.trees[0].nodes[0];
        assert_eq!((root.threshold).to_bits(), f64::to_bits(3.5));
        assert!((root.loss_change - 27.0).abs() < 1e-12);
        let pred: Vec<f64> = [1.0, 2.0, 3.0, 4.0]
            .iter()
            .map(|&x| predict(&b, x))
            .collect();
        for (p, e) in pred.iter().zip([2.5, 2.5, 2.5, 7.0]) {
            assert!((p - e).abs() < 1e-12, "{pred:?}");
        }
    }

    #[test]
    fn t3_gamma_pruning_is_unhalved() {
        let b = train(&BoostParams {
            gamma: 26.9,
            ..params()
        });
        assert_eq!(b.trees[0].nodes.len(), 3);
        let b = train(&BoostParams {
            gamma: 27.1,
            ..params()
        });
        assert_eq!(b.trees[0].nodes.len(), 1);
        assert!((predict(&b, 1.0) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn t2_two_trees_with_l1() {
        let b = train(&BoostParams {
            n_estimators: 2,
            max_depth: 2,
            learning_rate: 0.5,
            reg_lambda: 0.5,
            reg_alpha: 0.5,
            gamma: 3.0,
            ..params()
        });
        assert!((predict(&b, 1.0) - 2.765_306_122_4).abs() < 1e-9);
        assert!((predict(&b, 4.0) - 7.055_555_555_6).abs() < 1e-9);
    }

    #[test]
    fn hist_equals_exact_partition_on_few_values() {
        let b = train(&BoostParams {
            method: Method::Hist { max_bin: 256 },
            ..params()
        });
        assert_eq!((b.trees[0].nodes[0].threshold).to_bits(), f64::to_bits(4.0));
        assert!((predict(&b, 3.0) - 2.5).abs() < 1e-12);
    }

    /// Every node's cover equals the training rows that reach it by traversal, whatever the
    /// column sample (regression: a sampled feature's position was mapped twice).
    #[test]
    fn covers_match_routing_with_column_sampling() {
        let mut r = rng::stream(5, 0);
        let n = 200;
        let rows: Vec<Vec<f64>> = (0..n)
            .map(|_| {
                (0..6)
                    .map(|_| (rng::uniform(&mut r) * 8.0).floor())
                    .collect()
            })
            .collect();
        let y: Vec<f64> = rows
            .iter()
            .map(|v| v[1] - 2.0 * v[4] + rng::uniform(&mut r))
            .collect();
        let x = Matrix::from_rows(rows.clone(), 6);
        let all = super::super::data::all_rows(n);
        let features: Vec<usize> = (0..6).collect();
        for method in [Method::Exact, Method::Hist { max_bin: 4 }] {
            let index = SplitIndex::build(method, &x, &all, &features, 2);
            let data = TrainData {
                x: &x,
                y: &y,
                rows: &all,
                features: &features,
                index: &index,
            };
            let p = BoostParams {
                n_estimators: 20,
                max_depth: 4,
                learning_rate: 0.3,
                colsample_bytree: 0.5,
                method,
                ..params()
            };
            let b = boost(&data, &p, &Budget::unlimited(), 2);
            for t in &b.trees {
                let mut count = vec![0.0f64; t.nodes.len()];
                for row in &rows {
                    let mut i = 0;
                    loop {
                        count[i] += 1.0;
                        let nd = &t.nodes[i];
                        if nd.is_leaf() {
                            break;
                        }
                        i = if row[nd.feature as usize] < nd.threshold {
                            nd.left
                        } else {
                            nd.right
                        } as usize;
                    }
                }
                for (c, nd) in count.iter().zip(&t.nodes) {
                    assert_eq!(c.to_bits(), nd.cover.to_bits(), "{method:?}");
                }
            }
        }
    }

    #[test]
    fn cut_points_quantiles() {
        let v: Vec<f64> = (0..1000).map(f64::from).collect();
        let c = cut_points(v, 4);
        assert_eq!(c, vec![250.0, 500.0, 750.0]);
        assert_eq!(cut_points(vec![2.0, 1.0, 2.0, 3.0], 256), vec![2.0, 3.0]);
    }
}
