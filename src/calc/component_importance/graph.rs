//! The fault-propagation digraph in compressed sparse row (CSR) form.
//!
//! Conventions: nodes are `0..n` in request order; an edge `i → j` means "a fault of `i` directly
//! causes a fault of `j`". Edges are identified by their position in the CSR successor array
//! (`edge` below); successor and predecessor lists are sorted by node index, so that structurally
//! identical components see identical summation orders and get bit-identical results (spec §6 H7).

use std::ops::Range;

/// Why an edge list does not form a valid fault graph.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum GraphError {
    /// Edge `index` names a node `>= n`.
    OutOfRange {
        /// Position of the edge in the input list.
        index: usize,
    },
    /// Edge `index` is a self-loop `i → i`.
    SelfLoop {
        /// Position of the edge in the input list.
        index: usize,
    },
    /// Edge `index` repeats edge `first`.
    Duplicate {
        /// Position of the repeated edge in the input list.
        index: usize,
        /// Position of its first occurrence.
        first: usize,
    },
}

/// A simple directed graph (no self-loops, no parallel edges) in CSR form.
#[derive(Debug, Clone)]
pub struct Digraph {
    n: usize,
    succ_off: Vec<usize>,
    succ: Vec<usize>,
    tail: Vec<usize>,
    pred_off: Vec<usize>,
    pred: Vec<usize>,
    pred_edge: Vec<usize>,
}

impl Digraph {
    /// Build from an edge list `(from, to)`. Returns the graph and, for every input edge, its CSR
    /// edge index.
    ///
    /// # Errors
    /// [`GraphError`] for out-of-range nodes, self-loops and duplicate edges.
    pub fn from_edges(
        n: usize,
        edges: &[(usize, usize)],
    ) -> Result<(Self, Vec<usize>), GraphError> {
        for (index, &(a, b)) in edges.iter().enumerate() {
            if a >= n || b >= n {
                return Err(GraphError::OutOfRange { index });
            }
            if a == b {
                return Err(GraphError::SelfLoop { index });
            }
        }
        let mut order: Vec<usize> = (0..edges.len()).collect();
        order.sort_by_key(|&k| (edges[k].0, edges[k].1, k));
        for w in order.windows(2) {
            if edges[w[0]] == edges[w[1]] {
                return Err(GraphError::Duplicate {
                    index: w[0].max(w[1]),
                    first: w[0].min(w[1]),
                });
            }
        }
        let m = edges.len();
        let mut succ_off = vec![0usize; n + 1];
        for &(a, _) in edges {
            succ_off[a + 1] += 1;
        }
        for i in 0..n {
            succ_off[i + 1] += succ_off[i];
        }
        // `order` is sorted by (from, to): it is exactly the CSR order.
        let mut succ = Vec::with_capacity(m);
        let mut tail = Vec::with_capacity(m);
        let mut csr_of_input = vec![0usize; m];
        for (pos, &k) in order.iter().enumerate() {
            succ.push(edges[k].1);
            tail.push(edges[k].0);
            csr_of_input[k] = pos;
        }
        let mut pred_off = vec![0usize; n + 1];
        for &(_, b) in edges {
            pred_off[b + 1] += 1;
        }
        for i in 0..n {
            pred_off[i + 1] += pred_off[i];
        }
        let mut fill = pred_off.clone();
        let mut pred = vec![0usize; m];
        let mut pred_edge = vec![0usize; m];
        // Visiting edges in CSR order (sorted by tail) leaves every predecessor list sorted.
        for e in 0..m {
            let b = succ[e];
            pred[fill[b]] = tail[e];
            pred_edge[fill[b]] = e;
            fill[b] += 1;
        }
        Ok((
            Self {
                n,
                succ_off,
                succ,
                tail,
                pred_off,
                pred,
                pred_edge,
            },
            csr_of_input,
        ))
    }

    /// Number of nodes.
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of edges.
    #[must_use]
    pub fn m(&self) -> usize {
        self.succ.len()
    }

    /// Successors of `i`, sorted.
    #[must_use]
    pub fn succ(&self, i: usize) -> &[usize] {
        &self.succ[self.succ_off[i]..self.succ_off[i + 1]]
    }

    /// CSR edge indices of the out-edges of `i` (same order as [`Self::succ`]).
    #[must_use]
    pub fn out_edges(&self, i: usize) -> Range<usize> {
        self.succ_off[i]..self.succ_off[i + 1]
    }

    /// Predecessors of `i`, sorted.
    #[must_use]
    pub fn pred(&self, i: usize) -> &[usize] {
        &self.pred[self.pred_off[i]..self.pred_off[i + 1]]
    }

    /// CSR edge indices of the in-edges of `i` (same order as [`Self::pred`]).
    #[must_use]
    pub fn in_edges(&self, i: usize) -> &[usize] {
        &self.pred_edge[self.pred_off[i]..self.pred_off[i + 1]]
    }

    /// Head (target) of edge `e`.
    #[must_use]
    pub fn head(&self, e: usize) -> usize {
        self.succ[e]
    }

    /// Tail (source) of edge `e`.
    #[must_use]
    pub fn tail(&self, e: usize) -> usize {
        self.tail[e]
    }

    /// Out-degree of `i`.
    #[must_use]
    pub fn out_degree(&self, i: usize) -> usize {
        self.succ_off[i + 1] - self.succ_off[i]
    }

