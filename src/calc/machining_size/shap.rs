//! Exact Shapley values of tree ensembles (spec §4).
//!
//! * [`ShapForest::path_dependent`]: polynomial TreeSHAP (Lundberg, Erion, Lee, "Consistent
//!   individualized feature attribution for tree ensembles", 2018, Algorithm 2), the value of a
//!   coalition being the cover-weighted conditional expectation; equal to XGBoost's
//!   `pred_contribs` and shap's TreeExplainer without background data. The recursion follows
//!   shap's `tree_shap_recursive` (one path buffer preallocated for all levels, the parent's path
//!   copied into the next slot) over a [`ShapForest`] (nodes in depth-first pre-order with the
//!   cover fractions divided out once per request). The leaf step uses that one-fractions are 0
//!   or 1 (`leaf_step`): for o = 0 the unwound sum times (o − z) is the same for all such
//!   elements and needs no division; the o = 1 sums run side by side.
//! * [`ShapForest::interactions`]: SHAP interaction values by conditioning TreeSHAP on each
//!   feature a tree uses ("on"/"off"), as XGBoost's `pred_interactions` and shap do (spec §4.3).
//! * [`InterventionalTables`]: interventional TreeSHAP against a background set (spec §4.2), the
//!   background rows grouped per leaf by the path features on which they leave the path, so a row
//!   costs one walk per tree whatever |B|; the pair recursion of §4.2 remains for trees whose
//!   table would be too large.
//! * [`path_dependent`], [`interactions`], [`interventional`]: the same for one row, laying the
//!   model out on each call.
//!
//! Hazards (spec §8.9): a child with zero cover gives a (0, 0) path element whose later unwinding
//! would divide by zero; such a subtree contributes exactly 0 and is skipped. Cover fractions are
//! clamped to [0, 1] and are 0 under a node of zero cover ([`cover_fraction`]). Local accuracy
//! holds for any such fractions because φ₀ uses the same ones.

use super::model::{LEAF, MAX_TREE_DEPTH, Model, Tree, cover_fraction};
use crate::numerics::Budget;

/// One element of the unique path: feature (−1 for the root's dummy), the fraction of zero paths
/// (x's feature not in the coalition) and of one paths (in the coalition) flowing through it, and
/// the permutation weight.
#[derive(Debug, Clone, Copy, Default)]
struct PathElem {
    feature: i64,
    zero: f64,
    one: f64,
    w: f64,
}

/// Reciprocals 1/k for k ≤ [`MAX_TREE_DEPTH`] + 2 (1/0 stored as 0, never used): the path
/// algebra divides by small integers in its inner loops, and a multiplication is several times
/// cheaper than a division. A path holds at most depth + 1 elements, so indices stay in range.
const RECIP: [f64; MAX_TREE_DEPTH + 3] = {
    let mut r = [0.0; MAX_TREE_DEPTH + 3];
    let mut k = 1;
    while k < MAX_TREE_DEPTH + 3 {
        r[k] = 1.0 / k as f64;
        k += 1;
    }
    r
};

/// Grows the path by one element (the spec's EXTEND).
fn extend(path: &mut [PathElem], ud: usize, zero: f64, one: f64, feature: i64) {
    path[ud] = PathElem {
        feature,
        zero,
        one,
        w: if ud == 0 { 1.0 } else { 0.0 },
    };
    let inv_l1 = RECIP[ud + 1];
    let (one_l, zero_l) = (one * inv_l1, zero * inv_l1);
    for i in (0..ud).rev() {
        path[i + 1].w += one_l * path[i].w * (i + 1) as f64;
        path[i].w = zero_l * path[i].w * (ud - i) as f64;
    }
}

/// Removes element `idx` from the path, undoing its EXTEND (the spec's UNWIND).
fn unwind(path: &mut [PathElem], ud: usize, idx: usize) {
    let (one, zero) = (path[idx].one, path[idx].zero);
    let l1 = (ud + 1) as f64;
    let zero_l = zero * RECIP[ud + 1];
    let mut next = path[ud].w;
    // l1/one and l1/zero overflow for subnormal fractions (hostile covers): then divide as the
    // published algorithm does, which keeps 0·∞ out.
    if one != 0.0 {
        let a = l1 / one;
        for i in (0..ud).rev() {
            let t = path[i].w;
            path[i].w = if a.is_finite() {
                next * a * RECIP[i + 1]
            } else {
                next * l1 / ((i + 1) as f64 * one)
            };
            next = t - path[i].w * zero_l * (ud - i) as f64;
        }
    } else {
        let a = l1 / zero;
        for i in (0..ud).rev() {
            path[i].w = if a.is_finite() {
                path[i].w * a * RECIP[ud - i]
            } else {
                path[i].w * l1 / (zero * (ud - i) as f64)
            };
        }
    }
    for i in idx..ud {
        path[i].feature = path[i + 1].feature;
        path[i].zero = path[i + 1].zero;
        path[i].one = path[i + 1].one;
    }
}

