//! Second-order gradient boosting of regression trees with XGBoost's squared-error semantics
//! (spec §3): centred targets in f64, trees grown level by level over pre-sorted columns
//! ("exact", XGBoost's colmaker) or over per-feature bins ("hist"), L1/L2 leaf regularisation,
//! XGBoost's split threshold 1e-6 (`kRtEps`) and its γ pruning with the un-halved loss change.
//!
//! Growing level by level gives the same trees as the spec's depth-first description (a node's
//! split depends only on its own rows) and numbers the nodes breadth-first as XGBoost does.
//! Every node's sampled rows are one contiguous run of the tree's row list (hist) or of every
//! working column (exact), partitioned stably when the node splits, so a level touches only the
//! rows of its open nodes, in ascending row (hist) or value (exact) order.
//!
//! * exact: each sampled feature's working column holds 4-byte cells in ascending value order:
//!   the row, and a flag for "greater than the previous cell's value" that stays true through
//!   the partitions (the gradient and, for a chosen split only, the values are read by row); a
//!   level partitions the runs split by the previous level and scans the open runs, one feature
//!   per task on the compute threads ([`par_map`]).
//! * hist: bins are built once per model, row-major (one byte per cell when every feature has
//!   at most 256 bins). A node's histogram is summed from its own rows only, and of two
//!   expandable siblings only the smaller one is summed: the other is the parent's histogram
//!   minus it (counts exact, gradient sums equal to round-off) where that pays: when the larger
//!   child has more rows than its histogram has bins. Histograms are capped per model (bytes per
//!   training cell and an absolute ceiling). Histogram builds (split into feature chunks) and
//!   node searches run on the compute threads.
//!
//! Every parallel result is a sum in a fixed order (bins over a node's rows in row order; the
//! per-feature bests reduced in ascending feature order), so the trees are bit-identical for any
//! thread count.

use std::sync::{Mutex, MutexGuard, PoisonError};

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

/// Most histogram bytes of one level alive at once: a level with more nodes is processed in
/// batches (deep trees over many features and bins would otherwise hold gigabytes). Also at most
/// [`HIST_BYTES_PER_CELL`] per training cell (at least [`HIST_MIN_BYTES`]), so that the
/// histograms stay a small multiple of the data: k-fold training runs two models at once.
const HIST_BATCH_BYTES: usize = 64 << 20;

/// Most bytes of parent histograms kept for the sibling subtraction of the next level; siblings
/// beyond it are both summed directly. Also at most [`HIST_BYTES_PER_CELL`] per training cell.
const HIST_KEEP_BYTES: usize = 128 << 20;

/// Histogram bytes per training cell (rows × sampled features) one model may hold in a batch
/// and in kept parent histograms (each).
const HIST_BYTES_PER_CELL: usize = 8;

/// Histogram bytes a model may always hold in a batch and in kept parents (small data sets).
const HIST_MIN_BYTES: usize = 4 << 20;

/// Histogram slots per feature with one-byte bins (every bin number indexes them).
const U8_SLOTS: usize = 256;

/// Smallest histogram build (node rows × sampled features) split into per-thread feature chunks.
const HIST_CHUNK_WORK: usize = 32_768;

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

/// The flag bit of a column cell ([`ExactIndex`], [`Column`]): the cell's value is greater than
/// the value of the cell before it in its run (meaningless on a run's first cell: no scan reads
/// it there).
const NEW_VALUE: u32 = 1 << 31;

/// The row bits of a column cell. Rows are below 2³¹ (the service takes at most 100 000).
const ROW: u32 = NEW_VALUE - 1;

/// Pre-sorted columns for the exact method: for each candidate feature, every row of the matrix
/// in ascending order of its value, one 4-byte cell per row: the row, and in its top bit
/// whether its value is greater than the previous cell's. The split search never reads the
/// values themselves: a boundary is wherever the flag is set, and a chosen threshold is computed
/// from the matrix. The values must not be NaN (rows are finite at the door) and the rows must
/// be below 2³¹.
#[derive(Debug, Clone)]
pub struct ExactIndex {
    n_rows: usize,
    cells: Vec<u32>,
}

impl ExactIndex {
    /// Sorts every candidate feature's column (in parallel over features).
    #[must_use]
    pub fn build(x: &Matrix, features: &[usize], threads: usize) -> Self {
        let n = x.n_rows();
        debug_assert!(
            n <= ROW as usize + 1,
            "rows of the exact index must be below 2^31"
        );
        let parts = par_map(threads, features, |_, &f| {
            let col = x.col(f);
            let mut idx = super::data::all_rows(n);
            idx.sort_unstable_by(|&a, &b| {
                col[a as usize].total_cmp(&col[b as usize]).then(a.cmp(&b))
            });
            let mut prev = f64::INFINITY;
            for c in &mut idx {
                let v = col[*c as usize];
                *c = (*c & ROW) | if v > prev { NEW_VALUE } else { 0 };
                prev = v;
            }
            idx
        });
        let mut cells = Vec::with_capacity(n * features.len());
        for c in parts {
            cells.extend(c);
        }
        Self { n_rows: n, cells }
    }

    fn cells(&self, k: usize) -> &[u32] {
        &self.cells[k * self.n_rows..(k + 1) * self.n_rows]
    }
}

/// Binned columns for the hist method: per candidate feature the interior cut values
/// `c_1 < … < c_{B−1}` (from the training rows), and every row's bins `#{c ≤ x}` stored row by
/// row, one byte per cell when every feature has at most 256 bins (two bytes otherwise): a
/// histogram build reads one short contiguous run per row of the node it builds.
#[derive(Debug, Clone)]
pub struct HistIndex {
    n_feat: usize,
    bins: Bins,
    cuts: Vec<Vec<f64>>,
}