    /// In-degree of `i`.
    #[must_use]
    pub fn in_degree(&self, i: usize) -> usize {
        self.pred_off[i + 1] - self.pred_off[i]
    }

    /// CSR index of edge `i → j`, if present.
    #[must_use]
    pub fn edge(&self, i: usize, j: usize) -> Option<usize> {
        self.succ(i)
            .binary_search(&j)
            .ok()
            .map(|k| self.succ_off[i] + k)
    }

    /// A topological order (Kahn, smallest index first among ready nodes), or `None` if the graph
    /// has a cycle.
    #[must_use]
    pub fn topological_order(&self) -> Option<Vec<usize>> {
        let mut indeg: Vec<usize> = (0..self.n).map(|i| self.in_degree(i)).collect();
        let mut ready: std::collections::BinaryHeap<std::cmp::Reverse<usize>> = (0..self.n)
            .filter(|&i| indeg[i] == 0)
            .map(std::cmp::Reverse)
            .collect();
        let mut order = Vec::with_capacity(self.n);
        while let Some(std::cmp::Reverse(v)) = ready.pop() {
            order.push(v);
            for &w in self.succ(v) {
                indeg[w] -= 1;
                if indeg[w] == 0 {
                    ready.push(std::cmp::Reverse(w));
                }
            }
        }
        (order.len() == self.n).then_some(order)
    }

    /// Strongly connected components (iterative Tarjan). Returns the component id of every node
    /// and the number of components. Ids are in reverse topological order of the condensation:
    /// every edge between different components goes from a higher id to a lower id (sinks first).
    #[must_use]
    pub fn strongly_connected_components(&self) -> (Vec<usize>, usize) {
        const UNVISITED: usize = usize::MAX;
        let n = self.n;
        let mut index = vec![UNVISITED; n];
        let mut low = vec![0usize; n];
        let mut on_stack = vec![false; n];
        let mut stack: Vec<usize> = Vec::new();
        let mut comp = vec![UNVISITED; n];
        let mut n_comp = 0usize;
        let mut next_index = 0usize;
        // Call stack of (node, position in its successor list).
        let mut call: Vec<(usize, usize)> = Vec::new();
        for root in 0..n {
            if index[root] != UNVISITED {
                continue;
            }
            call.push((root, 0));
            index[root] = next_index;
            low[root] = next_index;
            next_index += 1;
            stack.push(root);
            on_stack[root] = true;
            while let Some(&mut (v, ref mut pos)) = call.last_mut() {
                let succ = self.succ(v);
                if *pos < succ.len() {
                    let w = succ[*pos];
                    *pos += 1;
                    if index[w] == UNVISITED {
                        index[w] = next_index;
                        low[w] = next_index;
                        next_index += 1;
                        stack.push(w);
                        on_stack[w] = true;
                        call.push((w, 0));
                    } else if on_stack[w] {
                        low[v] = low[v].min(index[w]);
                    }
                } else {
                    call.pop();
                    if let Some(&(parent, _)) = call.last() {
                        low[parent] = low[parent].min(low[v]);
                    }
                    if low[v] == index[v] {
                        while let Some(w) = stack.pop() {
                            on_stack[w] = false;
                            comp[w] = n_comp;
                            if w == v {
                                break;
                            }
                        }
                        n_comp += 1;
                    }
                }
            }
        }
        (comp, n_comp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csr_and_lookup() {
        let (g, map) = Digraph::from_edges(4, &[(2, 1), (0, 3), (0, 1), (1, 2)]).unwrap();
        assert_eq!(g.succ(0), &[1, 3]);
        assert_eq!(g.pred(1), &[0, 2]);
        assert_eq!(map, vec![3, 1, 0, 2]);
        for (k, &(a, b)) in [(2, 1), (0, 3), (0, 1), (1, 2)].iter().enumerate() {
            assert_eq!(g.tail(map[k]), a);
            assert_eq!(g.head(map[k]), b);
            assert_eq!(g.edge(a, b), Some(map[k]));
        }
        assert!(g.topological_order().is_none());
        let (comp, nc) = g.strongly_connected_components();
        assert_eq!(nc, 3);
        assert_eq!(comp[1], comp[2]);
    }

    #[test]
    fn rejects_bad_edges() {
        assert_eq!(
            Digraph::from_edges(2, &[(0, 0)]).unwrap_err(),
            GraphError::SelfLoop { index: 0 }
        );
        assert_eq!(
            Digraph::from_edges(2, &[(0, 1), (0, 1)]).unwrap_err(),
            GraphError::Duplicate { index: 1, first: 0 }
        );
        assert_eq!(
            Digraph::from_edges(2, &[(0, 2)]).unwrap_err(),
            GraphError::OutOfRange { index: 0 }
        );
    }

    #[test]
    fn scc_ids_are_sinks_first() {
        // 0 → 1 → 2 → 1, 2 → 3
        let (g, _) = Digraph::from_edges(4, &[(0, 1), (1, 2), (2, 1), (2, 3)]).unwrap();
        let (comp, nc) = g.strongly_connected_components();
        assert_eq!(nc, 3);
        for e in 0..g.m() {
            let (a, b) = (g.tail(e), g.head(e));
            assert!(comp[a] >= comp[b]);
        }
    }
}