/// Total permutation weight of the path with element `idx` removed (the spec's UNWOUNDSUM).
fn unwound_sum(path: &[PathElem], ud: usize, idx: usize) -> f64 {
    let (one, zero) = (path[idx].one, path[idx].zero);
    let l1 = (ud + 1) as f64;
    let mut total = 0.0;
    // As in `unwind`: the multiplied form where l1/one (l1/zero) is finite.
    if one != 0.0 {
        let a = l1 / one;
        let zero_l = zero * RECIP[ud + 1];
        let mut next = path[ud].w;
        for i in (0..ud).rev() {
            let t = if a.is_finite() {
                next * a * RECIP[i + 1]
            } else {
                next * l1 / ((i + 1) as f64 * one)
            };
            total += t;
            next = path[i].w - t * zero_l * (ud - i) as f64;
        }
    } else if zero != 0.0 {
        let a = l1 / zero;
        for i in (0..ud).rev() {
            total += if a.is_finite() {
                path[i].w * a * RECIP[ud - i]
            } else {
                path[i].w * l1 / (zero * (ud - i) as f64)
            };
        }
    }
    total
}

/// The leaf step of Algorithm 2: `φ[d_i] += UNWOUNDSUM(m, i)·(o_i − z_i)·scale` for every
/// element i = 1..=ud of the path.
///
/// In path-dependent TreeSHAP the one-fraction o of an element is 0 (x's child not taken) or 1
/// (taken), which makes two shortcuts exact:
/// * o = 0: UNWOUNDSUM = Σ_j w_j·(l+1)/(z·(l−j)), and times (0 − z) the zero-fraction cancels:
///   every such element receives the same −(l+1)·Σ_j w_j/(l−j), computed once per leaf, with no
///   division (and no overflow of (l+1)/z for tiny z);
/// * o = 1: the unwinding recursion divides by o = 1; the sums of all such elements are run
///   together, [`LANES`] at a time, sharing the loads of w_j and the factors of step j.
///
/// Any other one-fraction (never produced by the recursion) takes the general [`unwound_sum`].
#[expect(
    clippy::float_cmp,
    reason = "one-fractions are exactly 0 or 1 by construction; the test picks the exact shortcut"
)]
fn leaf_step(path: &[PathElem], ud: usize, scale: f64, phi: &mut [f64]) {
    if scale == 0.0 {
        return;
    }
    let mut cold: Option<f64> = None;
    let mut lanes = HotLanes::default();
    for i in 1..=ud {
        let e = path[i];
        let Ok(f) = usize::try_from(e.feature) else {
            continue;
        };
        if e.one == 0.0 {
            if e.zero != 0.0 {
                let s = *cold.get_or_insert_with(|| {
                    let sum: f64 = (0..ud).map(|j| path[j].w * RECIP[ud - j]).sum();
                    (ud + 1) as f64 * sum
                });
                phi[f] -= s * scale;
            }
        } else if e.one == 1.0 {
            lanes.push(f, e.zero);
            if lanes.n == LANES {
                lanes.flush(path, ud, scale, phi);
            }
        } else {
            phi[f] += unwound_sum(path, ud, i) * (e.one - e.zero) * scale;
        }
    }
    if lanes.n > 0 {
        lanes.flush(path, ud, scale, phi);
    }
}

/// Elements with one-fraction 1 whose unwound sums are computed together.
const LANES: usize = 4;

/// Pending o = 1 elements of [`leaf_step`]: feature and zero-fraction.
#[derive(Default)]
struct HotLanes {
    n: usize,
    feature: [usize; LANES],
    zero: [f64; LANES],
}

impl HotLanes {
    fn push(&mut self, feature: usize, zero: f64) {
        self.feature[self.n] = feature;
        self.zero[self.n] = zero;
        self.n += 1;
    }

    /// UNWOUNDSUM with o = 1 for every pending element (unused lanes compute with z = 0 and are
    /// dropped), then `φ[d] += sum·(1 − z)·scale`.
    fn flush(&mut self, path: &[PathElem], ud: usize, scale: f64, phi: &mut [f64]) {
        let l1 = (ud + 1) as f64;
        let inv_l1 = RECIP[ud + 1];
        let mut next = [path[ud].w; LANES];
        let mut total = [0.0; LANES];
        for j in (0..ud).rev() {
            let c = l1 * RECIP[j + 1];
            let dz = (ud - j) as f64 * inv_l1;
            let wj = path[j].w;
            for k in 0..LANES {
                let t = next[k] * c;
                total[k] += t;
                next[k] = wj - t * self.zero[k] * dz;
            }
        }
        for k in 0..self.n {
            phi[self.feature[k]] += total[k] * (1.0 - self.zero[k]) * scale;
        }
        self.n = 0;
    }
}

/// Conditioning of TreeSHAP on one feature, for interaction values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Condition {
    /// Plain TreeSHAP.
    None,
    /// The feature is in every coalition (follow x's child, do not extend the path).
    On(u32),
    /// The feature is in no coalition (both children by cover, do not extend the path).
    Off(u32),
}

impl Condition {
    fn feature(self) -> Option<u32> {
        match self {
            Self::None => None,
            Self::On(f) | Self::Off(f) => Some(f),
        }
    }
}

/// Reusable path buffer for trees up to a given depth.
#[derive(Debug, Clone, Default)]
pub struct PathBuffer {
    buf: Vec<PathElem>,
}

impl PathBuffer {
    /// A buffer for trees of depth ≤ `depth`.
    #[must_use]
    pub fn for_depth(depth: usize) -> Self {
        Self {
            buf: vec![PathElem::default(); (depth + 1) * (depth + 2) / 2 + 2 * depth + 4],
        }
    }
}

