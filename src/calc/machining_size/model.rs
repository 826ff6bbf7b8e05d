//! The validated tree ensemble every part of the module works on: trained here, read from our
//! model JSON or imported from an XGBoost JSON model (spec §5).
//!
//! A [`Tree`] is a flat node array in breadth-first order with the root at 0 and every child
//! after its parent, so a traversal always terminates within `nodes.len()` steps. Routing is
//! `x[feature] < threshold → left`. For imported XGBoost models ([`Routing::F32`]) the
//! thresholds and values are the model's f32 numbers and each input row is rounded to f32 before
//! routing ([`Model::prepare_row`]), which reproduces XGBoost's comparison `float(x) < float(θ)`
//! bit for bit (widening f32 → f64 is exact and monotone).

/// Marker of "no child" (a leaf) in [`Node::left`] / [`Node::right`].
pub const LEAF: u32 = u32::MAX;

/// Deepest tree accepted from a model document: recursion in TreeSHAP and the path buffers grow
/// with depth; XGBoost's own depth-wise trees are far shallower (training allows ≤ 12).
pub const MAX_TREE_DEPTH: usize = 64;

/// Most nodes over all trees of a model document (spec §8 hazard 10).
pub const MAX_TOTAL_NODES: usize = 1_000_000;

/// One node of a tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Index of the left child, or [`LEAF`].
    pub left: u32,
    /// Index of the right child, or [`LEAF`].
    pub right: u32,
    /// Feature tested at an internal node (original column index).
    pub feature: u32,
    /// Split threshold θ: `x < θ` goes left.
    pub threshold: f64,
    /// Direction of a missing value (kept for the format; rows are finite in v1).
    pub default_left: bool,
    /// Leaf value (already multiplied by η); internal nodes carry their own weight too.
    pub value: f64,
    /// Cover: sum of hessians of the training rows that reached the node (row count for
    /// squared error).
    pub cover: f64,
    /// Loss change Δ of the split (0 at leaves).
    pub loss_change: f64,
}

impl Node {
    /// A leaf with value `value` and cover `cover`.
    #[must_use]
    pub fn leaf(value: f64, cover: f64) -> Self {
        Self {
            left: LEAF,
            right: LEAF,
            feature: 0,
            threshold: 0.0,
            default_left: false,
            value,
            cover,
            loss_change: 0.0,
        }
    }

    /// Whether the node is a leaf.
    #[must_use]
    pub fn is_leaf(&self) -> bool {
        self.left == LEAF
    }
}

/// One regression tree, nodes in breadth-first order (root 0, children after parents).
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    /// The nodes.
    pub nodes: Vec<Node>,
}

/// The fraction of `parent`'s cover that went to `child`, clamped to [0, 1]; 0 when the parent
/// has no cover (spec §8 hazard 9: never 0/0). Covers of consistent trees give the plain ratio.
#[must_use]
pub fn cover_fraction(child: f64, parent: f64) -> f64 {
    if parent > 0.0 {
        (child / parent).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

impl Tree {
    /// A tree of one leaf with value `value` and cover `cover`.
    #[must_use]
    pub fn stump(value: f64, cover: f64) -> Self {
        Self {
            nodes: vec![Node::leaf(value, cover)],
        }
    }

    /// Index of the leaf that row `x` reaches.
    #[must_use]
    pub fn leaf_index(&self, x: &[f64]) -> usize {
        let mut i = 0usize;
        loop {
            let n = &self.nodes[i];
            if n.is_leaf() {
                return i;
            }
            i = if x[n.feature as usize] < n.threshold {
                n.left
            } else {
                n.right
            } as usize;
        }
    }

    /// The tree's output for row `x`.
    #[must_use]
    pub fn predict(&self, x: &[f64]) -> f64 {
        self.nodes[self.leaf_index(x)].value
    }

    /// Number of internal nodes (splits).
    #[must_use]
    pub fn n_splits(&self) -> usize {
        self.nodes.iter().filter(|n| !n.is_leaf()).count()
    }

    /// Number of leaves.
    #[must_use]
    pub fn n_leaves(&self) -> usize {
        self.nodes.len() - self.n_splits()
    }

    /// Depth (a single leaf has depth 0).
    #[must_use]
    pub fn depth(&self) -> usize {
        let mut depth = vec![0usize; self.nodes.len()];
        let mut max = 0;
        for (i, n) in self.nodes.iter().enumerate() {
            if !n.is_leaf() {
                let d = depth[i] + 1;
                depth[n.left as usize] = d;
                depth[n.right as usize] = d;
                max = max.max(d);
            }
        }
        max
    }

    /// Cover-weighted expectation of the tree's leaves: the value of the empty coalition of
    /// path-dependent TreeSHAP (children weighted by [`cover_fraction`]).
    #[must_use]
    pub fn expected_value(&self) -> f64 {
        let mut mean = vec![0.0; self.nodes.len()];
        for i in (0..self.nodes.len()).rev() {
            let n = &self.nodes[i];
            mean[i] = if n.is_leaf() {
                n.value
            } else {
                let (l, r) = (n.left as usize, n.right as usize);
                cover_fraction(self.nodes[l].cover, n.cover) * mean[l]
                    + cover_fraction(self.nodes[r].cover, n.cover) * mean[r]
            };
        }
        mean[0]
    }

    /// Features tested anywhere in the tree, ascending, without repeats.
    #[must_use]
    pub fn used_features(&self) -> Vec<u32> {
        let mut f: Vec<u32> = self
            .nodes
            .iter()
            .filter(|n| !n.is_leaf())
            .map(|n| n.feature)
            .collect();
        f.sort_unstable();
        f.dedup();
        f
    }
}

/// How input rows are compared with thresholds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Routing {
    /// f64 comparison (models trained here).
    F64,
    /// Rows rounded to f32 first (imported XGBoost models), as XGBoost does.
    F32,
}

/// Where a model came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelSource {
    /// Our `machining-size-gbdt/1` JSON (or trained in this request).
    Native,
    /// An XGBoost JSON model.
    Xgboost,
}