/// Row-major bin numbers (`n_rows × n_feat`).
#[derive(Debug, Clone)]
enum Bins {
    /// Every feature has at most 256 bins.
    U8(Vec<u8>),
    /// Some feature has more than 256 bins (`max_bin` ≤ 1024).
    U16(Vec<u16>),
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
        let nf = features.len();
        let parts = par_map(threads, features, |_, &f| {
            let col = x.col(f);
            let cuts = cut_points(rows.iter().map(|&r| col[r as usize]).collect(), max_bin);
            let bins: Vec<u16> = col
                .iter()
                .map(|&v| u16::try_from(cuts.partition_point(|&c| c <= v)).unwrap_or(u16::MAX))
                .collect();
            (cuts, bins)
        });
        // Bin numbers run 0..=cuts.len().
        let bins = if parts.iter().all(|(c, _)| c.len() <= usize::from(u8::MAX)) {
            let mut b = vec![0u8; n * nf];
            for (k, (_, col)) in parts.iter().enumerate() {
                for (r, &v) in col.iter().enumerate() {
                    b[r * nf + k] = u8::try_from(v).unwrap_or(u8::MAX);
                }
            }
            Bins::U8(b)
        } else {
            let mut b = vec![0u16; n * nf];
            for (k, (_, col)) in parts.iter().enumerate() {
                for (r, &v) in col.iter().enumerate() {
                    b[r * nf + k] = v;
                }
            }
            Bins::U16(b)
        };
        Self {
            n_feat: nf,
            bins,
            cuts: parts.into_iter().map(|(c, _)| c).collect(),
        }
    }

    /// Number of bins of candidate feature `k`.
    fn n_bins(&self, k: usize) -> usize {
        self.cuts[k].len() + 1
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
    boost_with(data, p, budget, threads, true)
}

/// [`boost`], with the hist method's sibling subtraction switchable (`subtract` false: every
/// node's histogram summed from its own rows; the tests compare the two).
fn boost_with(
    data: &TrainData<'_>,
    p: &BoostParams,
    budget: &Budget,
    threads: usize,
    subtract: bool,
) -> Boosted {
    let n = data.x.n_rows();
    let m = data.rows.len();
    let base = p.base_score.unwrap_or_else(|| {
        data.rows.iter().map(|&r| data.y[r as usize]).sum::<f64>() / m.max(1) as f64
    });
    let mut ws = Workspace {
        yc: data.y.iter().map(|&y| y - base).collect(),
        margin: vec![0.0; n],
        g: vec![0.0; n],
        inv: (0..=m)
            .map(|c| {
                let h = c as f64 + p.reg_lambda;
                if h > 0.0 { 1.0 / h } else { 0.0 }
            })
            .collect(),
        columns: match data.index {
            SplitIndex::Exact(_) => (0..data.features.len())
                .map(|_| Mutex::new(Column::default()))
                .collect(),
            SplitIndex::Hist(_) => Vec::new(),
        },
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
            ws.g[r] = ws.margin[r] - ws.yc[r];
        }
        let tree = match data.index {
            SplitIndex::Exact(ix) => {
                grow_exact(data, ix, p, &mut ws, &cols, sampled.as_deref(), threads)
            }
            SplitIndex::Hist(ix) => grow_hist(
                data,
                ix,
                p,
                &mut ws,
                &cols,
                sampled.as_deref(),
                threads,
                subtract,
            ),
        };
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
    /// Gradient g = margin − yc of every row (hessians are 1).
    g: Vec<f64>,
    /// 1/(c + λ) for every row count c: hessians are 1, so H is a count and the split search
    /// multiplies instead of dividing twice per boundary (scores agree with the division to
    /// 1 ulp; the tie tolerance absorbs that).
    inv: Vec<f64>,
    /// The exact method's working column of every candidate feature (reused tree after tree;
    /// one lock each so that the compute threads can each own some of them).
    columns: Vec<Mutex<Column>>,
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
    /// The node's sampled rows: `start..end` of the tree's row list (hist) or of every working
    /// column (exact).
    start: usize,
    end: usize,
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
/// Branch-free: |T_α(G)| = max(|G| − α, 0), bit for bit (rounding is symmetric in sign), and
/// the sign does not matter once squared.
fn fast_score(g: f64, count: u32, inv: &[f64], alpha: f64) -> f64 {
    let t = (g.abs() - alpha).max(0.0);
    t * t * inv[count as usize]
}

/// The loss change a candidate must exceed to replace a best of loss change `best` (see
/// [`better`]); the scans keep it beside their best instead of recomputing it per boundary.
fn bar(best: f64) -> f64 {
    best + TIE_REL * best.abs().max(1.0)
}

/// Whether a candidate with loss change `gain` replaces `best` (strictly better beyond the tie
/// tolerance; the first found keeps a tie).
fn better(gain: f64, best: Option<&Cand>) -> bool {
    best.is_none_or(|b| gain > bar(b.gain))
}

/// The midpoint of two consecutive distinct values, nudged up to `hi` when rounding put it on
/// `lo` (adjacent floats), so that `x < θ` sends exactly the values ≤ `lo` left.
/// The two children of `parent` split by candidate `c`: the first `c.nl` rows of its run go
/// left, the rest right.
fn children(parent: &BNode, c: &Cand) -> (BNode, BNode) {
    let mid = parent.start + c.nl as usize;
    let left = BNode {
        g: c.gl,
        n: c.nl,
        depth: parent.depth + 1,
        split: None,
        left: LEAF,
        right: LEAF,
        start: parent.start,
        end: mid,
    };
    let right = BNode {
        g: parent.g - c.gl,
        n: parent.n - c.nl,
        start: mid,
        end: parent.end,
        ..left
    };
    (left, right)
}

fn midpoint(lo: f64, hi: f64) -> f64 {
    let m = lo * 0.5 + hi * 0.5;
    if m > lo { m } else { hi }
}

/// A tree's working column (exact method): the sampled training rows in ascending order of the
/// feature, one 4-byte cell each (row and [`NEW_VALUE`] flag, as in [`ExactIndex`]): a column
/// of 10⁵ rows (400 KB) stays in a core's L2 cache beside the gradients, and a model's columns
/// are half of its data. (The earlier 12-byte (value, row) cells made the cost per row grow by a
/// quarter from 10⁴ to 10⁵ rows; a gradient beside each cell keeps the scan sequential but moves
/// three times the bytes per partition and was slower at 10⁴ rows: benches/RESULTS.md.)
#[derive(Debug, Default)]
struct Column {
    r: Vec<u32>,
}

/// Locks a working column (a poisoned lock means another worker panicked; that panic is re-raised
/// by the parallel map, so the data are never read after it).
fn lock(c: &Mutex<Column>) -> MutexGuard<'_, Column> {
    c.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Stable partition of every segment `start..end` of `col` in `splits`: rows with `left[r]`
/// first, each side in its previous (ascending value) order. The [`NEW_VALUE`] flags stay true
/// of each side: a cell's value is greater than that of the previous cell of its side exactly
/// when some cell from there to it (itself included) had its flag set (the values ascend), so
/// each side ORs the flags it passes over into the next cell it receives.
fn partition(col: &mut Column, splits: &[(usize, usize)], left: &[u64], tmp: &mut Vec<u32>) {
    for &(start, end) in splits {
        // Branch-free (the sides are as good as random): both sides are written, the index of
        // the other side stays.
        if tmp.len() < end - start {
            tmp.resize(end - start, 0);
        }
        let run = &mut col.r[start..end];
        let (mut w, mut t) = (0, 0);
        // The flags passed over since each side's last cell.
        let (mut fl, mut fr) = (0u32, 0u32);
        for i in 0..run.len() {
            let c = run[i];
            let l = is_left(left, c & ROW);
            run[w] = c | fl;
            tmp[t] = c | fr;
            // The side that took the cell starts over: all ones keep, zero clears.
            let keep_l = u32::from(l).wrapping_sub(1);
            let f = c & NEW_VALUE;
            fl = (fl | f) & keep_l;
            fr = (fr | f) & !keep_l;
            w += usize::from(l);
            t += usize::from(!l);
        }
        run[w..].copy_from_slice(&tmp[..t]);
    }
}

/// The fewest rows a child needs: a count c satisfies c ≥ `min_child_weight` (as f64, exactly)
/// when c ≥ this (never for NaN).
#[expect(
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss,
    reason = "a positive integral value, saturating above u64::MAX (no count reaches it)"
)]
fn least_count(min_child_weight: f64) -> u64 {
    if min_child_weight.is_nan() {
        u64::MAX
    } else if min_child_weight <= 0.0 {
        0
    } else {
        min_child_weight.ceil() as u64
    }
}