/// One node of a [`ShapForest`]: everything the recursion reads at a node in one place (about
/// one cache line), the cover fractions of both children divided out once.
#[derive(Debug, Clone, Copy)]
struct FlatNode {
    /// Split threshold (`x < θ` → left).
    threshold: f64,
    /// Leaf value (leaves only).
    value: f64,
    /// [`cover_fraction`] of the left and of the right child.
    frac: [f64; 2],
    /// Children (absolute indices into [`ShapForest::nodes`]); `left == LEAF` at leaves.
    left: u32,
    right: u32,
    feature: u32,
}

/// A model laid out for TreeSHAP: the nodes of all trees in one array, each tree in depth-first
/// pre-order (a left child right after its parent, each subtree contiguous), with the cover
/// fractions precomputed. Built once per request in O(nodes); the results are those of the
/// [`Model`] it was built from.
#[derive(Debug, Clone)]
pub struct ShapForest {
    nodes: Vec<FlatNode>,
    /// Root index of each tree in `nodes`, and the features it tests (ascending).
    trees: Vec<(u32, Vec<u32>)>,
}

impl ShapForest {
    /// The layout of `model`'s trees.
    #[must_use]
    pub fn new(model: &Model) -> Self {
        let total: usize = model.trees.iter().map(|t| t.nodes.len()).sum();
        let mut nodes = Vec::with_capacity(total);
        let mut trees = Vec::with_capacity(model.trees.len());
        let mut stack = Vec::new();
        for t in &model.trees {
            let root = nodes.len();
            // Pre-order: the new index of a node is known when it is visited; a parent's child
            // links are patched when each child is placed.
            stack.push((0usize, None::<(usize, usize)>));
            while let Some((i, parent)) = stack.pop() {
                let k = nodes.len();
                if let Some((p, side)) = parent {
                    let pn: &mut FlatNode = &mut nodes[p];
                    if side == 0 {
                        pn.left = k as u32;
                    } else {
                        pn.right = k as u32;
                    }
                }
                let n = &t.nodes[i];
                let leaf = n.is_leaf();
                let frac = if leaf {
                    [0.0; 2]
                } else {
                    [
                        cover_fraction(t.nodes[n.left as usize].cover, n.cover),
                        cover_fraction(t.nodes[n.right as usize].cover, n.cover),
                    ]
                };
                nodes.push(FlatNode {
                    threshold: n.threshold,
                    value: n.value,
                    frac,
                    left: LEAF,
                    right: LEAF,
                    feature: n.feature,
                });
                if !leaf {
                    stack.push((n.right as usize, Some((k, 1))));
                    stack.push((n.left as usize, Some((k, 0))));
                }
            }
            trees.push((root as u32, t.used_features()));
        }
        Self { nodes, trees }
    }
}

struct Walk<'a> {
    nodes: &'a [FlatNode],
    x: &'a [f64],
    cond: Condition,
}

/// One node of the recursion: `ud` is the index the new path element takes, `parent` the offset
/// of the parent's path in `buf`, `(pz, po, pf)` the element to add, `cf` the share of the
/// conditioning that reaches this node.
#[expect(
    clippy::too_many_arguments,
    reason = "the recursion's state, as in the published algorithm; bundling it would hide which \
              parts each level changes"
)]
fn recurse(
    w: &Walk<'_>,
    phi: &mut [f64],
    buf: &mut [PathElem],
    node: usize,
    ud: usize,
    parent: usize,
    (pz, po, pf): (f64, f64, i64),
    cf: f64,
) {
    if cf == 0.0 {
        return;
    }
    let start = parent + ud + 1;
    buf.copy_within(parent..=parent + ud, start);
    let cond_f = w.cond.feature().map(i64::from);
    if cond_f != Some(pf) {
        extend(&mut buf[start..], ud, pz, po, pf);
    }
    let n = &w.nodes[node];
    if n.left == LEAF {
        leaf_step(&buf[start..=start + ud], ud, n.value * cf, phi);
        return;
    }
    let f = n.feature;
    let (hot, cold, hz, cz) = if w.x[f as usize] < n.threshold {
        (n.left, n.right, n.frac[0], n.frac[1])
    } else {
        (n.right, n.left, n.frac[1], n.frac[0])
    };
    let (mut iz, mut io) = (1.0, 1.0);
    let mut next = ud + 1;
    let fi = i64::from(f);
    if let Some(k) = (1..=ud).find(|&k| buf[start + k].feature == fi) {
        iz = buf[start + k].zero;
        io = buf[start + k].one;
        unwind(&mut buf[start..], ud, k);
        next -= 1;
    }
    let (mut hcf, mut ccf) = (cf, cf);
    match w.cond {
        Condition::On(c) if c == f => {
            ccf = 0.0;
            next -= 1;
        }
        Condition::Off(c) if c == f => {
            hcf *= hz;
            ccf *= cz;
            next -= 1;
        }
        _ => {}
    }
    // A (0, 0) element contributes exactly 0 and cannot be unwound: skip it.
    if hz * iz != 0.0 || io != 0.0 {
        recurse(
            w,
            phi,
            buf,
            hot as usize,
            next,
            start,
            (hz * iz, io, fi),
            hcf,
        );
    }
    if cz * iz != 0.0 {
        recurse(
            w,
            phi,
            buf,
            cold as usize,
            next,
            start,
            (cz * iz, 0.0, fi),
            ccf,
        );
    }
}

impl ShapForest {
    fn tree_shap(
        &self,
        root: u32,
        x: &[f64],
        cond: Condition,
        phi: &mut [f64],
        buf: &mut PathBuffer,
    ) {
        let w = Walk {
            nodes: &self.nodes,
            x,
            cond,
        };
        recurse(
            &w,
            phi,
            &mut buf.buf,
            root as usize,
            0,
            0,
            (1.0, 1.0, -1),
            1.0,
        );
    }

