//! Principal component analysis of the factors (paper eq. 1 and eq. 16, as corrected by spec §6):
//! each column standardised over the samples (mean 0, sd 1, ddof = 1), eigen-decomposition of the
//! correlation matrix, eigenvalues descending, contribution rate 100·λ_j/Σλ, scores S = Z·V and the
//! composite score of each sample Σ_j S_ij·rate_j/100. Each eigenvector's sign is fixed so that its
//! largest-magnitude loading is positive (the first such entry on a tie).

use nalgebra::{DMatrix, SymmetricEigen};

use crate::numerics::{Budget, par_map};

use super::data::Matrix;

/// The analysis of the non-constant columns `cols`.
#[derive(Debug, Clone, PartialEq)]
pub struct Pca {
    /// Eigenvalues of the correlation matrix, descending (all of them; tiny negative rounding
    /// residues clamped to 0).
    pub eigenvalues: Vec<f64>,
    /// Contribution rate of each component [%].
    pub rates: Vec<f64>,
    /// Loadings: `loadings[j][c]` = entry `c` (column `cols[c]`) of eigenvector `j`, for the
    /// `k` retained components.
    pub loadings: Vec<Vec<f64>>,
    /// Composite score of every sample over the retained components.
    pub composite: Vec<f64>,
    /// Scores S (row-major `n × k`), when asked for.
    pub scores: Option<Vec<Vec<f64>>>,
}

/// Standardised column: (x − mean)/sd with ddof = 1, computed on x/max|x| so that no square
/// overflows whatever the magnitude of the data. `None` for a constant column.
fn standardise(col: &[f64]) -> Option<Vec<f64>> {
    let m = col.iter().fold(0.0f64, |a, &v| a.max(v.abs()));
    if m == 0.0 || col.len() < 2 {
        return None;
    }
    let n = col.len() as f64;
    let mean = col.iter().map(|&v| v / m).sum::<f64>() / n;
    let ss: f64 = col.iter().map(|&v| (v / m - mean) * (v / m - mean)).sum();
    let sd = (ss / (n - 1.0)).sqrt();
    (sd > 0.0).then(|| col.iter().map(|&v| (v / m - mean) / sd).collect())
}

/// PCA of the columns `cols` of `x` keeping `k` components (≤ `cols.len()`); `None` when the
/// budget ran out while the correlation matrix was built.
#[must_use]
pub fn pca(
    x: &Matrix,
    cols: &[usize],
    k: usize,
    scores: bool,
    budget: &Budget,
    threads: usize,
) -> Option<Pca> {
    let z: Vec<Vec<f64>> = cols
        .iter()
        .map(|&c| standardise(x.col(c)).unwrap_or_else(|| vec![0.0; x.n_rows()]))
        .collect();
    let d = z.len();
    let n = x.n_rows();
    let denom = (n.max(2) - 1) as f64;
    let rows = crate::numerics::par_map_while(threads, &z, |i, zi| {
        if budget.expired() {
            return None;
        }
        Some(
            (0..d)
                .map(|j| {
                    if j < i {
                        0.0
                    } else {
                        zi.iter().zip(&z[j]).map(|(a, b)| a * b).sum::<f64>() / denom
                    }
                })
                .collect::<Vec<f64>>(),
        )
    });
    let rows: Vec<Vec<f64>> = rows.into_iter().collect::<Option<_>>()?;
    let r = DMatrix::from_fn(d, d, |i, j| if j >= i { rows[i][j] } else { rows[j][i] });
    let eig = SymmetricEigen::new(r);
    let mut order: Vec<usize> = (0..d).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let eigenvalues: Vec<f64> = order.iter().map(|&j| eig.eigenvalues[j].max(0.0)).collect();
    let total: f64 = eigenvalues.iter().sum();
    let rates: Vec<f64> = eigenvalues
        .iter()
        .map(|&l| if total > 0.0 { 100.0 * l / total } else { 0.0 })
        .collect();
    let k = k.min(d);
    let loadings: Vec<Vec<f64>> = order[..k]
        .iter()
        .map(|&j| {
            let v: Vec<f64> = eig.eigenvectors.column(j).iter().copied().collect();
            let big = v
                .iter()
                .enumerate()
                .fold((0usize, 0.0f64), |(bi, bv), (i, &x)| {
                    if x.abs() > bv { (i, x.abs()) } else { (bi, bv) }
                })
                .0;
            let sign = if v[big] < 0.0 { -1.0 } else { 1.0 };
            v.into_iter().map(|x| sign * x).collect()
        })
        .collect();
    // Composite = Σ_j S_ij·rate_j/100 = Z·w with w = Σ_j v_j·rate_j/100 (no n × k scores needed).
    let w: Vec<f64> = (0..d)
        .map(|c| {
            loadings
                .iter()
                .zip(&rates)
                .map(|(v, r)| v[c] * r / 100.0)
                .sum()
        })
        .collect();
    let composite = (0..n)
        .map(|i| w.iter().zip(&z).map(|(a, zc)| a * zc[i]).sum())
        .collect();
    let sample_scores = scores.then(|| {
        par_map(threads, &(0..n).collect::<Vec<usize>>(), |_, &i| {
            loadings
                .iter()
                .map(|v| v.iter().zip(&z).map(|(a, zc)| a * zc[i]).sum::<f64>())
                .collect::<Vec<f64>>()
        })
    });
    Some(Pca {
        eigenvalues,
        rates,
        loadings,
        composite,
        scores: sample_scores,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_sum_to_100_and_perfectly_correlated_columns_share_one_component() {
        let rows: Vec<Vec<f64>> = (0..20)
            .map(|i| {
                let t = f64::from(i);
                vec![t, 2.0 * t + 1.0, (t * 1.7).sin()]
            })
            .collect();
        let x = Matrix::from_rows(rows, 3);
        let p = pca(&x, &[0, 1, 2], 3, true, &Budget::unlimited(), 1).unwrap();
        assert!((p.rates.iter().sum::<f64>() - 100.0).abs() < 1e-9);
        assert!(p.eigenvalues[0] >= p.eigenvalues[1]);
        // Columns 0 and 1 are identical after standardisation: loadings equal on them.
        assert!((p.loadings[0][0] - p.loadings[0][1]).abs() < 1e-9);
        assert!(p.loadings[0].iter().fold(0.0f64, |a, v| a.max(*v)) > 0.0);
        assert_eq!(p.composite.len(), 20);
    }

    #[test]
    fn huge_values_do_not_overflow() {
        let rows: Vec<Vec<f64>> = (0..10)
            .map(|i| vec![1e300 * f64::from(i % 3), f64::from(i)])
            .collect();
        let x = Matrix::from_rows(rows, 2);
        let p = pca(&x, &[0, 1], 2, false, &Budget::unlimited(), 1).unwrap();
        assert!(p.eigenvalues.iter().all(|v| v.is_finite()));
        assert!(p.composite.iter().all(|v| v.is_finite()));
    }
}