/// Bit `r` of the bit set `bits`.
fn is_left(bits: &[u64], r: u32) -> bool {
    (bits[(r >> 6) as usize] >> (r & 63)) & 1 != 0
}

/// Exact search over one node's run `cells` of a working column (ascending values of `xs`, the
/// feature's column of the matrix): every boundary between consecutive distinct values (a cell
/// flagged [`NEW_VALUE`]), ascending; the first of tied candidates wins. The threshold is the
/// midpoint of the values either side of the best boundary, read from `xs` once at the end.
fn scan_exact(
    cells: &[u32],
    xs: &[f64],
    g: &[f64],
    node: &BNode,
    parent_score: f64,
    p: &BoostParams,
    inv: &[f64],
) -> Option<Cand> {
    let (mut gl, mut nl) = (0.0, 0u32);
    let mut best: Option<Cand> = None;
    let mut need = f64::NEG_INFINITY;
    let least = least_count(p.min_child_weight);
    for &c in cells {
        if nl > 0 && c & NEW_VALUE != 0 {
            let nr = node.n - nl;
            if u64::from(nl) >= least && u64::from(nr) >= least {
                let gain = fast_score(gl, nl, inv, p.reg_alpha)
                    + fast_score(node.g - gl, nr, inv, p.reg_alpha)
                    - parent_score;
                if gain > need {
                    best = Some(Cand {
                        gain,
                        threshold: 0.0,
                        gl,
                        nl,
                    });
                    need = bar(gain);
                }
            }
        }
        gl += g[(c & ROW) as usize];
        nl += 1;
    }
    best.map(|mut b| {
        // nl ≥ 1 and nl < cells.len() for every candidate.
        let value = |i: usize| cells.get(i).map_or(0.0, |&c| xs[(c & ROW) as usize]);
        let i = b.nl as usize;
        b.threshold = midpoint(value(i - 1), value(i));
        b
    })
}