    /// Path-dependent SHAP values at the prepared row `x` ([`Model::prepare_row`]): adds φ_i to
    /// `phi[i]` (length `n_features`). φ₀ is [`Model::expected_value`].
    pub fn path_dependent(&self, x: &[f64], phi: &mut [f64], buf: &mut PathBuffer) {
        for &(root, _) in &self.trees {
            self.tree_shap(root, x, Condition::None, phi, buf);
        }
    }

    /// SHAP interaction values Φ (row-major `d × d`, added to `out`) and the SHAP values φ
    /// (added to `phi`) at the prepared row `x`: Φ_ij = (φ_i^{j on} − φ_i^{j off})/2 for i ≠ j,
    /// Φ_ii = φ_i − Σ_{j≠i} Φ_ij. Each tree is conditioned only on the features it uses (for
    /// the others "on" and "off" coincide). `scratch` needs two vectors of length `d`.
    pub fn interactions(
        &self,
        x: &[f64],
        phi: &mut [f64],
        out: &mut [f64],
        buf: &mut PathBuffer,
        scratch: &mut [Vec<f64>; 2],
    ) {
        let d = phi.len();
        for (root, used) in &self.trees {
            self.tree_shap(*root, x, Condition::None, phi, buf);
            for &j in used {
                let [on, off] = scratch;
                on.iter_mut().for_each(|v| *v = 0.0);
                off.iter_mut().for_each(|v| *v = 0.0);
                self.tree_shap(*root, x, Condition::On(j), on, buf);
                self.tree_shap(*root, x, Condition::Off(j), off, buf);
                let j = j as usize;
                for i in 0..d {
                    if i != j {
                        out[i * d + j] += (on[i] - off[i]) / 2.0;
                    }
                }
            }
        }
        for i in 0..d {
            let off: f64 = (0..d).filter(|&j| j != i).map(|j| out[i * d + j]).sum();
            out[i * d + i] = phi[i] - off;
        }
    }
}

/// Path-dependent SHAP values of `model` at the prepared row `x` ([`Model::prepare_row`]): adds
/// φ_i to `phi[i]` (length `n_features`). φ₀ is [`Model::expected_value`].
///
/// Lays the model out anew on every call: for many rows build one [`ShapForest`] and call
/// [`ShapForest::path_dependent`].
pub fn path_dependent(model: &Model, x: &[f64], phi: &mut [f64], buf: &mut PathBuffer) {
    ShapForest::new(model).path_dependent(x, phi, buf);
}

/// SHAP interaction values of `model` at the prepared row `x`; see
/// [`ShapForest::interactions`] (which this calls after laying the model out).
pub fn interactions(
    model: &Model,
    x: &[f64],
    phi: &mut [f64],
    out: &mut [f64],
    buf: &mut PathBuffer,
    scratch: &mut [Vec<f64>; 2],
) {
    ShapForest::new(model).interactions(x, phi, out, buf, scratch);
}

/// Weights of interventional TreeSHAP: `pos[u][w]` = (u−1)!·w!/(u+w)!, `neg[u][w]` =
/// u!·(w−1)!/(u+w)!, for u, w ≤ the deepest path.
#[derive(Debug, Clone)]
pub struct InterventionalWeights {
    n: usize,
    pos: Vec<f64>,
    neg: Vec<f64>,
}

impl InterventionalWeights {
    /// The weights for paths of at most `depth` splits.
    #[must_use]
    pub fn new(depth: usize) -> Self {
        let n = depth + 1;
        // ln k! by summation: exact enough (relative 1e-15) and never overflows.
        let mut lf = vec![0.0f64; 2 * n + 1];
        for k in 1..lf.len() {
            lf[k] = lf[k - 1] + (k as f64).ln();
        }
        let mut pos = vec![0.0; n * n];
        let mut neg = vec![0.0; n * n];
        for u in 0..n {
            for w in 0..n {
                if u + w == 0 {
                    continue;
                }
                if u > 0 {
                    pos[u * n + w] = (lf[u - 1] + lf[w] - lf[u + w]).exp();
                }
                if w > 0 {
                    neg[u * n + w] = (lf[u] + lf[w - 1] - lf[u + w]).exp();
                }
            }
        }
        Self { n, pos, neg }
    }
}

/// Feature sets of one (x, r) descent: features routed by x (`u`) and by r (`v`).
struct Sets {
    u: Vec<u32>,
    v: Vec<u32>,
}

fn interv_recurse(
    tree: &Tree,
    node: usize,
    x: &[f64],
    r: &[f64],
    sets: &mut Sets,
    wt: &InterventionalWeights,
    phi: &mut [f64],
) {
    let n = &tree.nodes[node];
    if n.is_leaf() {
        let (u, w) = (sets.u.len(), sets.v.len());
        if u > 0 {
            let a = n.value * wt.pos[u * wt.n + w];
            for &i in &sets.u {
                phi[i as usize] += a;
            }
        }
        if w > 0 {
            let b = n.value * wt.neg[u * wt.n + w];
            for &j in &sets.v {
                phi[j as usize] -= b;
            }
        }
        return;
    }
    let f = n.feature;
    let xl = x[f as usize] < n.threshold;
    let rl = r[f as usize] < n.threshold;
    let child = |left: bool| if left { n.left } else { n.right } as usize;
    if xl == rl || sets.u.contains(&f) {
        interv_recurse(tree, child(xl), x, r, sets, wt, phi);
    } else if sets.v.contains(&f) {
        interv_recurse(tree, child(rl), x, r, sets, wt, phi);
    } else {
        sets.u.push(f);
        interv_recurse(tree, child(xl), x, r, sets, wt, phi);
        sets.u.pop();
        sets.v.push(f);
        interv_recurse(tree, child(rl), x, r, sets, wt, phi);
        sets.v.pop();
    }
}

