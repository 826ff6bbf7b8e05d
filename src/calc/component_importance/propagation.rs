//! Propagation sums of the "improved ASP" indices (paper Eqs. 10–15, spec §3.8).
//!
//! Given edge values p_e = P_ij = x_i·HE_ij (CSR edge order), every function returns per-length
//! row sums `s[L−1][i]` = Σ over paths (or walks) of exactly L edges starting at i of Π p along
//! the path, for L = 1..=K. The index is `fp_raw_i = Σ_L s[L−1][i]`. Keeping the lengths apart
//! lets [`log_index`] scale x by its maximum c (P = c·P̃, so a length-L term scales as c^L) and
//! combine the lengths in log space: the result neither overflows (risk rates at t → 0 with
//! β < 1, spec §6 H1) nor underflows (F ≈ 1e-300, H2).

use super::error::{ComponentImportanceError, Work};
use super::graph::Digraph;
use crate::numerics::Budget;

/// Per-length row sums: `s[L−1][i]` for L = 1..=K.
pub type LengthSums = Vec<Vec<f64>>;

/// Check the time budget every this many enumerated paths.
const PATHS_PER_BUDGET_CHECK: u64 = 4096;

/// Exact sums over simple paths by depth-first search from every node, depth ≤ K, carrying the
/// running product. Cost: the number of simple paths of length ≤ K (≈ n·d^K). Fails when one
/// traversal enumerates more than `max_paths` paths.
///
/// # Errors
/// [`ComponentImportanceError::PropagationPathBudget`] beyond `max_paths`;
/// [`ComponentImportanceError::Stopped`] when the caller's budget runs out.
pub fn path_sums_dfs(
    g: &Digraph,
    p: &[f64],
    k: usize,
    max_paths: u64,
    budget: &Budget,
    work: &mut Work,
) -> Result<LengthSums, ComponentImportanceError> {
    const STAGE: &str = "propagation sum (simple-path DFS)";
    let n = g.n();
    let mut s = vec![vec![0.0; n]; k];
    let mut on_path = vec![false; n];
    let mut prod = vec![1.0; k + 1];
    // Frames: (node, next CSR edge).
    let mut stack: Vec<(usize, usize)> = Vec::with_capacity(k + 1);
    let mut enumerated = 0u64;
    for i in 0..n {
        work.passes += 1;
        work.check(budget, STAGE)?;
        stack.push((i, g.out_edges(i).start));
        on_path[i] = true;
        while !stack.is_empty() {
            let depth = stack.len() - 1;
            let top = &mut stack[depth];
            let v = top.0;
            if depth < k && top.1 < g.out_edges(v).end {
                let e = top.1;
                top.1 += 1;
                let w = g.head(e);
                if on_path[w] {
                    continue;
                }
                let q = prod[depth] * p[e];
                prod[depth + 1] = q;
                s[depth][i] += q;
                enumerated += 1;
                work.paths += 1;
                if enumerated > max_paths {
                    return Err(ComponentImportanceError::PropagationPathBudget {
                        enumerated,
                        budget: max_paths,
                        path_cap: k,
                    });
                }
                if work.paths.is_multiple_of(PATHS_PER_BUDGET_CHECK) {
                    work.check(budget, STAGE)?;
                }
                if depth + 1 < k {
                    on_path[w] = true;
                    stack.push((w, g.out_edges(w).start));
                }
            } else {
                on_path[v] = false;
                stack.pop();
            }
        }
    }
    Ok(s)
}

/// Exact sums over simple paths of length ≤ 3 on any digraph, in O(m·d) (spec §3.8 closed form).
///
/// The spec's identities S2 = offdiag(P²), S3 = offdiag(P³ − D2·P − P·D2 + P∘P∘Pᵀ) are
/// evaluated row by row in the equivalent form
/// S2_i = Σ_a P_ia Σ_{b≠i} P_ab and
/// S3_i = Σ_a P_ia Σ_{b≠i} P_ab (r_b − P_ba − P_bi), r = P·1,
/// which drops the walks i→a→i→·, i→a→b→a and i→a→b→i without subtracting whole matrix products
/// (so strong 2-cycles cause no large cancellation). Returns `None` for K outside 1..=3.
#[must_use]
pub fn path_sums_closed_form(g: &Digraph, p: &[f64], k: usize) -> Option<LengthSums> {
    if !(1..=3).contains(&k) {
        return None;
    }
    let n = g.n();
    let r: Vec<f64> = (0..n).map(|i| g.out_edges(i).map(|e| p[e]).sum()).collect();
    // rev[e] = P_ji for edge e = i → j (0 if j → i is absent).
    let rev: Vec<f64> = (0..g.m())
        .map(|e| g.edge(g.head(e), g.tail(e)).map_or(0.0, |f| p[f]))
        .collect();
    let mut out = vec![r.clone()];
    if k == 1 {
        return Some(out);
    }
    let mut s2 = vec![0.0; n];
    let mut s3 = vec![0.0; n];
    // into_i[b] = P_bi for b ∈ pred(i).
    let mut into_i = vec![0.0; n];
    for i in 0..n {
        for (&b, &e) in g.pred(i).iter().zip(g.in_edges(i)) {
            into_i[b] = p[e];
        }
        let (mut t2, mut t3) = (0.0, 0.0);
        for e1 in g.out_edges(i) {
            let a = g.head(e1);
            let (mut u2, mut u3) = (0.0, 0.0);
            for e2 in g.out_edges(a) {
                let b = g.head(e2);
                if b == i {
                    continue;
                }
                u2 += p[e2];
                if k == 3 {
                    let rest = (r[b] - rev[e2] - into_i[b]).max(0.0);
                    u3 += p[e2] * rest;
                }
            }
            t2 += p[e1] * u2;
            t3 += p[e1] * u3;
        }
        s2[i] = t2;
        s3[i] = t3;
        for &b in g.pred(i) {
            into_i[b] = 0.0;
        }
    }
    out.push(s2);
    if k == 3 {
        out.push(s3);
    }
    Some(out)
}