/// Grows one tree by the exact method over the sampled candidate features `cols` (positions in
/// `data.features`) and the sampled rows (`None`: all training rows), prunes it, and adds its
/// output to the margins of all training rows.
///
/// Each sampled feature has a working column: the tree's sampled rows in ascending order of the
/// feature (the pre-sorted index filtered once per tree, or copied when every row of the matrix
/// is used), gradients read by row, the side of each row of a split in a bit set (an L1-sized
/// random lookup for the partitions). Every node's rows
/// are one run `start..end` of every column, and a split partitions its run stably, so a level
/// scans only the rows of its open nodes, sequentially, and in the order the whole-column scan
/// visited them (the same sums, the same trees to the bit). The per-feature work (partition of
/// the last level's splits, then the scan of this level's nodes) runs on the compute threads;
/// the per-feature bests are reduced in ascending feature order.
#[expect(
    clippy::too_many_lines,
    reason = "one level loop: partition, search and node bookkeeping share its state"
)]
fn grow_exact(
    data: &TrainData<'_>,
    ix: &ExactIndex,
    p: &BoostParams,
    ws: &mut Workspace,
    cols: &[usize],
    sampled: Option<&[bool]>,
    threads: usize,
) -> Tree {
    let n = data.x.n_rows();
    let mut used = vec![false; n];
    let mut unsampled: Vec<u32> = Vec::new();
    let (mut g0, mut n0) = (0.0, 0u32);
    for &r in data.rows {
        if sampled.is_none_or(|s| s[r as usize]) {
            used[r as usize] = true;
            g0 += ws.g[r as usize];
            n0 += 1;
        } else {
            unsampled.push(r);
        }
    }
    let fill_threads = if n * cols.len() >= PAR_MIN_WORK {
        threads
    } else {
        1
    };
    {
        let used = &used;
        par_map(fill_threads, cols, |_, &k| {
            let mut c = lock(&ws.columns[k]);
            let c = &mut c.r;
            let cells = ix.cells(k);
            if n0 as usize == n {
                c.clear();
                c.extend_from_slice(cells);
                return;
            }
            // The filtered cells, their flags ORed over the rows left out (as in `partition`):
            // branch-free, every cell written and the position advanced for used rows only.
            c.clear();
            c.resize(n + 1, 0);
            let (mut w, mut f) = (0, 0u32);
            for &cell in cells {
                let u = used[(cell & ROW) as usize];
                c[w] = cell | f;
                f = (f | (cell & NEW_VALUE)) & u32::from(u).wrapping_sub(1);
                w += usize::from(u);
            }
            c.truncate(w);
        });
    }
    let mut nodes = vec![BNode {
        g: g0,
        n: n0,
        depth: 0,
        split: None,
        left: LEAF,
        right: LEAF,
        start: 0,
        end: n0 as usize,
    }];
    let expandable = |b: &BNode| b.depth < p.max_depth && b.n >= 2;
    let mut level: Vec<u32> = if expandable(&nodes[0]) {
        vec![0]
    } else {
        Vec::new()
    };
    // Runs split by the previous level (partitioned at the start of the next one) and the side
    // of each of their rows.
    let mut splits: Vec<(usize, usize)> = Vec::new();
    let mut left = vec![0u64; n.div_ceil(64)];
    while !level.is_empty() {
        let stats: Vec<(BNode, f64)> = level
            .iter()
            .map(|&i| {
                let b = nodes[i as usize];
                (b, p.score(b.g, f64::from(b.n)))
            })
            .collect();
        let work = (stats.iter().map(|(b, _)| b.n as usize).sum::<usize>()
            + splits.iter().map(|&(s, e)| e - s).sum::<usize>())
            * cols.len();
        let t = if cols.len() > 1 && work >= PAR_MIN_WORK {
            threads
        } else {
            1
        };
        let per_feature: Vec<Vec<Option<Cand>>> = {
            let (splits, left, inv, g) = (&splits, &left, &ws.inv, &ws.g);
            par_map(t, cols, |_, &k| {
                let mut c = lock(&ws.columns[k]);
                let xs = data.x.col(data.features[k]);
                let mut tmp = Vec::new();
                // Each run is partitioned just before its children are scanned, while it is
                // still in cache (runs and nodes are both in ascending position order).
                let mut done = 0;
                let res = stats
                    .iter()
                    .map(|(b, ps)| {
                        let upto = done + splits[done..].partition_point(|sp| sp.0 <= b.start);
                        partition(&mut c, &splits[done..upto], left, &mut tmp);
                        done = upto;
                        scan_exact(&c.r[b.start..b.end], xs, g, b, *ps, p, inv)
                    })
                    .collect();
                partition(&mut c, &splits[done..], left, &mut tmp);
                res
            })
        };
        let mut best: Vec<Option<(usize, Cand)>> = vec![None; level.len()];
        for (j, res) in per_feature.iter().enumerate() {
            for (s, c) in res.iter().enumerate() {
                if let Some(c) = c
                    && better(c.gain, best[s].as_ref().map(|b| &b.1))
                {
                    best[s] = Some((j, *c));
                }
            }
        }
        splits.clear();
        let mut next: Vec<u32> = Vec::new();
        for (s, c) in best.iter().enumerate() {
            let Some((j, c)) = c.filter(|(_, c)| c.gain > KRT_EPS) else {
                continue;
            };
            let id = level[s] as usize;
            let parent = nodes[id];
            let k = cols[j];
            // The split feature's run is sorted: its first nl rows go left.
            {
                let col = lock(&ws.columns[k]);
                let mid = parent.start + c.nl as usize;
                for &c in &col.r[parent.start..mid] {
                    let r = c & ROW;
                    left[(r >> 6) as usize] |= 1 << (r & 63);
                }
                for &c in &col.r[mid..parent.end] {
                    let r = c & ROW;
                    left[(r >> 6) as usize] &= !(1 << (r & 63));
                }
            }
            splits.push((parent.start, parent.end));
            let lid = u32::try_from(nodes.len()).unwrap_or(LEAF);
            let (lnode, rnode) = children(&parent, &c);
            for (child, b) in [(lid, lnode), (lid + 1, rnode)] {
                if expandable(&b) {
                    next.push(child);
                }
            }
            nodes.push(lnode);
            nodes.push(rnode);
            let b = &mut nodes[id];
            b.split = Some(Split {
                feature: data.features[k],
                threshold: c.threshold,
                gain: c.gain,
            });
            b.left = lid;
            b.right = lid + 1;
        }
        level = next;
    }
    let (tree, leaf_of) = finish_tree(p, nodes.clone());
    // The margins, from the runs of the unsplit nodes in one column (the last level's splits
    // partitioned there first).
    let mut col = lock(&ws.columns[cols[0]]);
    partition(&mut col, &splits, &left, &mut Vec::new());
    for (i, b) in nodes.iter().enumerate() {
        if b.left == LEAF {
            let v = tree.nodes[leaf_of[i] as usize].value;
            for &c in &col.r[b.start..b.end] {
                ws.margin[(c & ROW) as usize] += v;
            }
        }
    }
    drop(col);
    add_by_traversal(data, &tree, &unsampled, &mut ws.margin);
    tree
}