/// Interventional SHAP values of `model` at the prepared row `x` against the prepared
/// background rows: adds φ_i (the mean over the background) to `phi`. φ₀ is the mean prediction
/// over the background ([`Model::predict_prepared`]).
///
/// Builds the [`InterventionalTables`] of the background on every call: for many rows build them
/// once and call [`InterventionalTables::shap`].
pub fn interventional(
    model: &Model,
    x: &[f64],
    background: &[Vec<f64>],
    wt: &InterventionalWeights,
    phi: &mut [f64],
) {
    if let Some(t) = InterventionalTables::new(model, background, wt, &Budget::unlimited()) {
        t.shap(x, phi);
    }
}

/// The pair recursion of spec §4.2 for one tree: every (x, r) descent on its own.
fn interventional_pairs(
    tree: &Tree,
    x: &[f64],
    background: &[Vec<f64>],
    wt: &InterventionalWeights,
    acc: &mut [f64],
) {
    let mut sets = Sets {
        u: Vec::with_capacity(wt.n),
        v: Vec::with_capacity(wt.n),
    };
    for r in background {
        interv_recurse(tree, 0, x, r, &mut sets, wt, acc);
    }
}

/// Largest Σ over a tree's leaves of 2^(distinct features on the leaf's path) for which the tree
/// gets a table (the dense counting array of [`TreeTable::build`]); deeper trees keep the pair
/// recursion. Depth-8 trees fit.
const TABLE_MAX_DENSE: usize = 1 << 16;

/// Most table entries over all trees of one background (16 bytes each: 32 MB); trees beyond it
/// keep the pair recursion.
const TABLE_MAX_ENTRIES: usize = 1 << 21;

/// Interventional TreeSHAP with the background shared (spec §4.2, same values).
///
/// For a leaf L and a feature f tested on its path, x "leaves" the path at f if it takes the
/// other child at some node of f on the path; so does a background row r. The pair recursion of
/// §4.2 reaches L exactly when no feature is left by both, and then U (features routed by x) is
/// the set r leaves and V (routed by r) the set x leaves. So the contribution of r at L depends
/// only on r's mask D_r of left features, bits numbered by the features' first appearance on the
/// path. The tables hold, per leaf, each distinct D_r with its number of background rows
/// (built once per background in O(|B| · nodes) by one descent per tree carrying the masks of
/// all background rows); explaining a row walks each tree once for its
/// masks D_x and adds, per leaf entry with D_x ∩ D_r = ∅, v·n·(|U|−1)!|V|!/(|U|+|V|)! to every
/// feature of U and subtracts v·n·|U|!(|V|−1)!/(|U|+|V|)! from every feature of V: per row
/// O(nodes + Σ_L entries·depth) instead of O(|B| · pairs' nodes). Trees whose table would be too
/// large (`TABLE_MAX_DENSE`, `TABLE_MAX_ENTRIES`) keep the pair recursion.
#[derive(Debug)]
pub struct InterventionalTables<'a> {
    model: &'a Model,
    background: &'a [Vec<f64>],
    wt: &'a InterventionalWeights,
    /// Per tree: its table, or `None` for the pair recursion.
    trees: Vec<Option<TreeTable>>,
}

/// The table of one tree.
#[derive(Debug)]
struct TreeTable {
    /// Per internal node: the bit of its feature among the distinct features of its root path.
    bit: Vec<u8>,
    /// Per leaf node: its index into `leaves`.
    leaf: Vec<u32>,
    leaves: Vec<LeafTable>,
}

/// One leaf: its value, the features of its path by bit, and (D_r, count) entries.
#[derive(Debug)]
struct LeafTable {
    value: f64,
    features: Vec<u32>,
    entries: Vec<(u64, f64)>,
}

impl TreeTable {
    /// Bits of every node and the path features of every leaf; `None` when the dense counting
    /// array would exceed [`TABLE_MAX_DENSE`].
    fn layout(tree: &Tree) -> Option<(Self, Vec<usize>)> {
        let nn = tree.nodes.len();
        let mut bit = vec![0u8; nn];
        let mut leaf = vec![u32::MAX; nn];
        let mut leaves = Vec::new();
        let mut dense = Vec::new();
        let mut dense_total = 0usize;
        // (node, the distinct features of its path so far).
        let mut stack: Vec<(usize, Vec<u32>)> = vec![(0, Vec::new())];
        while let Some((i, mut feats)) = stack.pop() {
            let n = &tree.nodes[i];
            if n.is_leaf() {
                let width = 1usize.checked_shl(feats.len() as u32)?;
                dense_total = dense_total.checked_add(width)?;
                if dense_total > TABLE_MAX_DENSE {
                    return None;
                }
                leaf[i] = leaves.len() as u32;
                dense.push(width);
                leaves.push(LeafTable {
                    value: n.value,
                    features: feats,
                    entries: Vec::new(),
                });
                continue;
            }
            let k = match feats.iter().position(|&f| f == n.feature) {
                Some(k) => k,
                None => {
                    feats.push(n.feature);
                    feats.len() - 1
                }
            };
            // Distinct features on a path ≤ depth ≤ MAX_TREE_DEPTH = 64: the bit fits a u64.
            bit[i] = u8::try_from(k).ok().filter(|&b| b < 64)?;
            stack.push((n.right as usize, feats.clone()));
            stack.push((n.left as usize, feats));
        }
        Some((Self { bit, leaf, leaves }, dense))
    }