/// A validated additive tree ensemble: prediction = base_score + Σ trees.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Initial prediction (intercept) in target units.
    pub base_score: f64,
    /// Number of input columns a row must have.
    pub n_features: usize,
    /// Column names (empty when an imported model has none).
    pub feature_names: Vec<String>,
    /// Comparison rule of the thresholds.
    pub routing: Routing,
    /// Origin of the model.
    pub source: ModelSource,
    /// The trees.
    pub trees: Vec<Tree>,
}

impl Model {
    /// A row as the trees compare it: unchanged for f64 routing, each value rounded to f32 for
    /// imported XGBoost models.
    #[must_use]
    pub fn prepare_row(&self, x: &[f64]) -> Vec<f64> {
        match self.routing {
            Routing::F64 => x.to_vec(),
            Routing::F32 => x.iter().map(|&v| f64::from(v as f32)).collect(),
        }
    }

    /// [`Model::prepare_row`] in place.
    #[must_use]
    pub fn prepare_owned(&self, mut x: Vec<f64>) -> Vec<f64> {
        if self.routing == Routing::F32 {
            for v in &mut x {
                *v = f64::from(*v as f32);
            }
        }
        x
    }

    /// Prediction for a prepared row (see [`Model::prepare_row`]): base + Σ tree outputs, the sum
    /// accumulated from 0 in tree order.
    #[must_use]
    pub fn predict_prepared(&self, x: &[f64]) -> f64 {
        let mut s = 0.0;
        for t in &self.trees {
            s += t.predict(x);
        }
        self.base_score + s
    }

    /// φ₀ of path-dependent TreeSHAP: base + Σ cover-weighted tree expectations.
    #[must_use]
    pub fn expected_value(&self) -> f64 {
        let mut s = 0.0;
        for t in &self.trees {
            s += t.expected_value();
        }
        self.base_score + s
    }

    /// Deepest tree.
    #[must_use]
    pub fn max_depth(&self) -> usize {
        self.trees.iter().map(Tree::depth).max().unwrap_or(0)
    }

    /// Total number of leaves.
    #[must_use]
    pub fn n_leaves(&self) -> usize {
        self.trees.iter().map(Tree::n_leaves).sum()
    }

    /// Trees with at least one split.
    #[must_use]
    pub fn effective_trees(&self) -> usize {
        self.trees.iter().filter(|t| t.n_splits() > 0).count()
    }
}

/// A tree as a document gives it: parallel arrays indexed by node id (our format and XGBoost's
/// share this shape). Child −1 marks a leaf.
#[derive(Debug, Clone, Default)]
pub struct RawTree {
    /// Left child per node (−1 at leaves).
    pub left: Vec<i64>,
    /// Right child per node (−1 at leaves).
    pub right: Vec<i64>,
    /// Split feature per node (ignored at leaves).
    pub feature: Vec<i64>,
    /// Threshold per node (ignored at leaves).
    pub threshold: Vec<f64>,
    /// Default direction per node.
    pub default_left: Vec<bool>,
    /// Node value (leaf value at leaves).
    pub value: Vec<f64>,
    /// Cover per node.
    pub cover: Vec<f64>,
    /// Loss change per node.
    pub loss_change: Vec<f64>,
}