/// Adds the output of `tree` to the margins of rows `rows` (rows left out by row sampling,
/// routed as prediction routes them).
fn add_by_traversal(data: &TrainData<'_>, tree: &Tree, rows: &[u32], margin: &mut [f64]) {
    for &r in rows {
        let r = r as usize;
        let mut i = 0;
        loop {
            let nd = &tree.nodes[i];
            if nd.is_leaf() {
                margin[r] += nd.value;
                break;
            }
            i = if data.x.get(r, nd.feature as usize) < nd.threshold {
                nd.left
            } else {
                nd.right
            } as usize;
        }
    }
}

/// One bin of a node's histogram: Σ g and the number of its sampled rows (= Σ h, an integer
/// held exactly in f64), side by side so that one row's update is one two-lane add.
#[derive(Debug, Clone, Copy, Default)]
struct HBin([f64; 2]);

impl HBin {
    /// Adds one row of gradient `g`.
    #[inline]
    fn add(&mut self, g: f64) {
        let [a, b] = &mut self.0;
        *a += g;
        *b += 1.0;
    }

    /// Σ g.
    fn g(self) -> f64 {
        self.0[0]
    }

    /// The row count (exact: below 2^32).
    #[expect(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "a count of rows, an exact non-negative integer below 2^32"
    )]
    fn n(self) -> u32 {
        self.0[1] as u32
    }
}

/// Where a node of the level gets its histogram from.
#[derive(Debug, Clone, Copy)]
enum Source {
    /// Summed over the node's own rows.
    Build,
    /// Its parent's histogram (`kept[parent]`) minus its sibling's (level position `sibling`,
    /// always built directly and in the same batch).
    Subtract { parent: usize, sibling: usize },
}

/// A node of the level being grown by the hist method.
#[derive(Debug, Clone, Copy)]
struct Pending {
    id: u32,
    from: Source,
}

/// Histogram layout of one tree: the sampled features' bins back to back, `off[j]` the first
/// bin of `cols[j]`, `off[cols.len()]` the total; with one-byte bins every feature takes
/// [`U8_SLOTS`] slots (the unused ones stay empty).
struct Layout {
    off: Vec<usize>,
}

impl Layout {
    fn new(ix: &HistIndex, cols: &[usize]) -> Self {
        if matches!(ix.bins, Bins::U8(_)) {
            return Self {
                off: (0..=cols.len()).map(|j| j * U8_SLOTS).collect(),
            };
        }
        let mut off = Vec::with_capacity(cols.len() + 1);
        let mut t = 0;
        off.push(0);
        for &k in cols {
            t += ix.n_bins(k);
            off.push(t);
        }
        Self { off }
    }

    fn total(&self) -> usize {
        self.off.last().copied().unwrap_or(0)
    }
}

/// Adds rows `rows` to the histogram `hist` of the sampled features `cols` (bins of `cols[j]`
/// from `off[j] − off[0]`), in row order: each bin's sum runs over the node's rows in the same
/// order whatever the chunking, so the sums do not depend on the thread count.
fn add_rows<B: Copy>(
    bins: &[B],
    nf: usize,
    rows: &[u32],
    ws: &Workspace,
    cols: &[usize],
    off: &[usize],
    hist: &mut [HBin],
) where
    usize: From<B>,
{
    let base = off[0];
    let local: Vec<(usize, usize)> = cols.iter().zip(off).map(|(&k, &o)| (k, o - base)).collect();
    for &r in rows {
        let r = r as usize;
        let g = ws.g[r];
        let row = &bins[r * nf..(r + 1) * nf];
        for &(k, o) in &local {
            let h = &mut hist[o + usize::from(row[k])];
            h.add(g);
        }
    }
}

/// [`add_rows`] for one-byte bins: every feature's histogram has 256 slots, so a bin number
/// indexes it without a bounds check, and a run of consecutive features (no column sampling)
/// reads the row's bins as one slice. Same order of the sums as [`add_rows`].
fn add_rows_u8(bins: &[u8], nf: usize, rows: &[u32], g: &[f64], cols: &[usize], hist: &mut [HBin]) {
    let (slots, _) = hist.as_chunks_mut::<U8_SLOTS>();
    let Some(&k0) = cols.first() else {
        return;
    };
    let w = cols.len();
    if cols.iter().enumerate().all(|(i, &k)| k == k0 + i) {
        for &r in rows {
            let r = r as usize;
            let gr = g[r];
            let row = &bins[r * nf + k0..r * nf + k0 + w];
            for (h, &bin) in slots.iter_mut().zip(row) {
                h[usize::from(bin)].add(gr);
            }
        }
    } else {
        for &r in rows {
            let r = r as usize;
            let gr = g[r];
            let row = &bins[r * nf..(r + 1) * nf];
            for (h, &k) in slots.iter_mut().zip(cols) {
                h[usize::from(row[k])].add(gr);
            }
        }
    }
}

/// Histogram of rows `rows` over the sampled features `cols[j0..j1]`.
fn build_hist(
    ix: &HistIndex,
    layout: &Layout,
    rows: &[u32],
    ws: &Workspace,
    cols: &[usize],
    (j0, j1): (usize, usize),
) -> Vec<HBin> {
    let off = &layout.off[j0..=j1];
    let mut hist = vec![HBin::default(); off[off.len() - 1] - off[0]];
    match &ix.bins {
        Bins::U8(b) => add_rows_u8(b, ix.n_feat, rows, &ws.g, &cols[j0..j1], &mut hist),
        Bins::U16(b) => add_rows(b, ix.n_feat, rows, ws, &cols[j0..j1], off, &mut hist),
    }
    hist
}