    /// Calls `at_leaf(leaf, mask)` for every leaf with the mask of the path features on which
    /// row `z` leaves the path.
    fn masks(
        &self,
        tree: &Tree,
        z: &[f64],
        stack: &mut Vec<(u32, u64)>,
        mut at_leaf: impl FnMut(usize, u64),
    ) {
        stack.clear();
        stack.push((0, 0));
        while let Some((i, m)) = stack.pop() {
            let n = &tree.nodes[i as usize];
            if n.is_leaf() {
                at_leaf(self.leaf[i as usize] as usize, m);
                continue;
            }
            let off = m | (1u64 << self.bit[i as usize]);
            let (l, r) = if z[n.feature as usize] < n.threshold {
                (m, off)
            } else {
                (off, m)
            };
            stack.push((n.right, r));
            stack.push((n.left, l));
        }
    }

    /// The table of `tree` for the background given by columns (`cols[f][r]`, |B| = `nb`), or
    /// `None` (pair recursion). `masks` is scratch space (resized here).
    fn build(tree: &Tree, cols: &[Vec<f64>], nb: usize, masks: &mut Vec<u64>) -> Option<Self> {
        let (mut t, widths) = Self::layout(tree)?;
        let mut offset = Vec::with_capacity(widths.len() + 1);
        let mut total = 0usize;
        for w in &widths {
            offset.push(total);
            total += w;
        }
        let mut count = vec![0u32; total];
        let depth = tree.depth();
        masks.clear();
        masks.resize((depth + 1) * nb, 0);
        let mut fill = Fill {
            tree,
            table: &t,
            cols,
            nb,
            offset: &offset,
            count: &mut count,
        };
        fill.node(0, masks);
        for (k, lt) in t.leaves.iter_mut().enumerate() {
            let c = &count[offset[k]..offset[k] + widths[k]];
            lt.entries = c
                .iter()
                .enumerate()
                .filter(|&(_, &n)| n > 0)
                .map(|(m, &n)| (m as u64, f64::from(n)))
                .collect();
        }
        Some(t)
    }

    fn entries(&self) -> usize {
        self.leaves.iter().map(|l| l.entries.len()).sum()
    }

    /// Adds the (unnormalised) contributions of this tree at row `x` to `acc`.
    fn shap(
        &self,
        tree: &Tree,
        x: &[f64],
        wt: &InterventionalWeights,
        stack: &mut Vec<(u32, u64)>,
        acc: &mut [f64],
    ) {
        self.masks(tree, x, stack, |leaf, dx| {
            let lt = &self.leaves[leaf];
            let w = dx.count_ones() as usize;
            let mut minus = 0.0;
            for &(dr, n) in &lt.entries {
                if dr & dx != 0 {
                    continue;
                }
                let u = dr.count_ones() as usize;
                if u > 0 {
                    let a = lt.value * n * wt.pos[u * wt.n + w];
                    let mut b = dr;
                    while b != 0 {
                        acc[lt.features[b.trailing_zeros() as usize] as usize] += a;
                        b &= b - 1;
                    }
                }
                if w > 0 {
                    minus += n * wt.neg[u * wt.n + w];
                }
            }
            if w > 0 && minus != 0.0 {
                let b = lt.value * minus;
                let mut m = dx;
                while m != 0 {
                    acc[lt.features[m.trailing_zeros() as usize] as usize] -= b;
                    m &= m - 1;
                }
            }
        });
    }
}

/// The counting pass of [`TreeTable::build`]: one descent of the tree carrying the masks of all
/// background rows at once (`masks` holds one slice of |B| masks per level below the current
/// node; a child's slice is its parent's with the node's bit set for the rows that go the other
/// way), then at each leaf one count per row.
struct Fill<'t> {
    tree: &'t Tree,
    table: &'t TreeTable,
    cols: &'t [Vec<f64>],
    nb: usize,
    offset: &'t [usize],
    count: &'t mut [u32],
}

impl Fill<'_> {
    /// `masks[..nb]` are the masks at `node`; the rest is space for the levels below.
    fn node(&mut self, node: usize, masks: &mut [u64]) {
        let n = &self.tree.nodes[node];
        let (cur, below) = masks.split_at_mut(self.nb);
        if n.is_leaf() {
            let off = self.offset[self.table.leaf[node] as usize];
            for &m in cur.iter() {
                self.count[off + m as usize] += 1;
            }
            return;
        }
        let b = 1u64 << self.table.bit[node];
        let col = &self.cols[n.feature as usize];
        let th = n.threshold;
        for (child, left) in [(n.left, true), (n.right, false)] {
            for ((next, &m), &v) in below[..self.nb].iter_mut().zip(cur.iter()).zip(col) {
                *next = if (v < th) == left { m } else { m | b };
            }
            self.node(child as usize, below);
        }
    }
}