/// Walk sums (P^L·1)_i, L = 1..=K, by K sparse matrix–vector products, O(K·m). Equal to the
/// simple-path sums on a DAG; an upper bound of them on a cyclic graph.
#[must_use]
pub fn walk_sums(g: &Digraph, p: &[f64], k: usize) -> LengthSums {
    let n = g.n();
    let mut out: LengthSums = Vec::with_capacity(k);
    let mut prev = vec![1.0; n];
    for _ in 0..k {
        let next: Vec<f64> = (0..n)
            .map(|i| g.out_edges(i).map(|e| p[e] * prev[g.head(e)]).sum())
            .collect();
        out.push(next.clone());
        prev = next;
    }
    out
}

/// The K = ∞ sum on a DAG: [P(I−P)^{-1}·1]_i (the DEMATEL total-relation row sum of P),
/// by y_i = Σ_j P_ij (1 + y_j) in reverse topological order, O(m). `topo` must be a topological
/// order of `g`.
#[must_use]
pub fn dag_total_sum(g: &Digraph, topo: &[usize], p: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; g.n()];
    for &i in topo.iter().rev() {
        y[i] = g.out_edges(i).map(|e| p[e] * (1.0 + y[g.head(e)])).sum();
    }
    y
}

/// ln fp_raw_i = ln Σ_L c^L·s̃[L−1]\[i\] for sums `s̃` computed with x scaled by 1/c; −∞ where
/// every term is 0. `ln_c` = ln c.
#[must_use]
pub fn log_index(s: &LengthSums, ln_c: f64) -> Vec<f64> {
    let n = s.first().map_or(0, Vec::len);
    (0..n)
        .map(|i| {
            let mut max = f64::NEG_INFINITY;
            for (l, row) in s.iter().enumerate() {
                if row[i] > 0.0 {
                    max = max.max(length_f64(l + 1).mul_add(ln_c, row[i].ln()));
                }
            }
            if max == f64::NEG_INFINITY {
                return max;
            }
            let mut sum = 0.0;
            for (l, row) in s.iter().enumerate() {
                if row[i] > 0.0 {
                    sum += (length_f64(l + 1).mul_add(ln_c, row[i].ln()) - max).exp();
                }
            }
            max + sum.ln()
        })
        .collect()
}

/// Column normalization fp_i = fp_raw_i / Σ_k fp_raw_k from logarithms (spec §3.9 step 1).
/// Returns `None` when every raw value is 0.
#[must_use]
pub fn normalize_log(ln_raw: &[f64]) -> Option<Vec<f64>> {
    let max = ln_raw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return None;
    }
    let w: Vec<f64> = ln_raw.iter().map(|&l| (l - max).exp()).collect();
    let total: f64 = w.iter().sum();
    Some(w.iter().map(|x| x / total).collect())
}

/// Relative truncation bound of the K-capped sum against the K = ∞ walk sum,
/// ρ^K/(1−ρ) for ρ < 1 (`None`: bound void), ρ = max_i Σ_j P_ij given as ln ρ.
#[must_use]
pub fn tail_bound(ln_rho: f64, k: usize) -> Option<f64> {
    if ln_rho >= 0.0 {
        return None;
    }
    let rho = ln_rho.exp();
    Some((length_f64(k) * ln_rho).exp() / (1.0 - rho))
}

/// Small count → f64 (K ≤ 8).
fn length_f64(l: usize) -> f64 {
    f64::from(u32::try_from(l).unwrap_or(u32::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn complete(n: usize) -> Digraph {
        let mut e = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if i != j {
                    e.push((i, j));
                }
            }
        }
        Digraph::from_edges(n, &e).unwrap().0
    }

    #[test]
    fn closed_form_equals_dfs_on_complete_digraph() {
        let g = complete(6);
        let p: Vec<f64> = (0..g.m())
            .map(|e| 0.01f64.mul_add((e % 7) as f64, 0.1))
            .collect();
        let mut w = Work::default();
        let dfs = path_sums_dfs(&g, &p, 3, u64::MAX, &Budget::unlimited(), &mut w).unwrap();
        let cf = path_sums_closed_form(&g, &p, 3).unwrap();
        for l in 0..3 {
            for i in 0..6 {
                assert!((dfs[l][i] - cf[l][i]).abs() < 1e-14, "L={} i={i}", l + 1);
            }
        }
        // Number of simple paths of length ≤ 3 in K6 from each node: 5 + 20 + 60.
        assert_eq!(w.paths, 6 * 85);
    }

    #[test]
    fn log_index_scales() {
        let s = vec![vec![0.5, 0.0], vec![0.25, 0.0]];
        let l = log_index(&s, 2f64.ln());
        assert!((l[0].exp() - 2.0).abs() < 1e-14);
        assert!(l[1].is_infinite() && l[1] < 0.0);
        assert!(normalize_log(&[f64::NEG_INFINITY; 3]).is_none());
    }
}