/// Best split of one node over its histogram: per sampled feature (ascending) the boundary after
/// every non-empty bin, θ = that bin's upper cut; features reduced in ascending order.
fn search_hist(
    hist: &[HBin],
    layout: &Layout,
    ix: &HistIndex,
    cols: &[usize],
    node: &BNode,
    p: &BoostParams,
    inv: &[f64],
) -> Option<(usize, Cand)> {
    let parent_score = p.score(node.g, f64::from(node.n));
    let mut best: Option<(usize, Cand)> = None;
    for (j, &k) in cols.iter().enumerate() {
        let h = &hist[layout.off[j]..layout.off[j] + ix.n_bins(k)];
        let cuts = &ix.cuts[k];
        let mut fbest: Option<Cand> = None;
        let mut need = f64::NEG_INFINITY;
        let (mut gl, mut nl) = (0.0, 0u32);
        for (b, bin) in h[..h.len() - 1].iter().enumerate() {
            let nb = bin.n();
            gl += bin.g();
            nl += nb;
            let nr = node.n - nl;
            if nb == 0 || nl == 0 || nr == 0 {
                continue;
            }
            let (hl, hr) = (f64::from(nl), f64::from(nr));
            if hl >= p.min_child_weight && hr >= p.min_child_weight {
                let gain = fast_score(gl, nl, inv, p.reg_alpha)
                    + fast_score(node.g - gl, nr, inv, p.reg_alpha)
                    - parent_score;
                if gain > need {
                    fbest = Some(Cand {
                        gain,
                        threshold: cuts[b],
                        gl,
                        nl,
                    });
                    need = bar(gain);
                }
            }
        }
        if let Some(c) = fbest
            && better(c.gain, best.as_ref().map(|b| &b.1))
        {
            best = Some((j, c));
        }
    }
    best
}

/// Stable partition (x < θ first, each side in ascending row order) of the row runs `jobs`
/// (start, end, feature, θ; ascending and disjoint) of `part`: the splits of one batch, on the
/// compute threads when there are several and enough rows.
fn partition_rows(
    part: &mut [u32],
    jobs: &[(usize, usize, usize, f64)],
    x: &Matrix,
    threads: usize,
) {
    let mut segs: Vec<Mutex<(&mut [u32], usize, f64)>> = Vec::with_capacity(jobs.len());
    let mut rest: &mut [u32] = part;
    let mut at = 0;
    for &(start, end, f, theta) in jobs {
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(start - at);
        let (seg, tail) = tail.split_at_mut(end - start);
        segs.push(Mutex::new((seg, f, theta)));
        rest = tail;
        at = end;
    }
    let work: usize = jobs.iter().map(|j| j.1 - j.0).sum();
    let t = if jobs.len() > 1 && work >= PAR_MIN_WORK {
        threads
    } else {
        1
    };
    par_map(t, &segs, |_, m| {
        let mut guard = m.lock().unwrap_or_else(PoisonError::into_inner);
        let (seg, f, theta) = &mut *guard;
        let col = x.col(*f);
        // Branch-free (the sides are as good as random): both sides are written, the index of
        // the other side stays.
        let mut tmp = vec![0u32; seg.len()];
        let (mut w, mut t) = (0, 0);
        for i in 0..seg.len() {
            let r = seg[i];
            let is_left = col[r as usize] < *theta;
            seg[w] = r;
            tmp[t] = r;
            w += usize::from(is_left);
            t += usize::from(!is_left);
        }
        seg[w..].copy_from_slice(&tmp[..t]);
    });
}