impl<'a> InterventionalTables<'a> {
    /// The tables of `model`'s trees for `background` (prepared rows). `None` when the budget
    /// ran out (checked after every tree).
    ///
    /// A tree keeps its table when a row's walk over it (its nodes plus its entries) is expected
    /// to cost less than the pair recursion (about 3·(depth + 1) node visits per background row,
    /// measured on the bench's models): deep trees with few background rows keep the pairs.
    #[must_use]
    pub fn new(
        model: &'a Model,
        background: &'a [Vec<f64>],
        wt: &'a InterventionalWeights,
        budget: &Budget,
    ) -> Option<Self> {
        let nb = background.len();
        Self::build(model, background, wt, budget, |nodes, entries, depth| {
            nodes + entries <= 3 * nb * (depth + 1)
        })
    }

    /// [`InterventionalTables::new`] with the choice of table or pairs per tree given by
    /// `keep(nodes, entries, depth)`.
    fn build(
        model: &'a Model,
        background: &'a [Vec<f64>],
        wt: &'a InterventionalWeights,
        budget: &Budget,
        keep: impl Fn(usize, usize, usize) -> bool,
    ) -> Option<Self> {
        let mut trees = Vec::with_capacity(model.trees.len());
        let mut entries = 0usize;
        let nb = background.len();
        let cols: Vec<Vec<f64>> = (0..model.n_features)
            .map(|f| background.iter().map(|r| r[f]).collect())
            .collect();
        let mut masks = Vec::new();
        for t in &model.trees {
            if budget.expired() {
                return None;
            }
            let table = if entries < TABLE_MAX_ENTRIES {
                TreeTable::build(t, &cols, nb, &mut masks)
                    .filter(|tt| keep(t.nodes.len(), tt.entries(), t.depth()))
            } else {
                None
            };
            if let Some(tt) = &table {
                entries += tt.entries();
            }
            trees.push(table);
        }
        Some(Self {
            model,
            background,
            wt,
            trees,
        })
    }

    /// Tree traversals of building the tables and explaining `rows` rows: |B| + rows per tree
    /// with a table, rows·|B| per tree without.
    #[must_use]
    pub fn traversals(&self, rows: usize) -> u64 {
        let (b, n) = (self.background.len() as u64, rows as u64);
        self.trees
            .iter()
            .map(|t| if t.is_some() { b + n } else { b * n })
            .sum()
    }