/// Names of [`RawTree`]'s arrays in the document, for error pointers.
#[derive(Debug, Clone, Copy)]
pub struct RawNames {
    /// Left-child array.
    pub left: &'static str,
    /// Right-child array.
    pub right: &'static str,
    /// Feature array.
    pub feature: &'static str,
    /// Threshold array.
    pub threshold: &'static str,
    /// Value array.
    pub value: &'static str,
    /// Cover array.
    pub cover: &'static str,
}

impl RawNames {
    /// The arrays named by their own roles (`left`, `right`, `feature`, …): the native model
    /// document.
    pub const PLAIN: Self = Self {
        left: "left",
        right: "right",
        feature: "feature",
        threshold: "threshold",
        value: "value",
        cover: "cover",
    };
}

/// A structural defect of a tree document, with the JSON pointer of the offending entry.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StructureIssue {
    /// JSON pointer of the offending entry.
    pub pointer: String,
    /// What is wrong.
    pub detail: String,
}

/// Largest magnitude accepted for a leaf value or base score: keeps a sum over 5000 trees (and
/// every SHAP term) far from overflow.
pub const MAX_ABS_VALUE: f64 = 1e100;

/// The number of nodes of a document tree: every node array as long as the left-child array,
/// and at least the root.
fn node_count(raw: &RawTree, names: RawNames, at: &str) -> Result<usize, StructureIssue> {
    let n = raw.left.len();
    let lengths = [
        (names.right, raw.right.len()),
        (names.feature, raw.feature.len()),
        (names.threshold, raw.threshold.len()),
        (names.value, raw.value.len()),
        (names.cover, raw.cover.len()),
    ];
    for (field, len) in lengths {
        if len != n {
            return Err(StructureIssue {
                pointer: format!("{at}/{field}"),
                detail: format!("has {len} entries but {} has {n}", names.left),
            });
        }
    }
    if n == 0 {
        return Err(StructureIssue {
            pointer: format!("{at}/{}", names.left),
            detail: "a tree needs at least its root node".to_owned(),
        });
    }
    Ok(n)
}