/// Grows one tree by the hist method: level by level over per-node row lists (each node's
/// sampled rows are a contiguous run of `part`, in ascending row order), one histogram per node
/// built from its own rows only, and with `subtract` the larger of two expandable siblings'
/// histogram taken as parent − smaller sibling. Prunes the tree and adds its output to the
/// margins of all training rows.
#[expect(
    clippy::too_many_lines,
    clippy::too_many_arguments,
    reason = "one level loop: batches, histograms, search and partition share its state; the \
              arguments are the tree's inputs, as for `grow_exact`, plus the subtraction switch"
)]
fn grow_hist(
    data: &TrainData<'_>,
    ix: &HistIndex,
    p: &BoostParams,
    ws: &mut Workspace,
    cols: &[usize],
    sampled: Option<&[bool]>,
    threads: usize,
    subtract: bool,
) -> Tree {
    let mut part: Vec<u32> = Vec::with_capacity(data.rows.len());
    let mut unsampled: Vec<u32> = Vec::new();
    let (mut g0, mut n0) = (0.0, 0u32);
    for &r in data.rows {
        if sampled.is_none_or(|s| s[r as usize]) {
            part.push(r);
            g0 += ws.g[r as usize];
            n0 += 1;
        } else {
            unsampled.push(r);
        }
    }
    let layout = Layout::new(ix, cols);
    let node_bytes = layout.total() * std::mem::size_of::<HBin>();
    let per_data = (part.len() * cols.len() * HIST_BYTES_PER_CELL).max(HIST_MIN_BYTES);
    let batch_nodes = (HIST_BATCH_BYTES.min(per_data) / node_bytes.max(1)).max(2);
    let keep_bytes = HIST_KEEP_BYTES.min(per_data);
    let mut nodes = vec![BNode {
        g: g0,
        n: n0,
        depth: 0,
        split: None,
        left: LEAF,
        right: LEAF,
        start: 0,
        end: part.len(),
    }];
    let expandable = |b: &BNode| b.depth < p.max_depth && b.n >= 2;
    let mut level: Vec<Pending> = if expandable(&nodes[0]) {
        vec![Pending {
            id: 0,
            from: Source::Build,
        }]
    } else {
        Vec::new()
    };
    let mut kept: Vec<Vec<HBin>> = Vec::new();
    while !level.is_empty() {
        let mut next: Vec<Pending> = Vec::new();
        let mut next_kept: Vec<Vec<HBin>> = Vec::new();
        let mut kept_bytes = 0;
        let mut i0 = 0;
        while i0 < level.len() {
            let mut i1 = (i0 + batch_nodes).min(level.len());
            // Siblings that share a parent histogram stay in one batch.
            if i1 < level.len()
                && matches!(level[i1].from, Source::Subtract { sibling, .. } if sibling + 1 == i1)
            {
                i1 += 1;
            }
            if i1 < level.len()
                && matches!(level[i1 - 1].from, Source::Subtract { sibling, .. } if sibling == i1)
            {
                i1 += 1;
            }
            let batch = &level[i0..i1];
            // Direct builds, split by feature chunks on big nodes.
            let mut tasks: Vec<(usize, (usize, usize))> = Vec::new();
            let mut work = 0;
            for (i, w) in batch.iter().enumerate() {
                if matches!(w.from, Source::Build) {
                    let rows = nodes[w.id as usize].n as usize;
                    work += rows * cols.len();
                    let chunks = if rows * cols.len() >= HIST_CHUNK_WORK {
                        threads.clamp(1, cols.len().max(1))
                    } else {
                        1
                    };
                    for c in 0..chunks {
                        tasks.push((i, (c * cols.len() / chunks, (c + 1) * cols.len() / chunks)));
                    }
                }
            }
            let t = if work >= PAR_MIN_WORK { threads } else { 1 };
            let built = par_map(t, &tasks, |_, &(i, range)| {
                let b = &nodes[batch[i].id as usize];
                build_hist(ix, &layout, &part[b.start..b.end], ws, cols, range)
            });
            let mut hists: Vec<Vec<HBin>> = vec![Vec::new(); batch.len()];
            for (&(i, _), h) in tasks.iter().zip(built) {
                hists[i].extend(h);
            }
            for (i, w) in batch.iter().enumerate() {
                if let Source::Subtract { parent, sibling } = w.from {
                    let mut h = std::mem::take(&mut kept[parent]);
                    for (a, b) in h.iter_mut().zip(&hists[sibling - i0]) {
                        a.0[0] -= b.0[0];
                        a.0[1] -= b.0[1];
                    }
                    hists[i] = h;
                }
            }
            let t = if batch.len() > 1 && batch.len() * layout.total() >= PAR_MIN_WORK {
                threads
            } else {
                1
            };
            let best = par_map(t, batch, |i, w| {
                search_hist(
                    &hists[i],
                    &layout,
                    ix,
                    cols,
                    &nodes[w.id as usize],
                    p,
                    &ws.inv,
                )
            });
            let mut jobs: Vec<(usize, usize, usize, f64)> = Vec::new();
            for ((w, c), hist) in batch.iter().zip(best).zip(hists) {
                let Some((j, c)) = c.filter(|(_, c)| c.gain > KRT_EPS) else {
                    continue;
                };
                let id = w.id as usize;
                let parent = nodes[id];
                let k = cols[j];
                let feature = data.features[k];
                // Stable partition of the node's rows: x < θ first.
                jobs.push((parent.start, parent.end, feature, c.threshold));
                let left = u32::try_from(nodes.len()).unwrap_or(LEAF);
                let (lnode, rnode) = children(&parent, &c);
                let (le, re) = (expandable(&lnode), expandable(&rnode));
                nodes.push(lnode);
                nodes.push(rnode);
                let b = &mut nodes[id];
                b.split = Some(Split {
                    feature,
                    threshold: c.threshold,
                    gain: c.gain,
                });
                b.left = left;
                b.right = left + 1;
                // Subtraction pays when the larger child has more rows than its histogram has
                // bins (summing it directly would cost more than subtracting); smaller nodes are
                // summed directly and keep no parent histogram.
                let pays = lnode.n.max(rnode.n) as usize * cols.len() > layout.total();
                match (le, re) {
                    (true, true) if subtract && pays && kept_bytes + node_bytes <= keep_bytes => {
                        kept_bytes += node_bytes;
                        // The smaller child is summed, the larger one subtracted.
                        let small_left = lnode.n <= rnode.n;
                        let s = next.len() + usize::from(!small_left);
                        let from = Source::Subtract {
                            parent: next_kept.len(),
                            sibling: s,
                        };
                        next_kept.push(hist);
                        for (child, is_small) in [(left, small_left), (left + 1, !small_left)] {
                            next.push(Pending {
                                id: child,
                                from: if is_small { Source::Build } else { from },
                            });
                        }
                    }
                    _ => {
                        for (child, e) in [(left, le), (left + 1, re)] {
                            if e {
                                next.push(Pending {
                                    id: child,
                                    from: Source::Build,
                                });
                            }
                        }
                    }
                }
            }
            partition_rows(&mut part, &jobs, data.x, threads);
            i0 = i1;
        }
        level = next;
        kept = next_kept;
    }
    let (tree, leaf_of) = finish_tree(p, nodes.clone());
    for (i, b) in nodes.iter().enumerate() {
        if b.left == LEAF {
            let v = tree.nodes[leaf_of[i] as usize].value;
            for &r in &part[b.start..b.end] {
                ws.margin[r as usize] += v;
            }
        }
    }
    add_by_traversal(data, &tree, &unsampled, &mut ws.margin);
    tree
}