    /// Interventional SHAP values at the prepared row `x`: adds φ_i (the mean over the
    /// background) to `phi`.
    pub fn shap(&self, x: &[f64], phi: &mut [f64]) {
        if self.background.is_empty() {
            return;
        }
        let mut acc = vec![0.0; phi.len()];
        let mut stack = Vec::new();
        for (t, table) in self.model.trees.iter().zip(&self.trees) {
            match table {
                Some(tt) => tt.shap(t, x, self.wt, &mut stack, &mut acc),
                None => interventional_pairs(t, x, self.background, self.wt, &mut acc),
            }
        }
        let nb = self.background.len() as f64;
        for (p, a) in phi.iter_mut().zip(acc) {
            *p += a / nb;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::model::{ModelSource, Node, Routing};
    use super::*;

    fn split(feature: u32, threshold: f64, left: u32, cover: f64) -> Node {
        Node {
            left,
            right: left + 1,
            feature,
            threshold,
            default_left: false,
            value: 0.0,
            cover,
            loss_change: 1.0,
        }
    }

    /// T1 of the spec: x < 3.5 → −1.5 (cover 3) else 3 (cover 1), base 4.
    fn t1() -> Model {
        Model {
            base_score: 4.0,
            n_features: 1,
            feature_names: vec!["x".into()],
            routing: Routing::F64,
            source: ModelSource::Native,
            trees: vec![Tree {
                nodes: vec![
                    split(0, 3.5, 1, 4.0),
                    Node::leaf(-1.5, 3.0),
                    Node::leaf(3.0, 1.0),
                ],
            }],
        }
    }

    #[test]
    fn t1_shap_values() {
        let m = t1();
        assert!((m.expected_value() - 3.625).abs() < 1e-15);
        let mut buf = PathBuffer::for_depth(1);
        for (x, e) in [(1.0, -1.125), (4.0, 3.375)] {
            let mut phi = [0.0];
            path_dependent(&m, &[x], &mut phi, &mut buf);
            assert!((phi[0] - e).abs() < 1e-15, "{phi:?}");
        }
    }

    #[test]
    fn two_feature_tree_is_locally_accurate_and_interactions_sum_up() {
        // x0 < 0 → (x1 < 0 → 1 | 2) ; else (x1 < 1 → 3 | x0 < 5 → 4 | 5)
        let nodes = vec![
            split(0, 0.0, 1, 10.0),
            split(1, 0.0, 3, 4.0),
            split(1, 1.0, 5, 6.0),
            Node::leaf(1.0, 1.0),
            Node::leaf(2.0, 3.0),
            Node::leaf(3.0, 2.0),
            split(0, 5.0, 7, 4.0),
            Node::leaf(4.0, 3.0),
            Node::leaf(5.0, 1.0),
        ];
        let m = Model {
            base_score: 0.5,
            n_features: 2,
            feature_names: vec![],
            routing: Routing::F64,
            source: ModelSource::Native,
            trees: vec![Tree { nodes }],
        };
        let mut buf = PathBuffer::for_depth(3);
        for x in [[-1.0, -1.0], [1.0, 2.0], [6.0, 2.0], [1.0, 0.5]] {
            let mut phi = [0.0; 2];
            path_dependent(&m, &x, &mut phi, &mut buf);
            let f = m.predict_prepared(&x);
            assert!((m.expected_value() + phi[0] + phi[1] - f).abs() < 1e-12);
            let mut phi2 = [0.0; 2];
            let mut inter = [0.0; 4];
            let mut scratch = [vec![0.0; 2], vec![0.0; 2]];
            interactions(&m, &x, &mut phi2, &mut inter, &mut buf, &mut scratch);
            assert!((inter[0] + inter[1] - phi[0]).abs() < 1e-12);
            assert!((inter[2] + inter[3] - phi[1]).abs() < 1e-12);
            assert!((inter[1] - inter[2]).abs() < 1e-12, "symmetric: {inter:?}");
            let bg = vec![vec![-2.0, 3.0], vec![7.0, -1.0]];
            let wt = InterventionalWeights::new(3);
            let mut phi3 = [0.0; 2];
            interventional(&m, &x, &bg, &wt, &mut phi3);
            let e = bg.iter().map(|r| m.predict_prepared(r)).sum::<f64>() / 2.0;
            assert!((e + phi3[0] + phi3[1] - f).abs() < 1e-12);
        }
    }
    /// A random tree (pre-order, children after parents) over `d` features, with repeated
    /// features on paths and consistent covers.
    fn random_tree(seed: u64, depth: usize, d: u32) -> Tree {
        fn grow(nodes: &mut Vec<Node>, s: &mut u64, depth: usize, d: u32, cover: f64) -> u32 {
            let mut next = || {
                *s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (*s >> 11) as f64 / (1u64 << 53) as f64
            };
            let k = nodes.len() as u32;
            if depth == 0 || next() < 0.15 {
                nodes.push(Node::leaf(next() * 4.0 - 2.0, cover));
                return k;
            }
            let feature = (next() * f64::from(d)) as u32 % d;
            let threshold = next();
            let share = 0.1 + 0.8 * next();
            nodes.push(split(feature, threshold, 0, cover));
            let l = grow(nodes, s, depth - 1, d, cover * share);
            let r = grow(nodes, s, depth - 1, d, cover * (1.0 - share));
            nodes[k as usize].left = l;
            nodes[k as usize].right = r;
            k
        }
        let mut nodes = Vec::new();
        let mut s = seed;
        grow(&mut nodes, &mut s, depth, d, 100.0);
        Tree { nodes }
    }

    #[test]
    fn tables_equal_the_pair_recursion_and_local_accuracy_holds() {
        let d = 4;
        let trees: Vec<Tree> = (0..12)
            .map(|k| random_tree(k + 1, 2 + (k as usize % 6), d))
            .collect();
        let m = Model {
            base_score: 0.25,
            n_features: d as usize,
            feature_names: vec![],
            routing: Routing::F64,
            source: ModelSource::Native,
            trees,
        };
        let wt = InterventionalWeights::new(m.max_depth());
        let grid = |k: usize| {
            (0..d as usize)
                .map(|j| ((k * 7 + j * 3) % 11) as f64 / 10.0)
                .collect::<Vec<_>>()
        };
        let bg: Vec<Vec<f64>> = (0..37).map(grid).collect();
        let all = |_, _, _| true;
        let tables = InterventionalTables::build(&m, &bg, &wt, &Budget::unlimited(), all).unwrap();
        assert!(tables.trees.iter().all(Option::is_some));
        // With 3 background rows the deep trees keep the pair recursion, the shallow ones a table.
        let few = &bg[..3];
        let chosen = InterventionalTables::new(&m, few, &wt, &Budget::unlimited()).unwrap();
        assert!(
            chosen.trees.iter().any(Option::is_none),
            "some trees keep the pairs"
        );
        assert!(
            chosen.trees.iter().any(Option::is_some),
            "some trees keep a table"
        );
        let few_all = InterventionalTables::build(&m, few, &wt, &Budget::unlimited(), all).unwrap();
        let mut buf = PathBuffer::for_depth(m.max_depth());
        let forest = ShapForest::new(&m);
        for k in 0..9 {
            let x = grid(100 + 5 * k);
            let mut fast = vec![0.0; d as usize];
            tables.shap(&x, &mut fast);
            let (mut mixed, mut few_tables) = (vec![0.0; d as usize], vec![0.0; d as usize]);
            chosen.shap(&x, &mut mixed);
            few_all.shap(&x, &mut few_tables);
            let mut pairs = vec![0.0; d as usize];
            for t in &m.trees {
                interventional_pairs(t, &x, &bg, &wt, &mut pairs);
            }
            for (a, b) in fast.iter().zip(&pairs) {
                assert!(
                    (a - b / bg.len() as f64).abs() < 1e-13,
                    "{fast:?} vs {pairs:?}"
                );
            }
            for (a, c) in few_tables.iter().zip(&mixed) {
                assert!((a - c).abs() < 1e-13, "{few_tables:?} vs {mixed:?}");
            }
            let f = m.predict_prepared(&x);
            let e = bg.iter().map(|r| m.predict_prepared(r)).sum::<f64>() / bg.len() as f64;
            assert!((e + fast.iter().sum::<f64>() - f).abs() < 1e-12);
            let mut phi = vec![0.0; d as usize];
            forest.path_dependent(&x, &mut phi, &mut buf);
            assert!((m.expected_value() + phi.iter().sum::<f64>() - f).abs() < 1e-12);
        }
    }
}