/// Validates a document tree and returns it in breadth-first order. `at` is the pointer of the
/// tree object; `n_features` bounds the feature indices.
///
/// Checks: equal array lengths; the root exists; every node reached from the root has either two
/// children in range or none (−1, −1); no node is reached twice (a cycle or a shared child);
/// depth ≤ [`MAX_TREE_DEPTH`]; features of internal nodes in `0..n_features`; thresholds finite;
/// values finite with |v| ≤ [`MAX_ABS_VALUE`]; covers finite and ≥ 0. Nodes not reachable from
/// the root (XGBoost keeps pruned nodes in its arrays) are ignored.
///
/// # Errors
/// The first defect found, with its pointer.
pub fn build_tree(
    raw: &RawTree,
    names: RawNames,
    at: &str,
    n_features: usize,
) -> Result<Tree, StructureIssue> {
    let n = node_count(raw, names, at)?;
    let issue = |field: &str, i: usize, detail: String| StructureIssue {
        pointer: format!("{at}/{field}/{i}"),
        detail,
    };
    let optional = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0);
    let mut seen = vec![false; n];
    seen[0] = true;
    // Breadth-first walk: (document index, depth); the output index is the queue position.
    let mut queue: Vec<(usize, usize)> = vec![(0, 0)];
    let mut nodes: Vec<Node> = Vec::new();
    let mut head = 0;
    while head < queue.len() {
        let (i, depth) = queue[head];
        head += 1;
        let (l, r) = (raw.left[i], raw.right[i]);
        let value = raw.value[i];
        let cover = raw.cover[i];
        if !(cover.is_finite() && cover >= 0.0) {
            return Err(issue(
                names.cover,
                i,
                format!("cover must be finite and ≥ 0, got {cover}"),
            ));
        }
        let mut node = Node {
            left: LEAF,
            right: LEAF,
            feature: 0,
            threshold: 0.0,
            default_left: raw.default_left.get(i).copied().unwrap_or(false),
            value,
            cover,
            loss_change: optional(&raw.loss_change, i),
        };
        if !node.loss_change.is_finite() {
            node.loss_change = 0.0;
        }
        if l == -1 && r == -1 {
            if !(value.is_finite() && value.abs() <= MAX_ABS_VALUE) {
                return Err(issue(
                    names.value,
                    i,
                    format!("leaf value must be finite with magnitude ≤ 1e100, got {value}"),
                ));
            }
            nodes.push(node);
            continue;
        }
        for (field, c) in [(names.left, l), (names.right, r)] {
            let in_range = usize::try_from(c).is_ok_and(|c| c < n);
            if !in_range {
                return Err(issue(
                    field,
                    i,
                    format!(
                        "child index must be −1 (leaf, with the other child −1 too) or a node \
                         index in 0..{n}, got {c}"
                    ),
                ));
            }
        }
        // In range: checked above.
        let (lu, ru) = (l as usize, r as usize);
        for (field, c) in [(names.left, lu), (names.right, ru)] {
            if seen[c] {
                return Err(issue(
                    field,
                    i,
                    format!(
                        "node {c} is reached twice (a cycle or a shared child): a tree needs \
                         each node to have exactly one parent"
                    ),
                ));
            }
            seen[c] = true;
        }
        if depth + 1 > MAX_TREE_DEPTH {
            return Err(issue(
                names.left,
                i,
                format!("tree deeper than {MAX_TREE_DEPTH} levels"),
            ));
        }
        let f = raw.feature[i];
        if !usize::try_from(f).is_ok_and(|f| f < n_features) {
            return Err(issue(
                names.feature,
                i,
                format!("split feature must be in 0..{n_features}, got {f}"),
            ));
        }
        let th = raw.threshold[i];
        if !th.is_finite() {
            return Err(issue(
                names.threshold,
                i,
                format!("threshold must be finite, got {th}"),
            ));
        }
        if !value.is_finite() {
            node.value = 0.0;
        }
        let next = queue.len();
        node.left = u32::try_from(next).unwrap_or(LEAF);
        node.right = u32::try_from(next + 1).unwrap_or(LEAF);
        node.feature = u32::try_from(f).unwrap_or(0);
        node.threshold = th;
        queue.push((lu, depth + 1));
        queue.push((ru, depth + 1));
        nodes.push(node);
    }
    Ok(Tree { nodes })
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAMES: RawNames = RawNames::PLAIN;

    fn raw(left: Vec<i64>, right: Vec<i64>) -> RawTree {
        let n = left.len();
        RawTree {
            left,
            right,
            feature: vec![0; n],
            threshold: vec![0.5; n],
            default_left: vec![false; n],
            value: (0..n).map(|i| i as f64).collect(),
            cover: vec![1.0; n],
            loss_change: vec![0.0; n],
        }
    }

    #[test]
    fn depth_one_tree_routes() {
        let t = build_tree(&raw(vec![1, -1, -1], vec![2, -1, -1]), NAMES, "/t", 1).unwrap();
        assert_eq!((t.predict(&[0.0])).to_bits(), f64::to_bits(1.0));
        assert_eq!((t.predict(&[0.5])).to_bits(), f64::to_bits(2.0));
        assert_eq!(t.depth(), 1);
    }

    #[test]
    fn cycles_and_out_of_range_children_are_rejected() {
        let e = build_tree(&raw(vec![1, 0, -1], vec![2, 2, -1]), NAMES, "/t", 1).unwrap_err();
        assert!(e.detail.contains("reached twice"), "{e:?}");
        assert_eq!(e.pointer, "/t/left/1");
        let e = build_tree(&raw(vec![1, -1, -1], vec![7, -1, -1]), NAMES, "/t", 1).unwrap_err();
        assert_eq!(e.pointer, "/t/right/0");
        let e = build_tree(&raw(vec![1, -1, -1], vec![-1, -1, -1]), NAMES, "/t", 1).unwrap_err();
        assert_eq!(e.pointer, "/t/right/0");
    }

    #[test]
    fn document_order_is_rewritten_breadth_first() {
        // Root 0 → (2, 1); node 2 → (3, 4).
        let r = raw(vec![2, -1, 3, -1, -1], vec![1, -1, 4, -1, -1]);
        let t = build_tree(&r, NAMES, "/t", 1).unwrap();
        assert_eq!(t.nodes.len(), 5);
        for (i, n) in t.nodes.iter().enumerate() {
            if !n.is_leaf() {
                assert!(n.left as usize > i && n.right as usize > i);
            }
        }
        assert_eq!((t.predict(&[0.0])).to_bits(), f64::to_bits(3.0));
    }
}