/// Leaf values, γ pruning and compaction to a breadth-first [`Tree`]; with it, for every node
/// under construction the index of the leaf its rows end in (meaningful for unsplit nodes).
fn finish_tree(p: &BoostParams, mut nodes: Vec<BNode>) -> (Tree, Vec<u32>) {
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
    let leaf_of = rep.iter().map(|&i| new_id[i as usize]).collect();
    (Tree { nodes: out }, leaf_of)
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

    /// `n` rows of `d` uniform features and a nonlinear target; with `dyadic` the targets are
    /// multiples of 1/8 (every gradient sum of a first tree with base 0 is exact in f64).
    fn continuous(n: usize, d: usize, seed: u64, dyadic: bool) -> (Matrix, Vec<f64>) {
        let mut r = rng::stream(seed, 3);
        let rows: Vec<Vec<f64>> = (0..n)
            .map(|_| (0..d).map(|_| rng::uniform(&mut r)).collect())
            .collect();
        let y = rows
            .iter()
            .map(|v| {
                let t =
                    (6.0 * v[0]).sin() + 2.0 * v[1] * v[2] - v[d - 1] + 0.2 * rng::uniform(&mut r);
                if dyadic { (t * 8.0).round() / 8.0 } else { t }
            })
            .collect();
        (Matrix::from_rows(rows, d), y)
    }

    fn fit_with(x: &Matrix, y: &[f64], p: &BoostParams, threads: usize, subtract: bool) -> Boosted {
        let rows = super::super::data::all_rows(x.n_rows());
        let features: Vec<usize> = (0..x.n_cols()).collect();
        let index = SplitIndex::build(p.method, x, &rows, &features, threads);
        let data = TrainData {
            x,
            y,
            rows: &rows,
            features: &features,
            index: &index,
        };
        boost_with(&data, p, &Budget::unlimited(), threads, subtract)
    }

    /// Bit patterns of every node field of every tree.
    fn bits(b: &Boosted) -> Vec<(u32, u32, u32, u64, u64, u64, u64)> {
        b.trees
            .iter()
            .flat_map(|t| t.nodes.iter())
            .map(|n| {
                (
                    n.left,
                    n.right,
                    n.feature,
                    n.threshold.to_bits(),
                    n.value.to_bits(),
                    n.cover.to_bits(),
                    n.loss_change.to_bits(),
                )
            })
            .collect()
    }

    /// Issue 27: with exactly representable gradients (dyadic targets, base 0, first tree) the
    /// histogram of a sibling taken as parent − smaller child equals its direct sum bit for bit,
    /// so the tree is the same to the last bit (u8 bins and u16 bins).
    #[test]
    fn hist_subtraction_is_exact_on_representable_gradients() {
        let (x, y) = continuous(3000, 6, 21, true);
        for max_bin in [32, 700] {
            let p = BoostParams {
                method: Method::Hist { max_bin },
                base_score: Some(0.0),
                learning_rate: 0.5,
                reg_lambda: 0.0,
                ..BoostParams::xgboost(1, 6)
            };
            let sub = fit_with(&x, &y, &p, 2, true);
            let direct = fit_with(&x, &y, &p, 2, false);
            assert!(sub.trees[0].n_splits() > 20, "{}", sub.trees[0].n_splits());
            assert_eq!(bits(&sub), bits(&direct), "max_bin {max_bin}");
        }
    }

    /// Issue 27: over many rounds (inexact gradients, row and column sampling) the subtraction
    /// changes the trees by round-off only: same structure and thresholds, values and loss
    /// changes within a few ulps of the scale, predictions within 1e-12.
    #[test]
    fn hist_subtraction_agrees_to_round_off() {
        let (x, y) = continuous(4000, 8, 5, false);
        for max_bin in [64, 1000] {
            let p = BoostParams {
                method: Method::Hist { max_bin },
                colsample_bytree: 0.8,
                subsample: 0.9,
                seed: 4,
                ..BoostParams::xgboost(30, 6)
            };
            let sub = fit_with(&x, &y, &p, 2, true);
            let direct = fit_with(&x, &y, &p, 2, false);
            assert_eq!(sub.trees.len(), direct.trees.len());
            for (a, b) in sub.trees.iter().zip(&direct.trees) {
                assert_eq!(a.nodes.len(), b.nodes.len());
                for (u, v) in a.nodes.iter().zip(&b.nodes) {
                    assert_eq!((u.left, u.right, u.feature), (v.left, v.right, v.feature));
                    assert_eq!(u.threshold.to_bits(), v.threshold.to_bits());
                    assert_eq!(u.cover.to_bits(), v.cover.to_bits());
                    assert!(
                        (u.value - v.value).abs() <= 1e-13,
                        "{} {}",
                        u.value,
                        v.value
                    );
                    let tol = 1e-11 * u.loss_change.abs().max(1.0);
                    assert!((u.loss_change - v.loss_change).abs() <= tol);
                }
            }
            let worst = (0..x.n_rows())
                .map(|r| {
                    let row = x.row(r);
                    let f = |b: &Boosted| b.trees.iter().map(|t| t.predict(&row)).sum::<f64>();
                    (f(&sub) - f(&direct)).abs()
                })
                .fold(0.0f64, f64::max);
            assert!(worst <= 1e-12, "max_bin {max_bin}: {worst:e}");
        }
    }

    /// The hist trees are bit-identical for 1 and 2 threads (feature chunks of one histogram,
    /// nodes of one level searched in parallel), with the work above the parallel thresholds.
    #[test]
    fn hist_is_bit_identical_across_thread_counts() {
        let (x, y) = continuous(6000, 24, 8, false);
        let p = BoostParams {
            method: Method::Hist { max_bin: 256 },
            colsample_bytree: 0.7,
            subsample: 0.8,
            seed: 9,
            ..BoostParams::xgboost(8, 6)
        };
        let one = fit_with(&x, &y, &p, 1, true);
        let two = fit_with(&x, &y, &p, 2, true);
        assert!(one.trees.iter().all(|t| t.n_splits() > 10));
        assert_eq!(bits(&one), bits(&two));
    }

    #[test]
    fn cut_points_quantiles() {
        let v: Vec<f64> = (0..1000).map(f64::from).collect();
        let c = cut_points(v, 4);
        assert_eq!(c, vec![250.0, 500.0, 750.0]);
        assert_eq!(cut_points(vec![2.0, 1.0, 2.0, 3.0], 256), vec![2.0, 3.0]);
    }
}
