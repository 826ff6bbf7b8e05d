//! Standard centralities of the unweighted fault graph and Kendall τ_b, for comparison with CI
//! (spec §3.10).

use std::cmp::Ordering;

use super::error::{ComponentImportanceError, Work};
use super::graph::Digraph;
use super::structure::{Reach, to_f64};
use crate::numerics::Budget;

/// PageRank damping α (spec §3.10).
pub const PAGERANK_ALPHA: f64 = 0.85;
/// Power iteration stops when the L1 change of one step is below this; the remaining error is at
/// most α/(1−α) times it (≈ 6e-15), i.e. "exact" at the printed 9 digits (spec §6 H7).
const PAGERANK_TOL: f64 = 1e-15;
/// α^400 ≈ 6e-29: the iteration has converged to rounding long before this.
const PAGERANK_MAX_ITER: usize = 400;

/// Normalized node betweenness: unnormalized Brandes values divided by (n−1)(n−2) (0 for n < 3).
#[must_use]
pub fn normalized_node_betweenness(node: &[f64]) -> Vec<f64> {
    let n = node.len();
    if n < 3 {
        return vec![0.0; n];
    }
    let d = to_f64(n - 1) * to_f64(n - 2);
    node.iter().map(|b| b / d).collect()
}

/// Outward closeness: Wasserman–Faust closeness on the reversed graph,
/// C_i = (r−1)/Σd · (r−1)/(n−1), r = nodes reachable from i including i; 0 if r = 1.
#[must_use]
pub fn outward_closeness(reach: &Reach) -> Vec<f64> {
    let n = reach.reach.len();
    reach
        .reach
        .iter()
        .zip(&reach.dist_sum)
        .map(|(&r, &ds)| {
            if r <= 1 || ds <= 0.0 || n < 2 {
                0.0
            } else {
                let r1 = to_f64(r - 1);
                r1 / ds * r1 / to_f64(n - 1)
            }
        })
        .collect()
}

/// PageRank on the reversed graph (fault influence flows back to the cause): α = 0.85, uniform
/// teleport, the mass of dangling nodes (original in-degree 0) spread uniformly. Power iteration
/// with a fixed summation order (sorted adjacency), so structurally identical nodes get identical
/// values (spec §6 H7).
///
/// # Errors
/// [`ComponentImportanceError::Stopped`] when the budget runs out.
pub fn pagerank_reversed(
    g: &Digraph,
    budget: &Budget,
    work: &mut Work,
) -> Result<Vec<f64>, ComponentImportanceError> {
    let n = g.n();
    let nf = to_f64(n);
    let indeg: Vec<f64> = (0..n).map(|i| to_f64(g.in_degree(i))).collect();
    let mut pr = vec![1.0 / nf; n];
    let mut next = vec![0.0; n];
    for _ in 0..PAGERANK_MAX_ITER {
        work.passes += 1;
        work.check(budget, "reversed PageRank")?;
        let dangling: f64 = (0..n).filter(|&i| g.in_degree(i) == 0).map(|i| pr[i]).sum();
        let base = PAGERANK_ALPHA.mul_add(dangling / nf, (1.0 - PAGERANK_ALPHA) / nf);
        for (v, nv) in next.iter_mut().enumerate() {
            // Reversed edge u → v exists for every original edge v → u.
            let s: f64 = g.succ(v).iter().map(|&u| pr[u] / indeg[u]).sum();
            *nv = PAGERANK_ALPHA.mul_add(s, base);
        }
        let diff: f64 = pr.iter().zip(&next).map(|(a, b)| (a - b).abs()).sum();
        std::mem::swap(&mut pr, &mut next);
        if diff < PAGERANK_TOL {
            break;
        }
    }
    Ok(pr)
}

fn cmp_f64(a: f64, b: f64) -> Ordering {
    a.partial_cmp(&b).unwrap_or(Ordering::Equal)
}

