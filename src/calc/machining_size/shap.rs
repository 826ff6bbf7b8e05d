//! Exact Shapley values of tree ensembles (spec §4).
//!
//! * [`path_dependent`]: polynomial TreeSHAP (Lundberg, Erion, Lee, "Consistent individualized
//!   feature attribution for tree ensembles", 2018, Algorithm 2), the value of a coalition being
//!   the cover-weighted conditional expectation; equal to XGBoost's `pred_contribs` and shap's
//!   TreeExplainer without background data. The recursion follows shap's `tree_shap_recursive`
//!   (path buffer shared by all levels, the parent's path copied into the next slot).
//! * [`interactions`]: SHAP interaction values by conditioning TreeSHAP on each feature a tree
//!   uses ("on"/"off"), as XGBoost's `pred_interactions` and shap do (spec §4.3).
//! * [`interventional`]: interventional TreeSHAP against a background set (spec §4.2).
//!
//! Hazards (spec §8.9): a child with zero cover gives a (0, 0) path element whose later unwinding
//! would divide by zero; such a subtree contributes exactly 0 and is skipped. Cover fractions are
//! clamped to [0, 1] and are 0 under a node of zero cover ([`cover_fraction`]). Local accuracy
//! holds for any such fractions because φ₀ uses the same ones.

use super::model::{MAX_TREE_DEPTH, Model, Tree, cover_fraction};

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

struct Walk<'a> {
    tree: &'a Tree,
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
    let n = &w.tree.nodes[node];
    if n.is_leaf() {
        let path = &buf[start..];
        for i in 1..=ud {
            let s = unwound_sum(path, ud, i);
            let e = path[i];
            if let Ok(f) = usize::try_from(e.feature) {
                phi[f] += s * (e.one - e.zero) * n.value * cf;
            }
        }
        return;
    }
    let f = n.feature;
    let (hot, cold) = if w.x[f as usize] < n.threshold {
        (n.left as usize, n.right as usize)
    } else {
        (n.right as usize, n.left as usize)
    };
    let nodes = &w.tree.nodes;
    let hz = cover_fraction(nodes[hot].cover, n.cover);
    let cz = cover_fraction(nodes[cold].cover, n.cover);
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
        recurse(w, phi, buf, hot, next, start, (hz * iz, io, fi), hcf);
    }
    if cz * iz != 0.0 {
        recurse(w, phi, buf, cold, next, start, (cz * iz, 0.0, fi), ccf);
    }
}

fn tree_shap(tree: &Tree, x: &[f64], cond: Condition, phi: &mut [f64], buf: &mut PathBuffer) {
    let w = Walk { tree, x, cond };
    recurse(&w, phi, &mut buf.buf, 0, 0, 0, (1.0, 1.0, -1), 1.0);
}

/// Path-dependent SHAP values of `model` at the prepared row `x` ([`Model::prepare_row`]): adds
/// φ_i to `phi[i]` (length `n_features`). φ₀ is [`Model::expected_value`].
pub fn path_dependent(model: &Model, x: &[f64], phi: &mut [f64], buf: &mut PathBuffer) {
    for t in &model.trees {
        tree_shap(t, x, Condition::None, phi, buf);
    }
}

/// SHAP interaction values Φ (row-major `d × d`, added to `out`) and the SHAP values φ (added to
/// `phi`) of `model` at the prepared row `x`: Φ_ij = (φ_i^{j on} − φ_i^{j off})/2 for i ≠ j,
/// Φ_ii = φ_i − Σ_{j≠i} Φ_ij. Each tree is conditioned only on the features it uses (for the
/// others "on" and "off" coincide). `scratch` needs two vectors of length `d`.
pub fn interactions(
    model: &Model,
    x: &[f64],
    phi: &mut [f64],
    out: &mut [f64],
    buf: &mut PathBuffer,
    scratch: &mut [Vec<f64>; 2],
) {
    let d = model.n_features;
    for t in &model.trees {
        tree_shap(t, x, Condition::None, phi, buf);
        for j in t.used_features() {
            let [on, off] = scratch;
            on.iter_mut().for_each(|v| *v = 0.0);
            off.iter_mut().for_each(|v| *v = 0.0);
            tree_shap(t, x, Condition::On(j), on, buf);
            tree_shap(t, x, Condition::Off(j), off, buf);
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
pub fn interventional(
    model: &Model,
    x: &[f64],
    background: &[Vec<f64>],
    wt: &InterventionalWeights,
    phi: &mut [f64],
) {
    if background.is_empty() {
        return;
    }
    let mut acc = vec![0.0; phi.len()];
    let mut sets = Sets {
        u: Vec::with_capacity(wt.n),
        v: Vec::with_capacity(wt.n),
    };
    for r in background {
        for t in &model.trees {
            interv_recurse(t, 0, x, r, &mut sets, wt, &mut acc);
        }
    }
    let nb = background.len() as f64;
    for (p, a) in phi.iter_mut().zip(acc) {
        *p += a / nb;
    }
}

#[cfg(test)]
mod tests {
    use super::super::model::{ModelSource, Node, Routing};
    use super::*;

    fn leaf(value: f64, cover: f64) -> Node {
        Node {
            left: super::super::model::LEAF,
            right: super::super::model::LEAF,
            feature: 0,
            threshold: 0.0,
            default_left: false,
            value,
            cover,
            loss_change: 0.0,
        }
    }

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
                nodes: vec![split(0, 3.5, 1, 4.0), leaf(-1.5, 3.0), leaf(3.0, 1.0)],
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
            leaf(1.0, 1.0),
            leaf(2.0, 3.0),
            leaf(3.0, 2.0),
            split(0, 5.0, 7, 4.0),
            leaf(4.0, 3.0),
            leaf(5.0, 1.0),
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
}