/// Kendall τ_b of two equally long samples, O(n log n) (Knight 1966): sort by (x, y), count
/// discordant pairs as inversions of y by merge sort. Ties are exact equalities.
/// `None` when undefined (n < 2 or one sample constant).
#[must_use]
pub fn kendall_tau_b(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len();
    if n < 2 || y.len() != n {
        return None;
    }
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|&a, &b| cmp_f64(x[a], x[b]).then(cmp_f64(y[a], y[b])));
    let pairs = |t: u64| t * t.saturating_sub(1) / 2;
    let (mut xtie, mut ntie) = (0u64, 0u64);
    let (mut tx, mut tn) = (1u64, 1u64);
    for w in idx.windows(2) {
        let same_x = cmp_f64(x[w[0]], x[w[1]]) == Ordering::Equal;
        let same_xy = same_x && cmp_f64(y[w[0]], y[w[1]]) == Ordering::Equal;
        if same_x {
            tx += 1;
        } else {
            xtie += pairs(tx);
            tx = 1;
        }
        if same_xy {
            tn += 1;
        } else {
            ntie += pairs(tn);
            tn = 1;
        }
    }
    xtie += pairs(tx);
    ntie += pairs(tn);
    let mut ys: Vec<f64> = idx.iter().map(|&i| y[i]).collect();
    let mut buf = ys.clone();
    let dis = merge_count(&mut ys, &mut buf);
    let mut ytie = 0u64;
    let mut ty = 1u64;
    for w in ys.windows(2) {
        if cmp_f64(w[0], w[1]) == Ordering::Equal {
            ty += 1;
        } else {
            ytie += pairs(ty);
            ty = 1;
        }
    }
    ytie += pairs(ty);
    let tot = pairs(u64::try_from(n).ok()?);
    if tot == xtie || tot == ytie {
        return None;
    }
    let u = |v: u64| -> f64 {
        // Pair counts ≤ 2e6 here: exact in f64.
        v as f64
    };
    let con_minus_dis = 2.0f64.mul_add(-u(dis), u(tot) - u(xtie) - u(ytie) + u(ntie));
    Some(con_minus_dis / ((u(tot) - u(xtie)).sqrt() * (u(tot) - u(ytie)).sqrt()))
}

/// Sort `a` ascending (stable merge sort) and return the number of strict inversions.
fn merge_count(a: &mut [f64], buf: &mut [f64]) -> u64 {
    let n = a.len();
    if n < 2 {
        return 0;
    }
    let mid = n / 2;
    let mut inv = {
        let (l, r) = a.split_at_mut(mid);
        let (bl, br) = buf.split_at_mut(mid);
        merge_count(l, bl) + merge_count(r, br)
    };
    let (mut i, mut j, mut k) = (0, mid, 0);
    while i < mid && j < n {
        if cmp_f64(a[j], a[i]) == Ordering::Less {
            buf[k] = a[j];
            j += 1;
            inv += u64::try_from(mid - i).unwrap_or(u64::MAX);
        } else {
            buf[k] = a[i];
            i += 1;
        }
        k += 1;
    }
    while i < mid {
        buf[k] = a[i];
        i += 1;
        k += 1;
    }
    while j < n {
        buf[k] = a[j];
        j += 1;
        k += 1;
    }
    a.copy_from_slice(&buf[..n]);
    inv
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive(x: &[f64], y: &[f64]) -> Option<f64> {
        let n = x.len();
        let (mut c, mut d, mut tx, mut ty) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for i in 0..n {
            for j in i + 1..n {
                let a = cmp_f64(x[i], x[j]);
                let b = cmp_f64(y[i], y[j]);
                match (a, b) {
                    (Ordering::Equal, Ordering::Equal) => {}
                    (Ordering::Equal, _) => tx += 1.0,
                    (_, Ordering::Equal) => ty += 1.0,
                    _ if a == b => c += 1.0,
                    _ => d += 1.0,
                }
            }
        }
        let den = ((c + d + tx) * (c + d + ty)).sqrt();
        (den > 0.0).then(|| (c - d) / den)
    }

    #[test]
    fn tau_b_matches_naive() {
        let x = [1.0, 2.0, 2.0, 3.0, 0.0, 0.0, 5.0, 2.0];
        let y = [0.3, 0.1, 0.1, 0.5, 0.0, 0.2, 0.5, 0.9];
        let a = kendall_tau_b(&x, &y).unwrap();
        let b = naive(&x, &y).unwrap();
        assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        assert!(kendall_tau_b(&[1.0, 1.0], &[0.0, 1.0]).is_none());
        assert!((kendall_tau_b(&[1.0, 2.0, 3.0], &[3.0, 2.0, 1.0]).unwrap() + 1.0).abs() < 1e-15);
    }
}
