//! The feature matrix (column-major, f64), the train/test and k-fold splits, constant columns and
//! the regression metrics of the paper (eq. 12–14).

use rand_chacha::ChaCha8Rng;

use super::rng;

/// A feature matrix stored column by column (`n_rows × n_cols`, 8 bytes per cell).
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    n_rows: usize,
    n_cols: usize,
    data: Vec<f64>,
}

impl Matrix {
    /// Builds the matrix from rows of equal length `n_cols` (checked by the caller), consuming
    /// them one by one so that the row-major copy is released while the columns fill.
    #[must_use]
    pub fn from_rows(rows: Vec<Vec<f64>>, n_cols: usize) -> Self {
        let n_rows = rows.len();
        let mut data = vec![0.0; n_rows * n_cols];
        for (r, row) in rows.into_iter().enumerate() {
            for (f, v) in row.into_iter().take(n_cols).enumerate() {
                data[f * n_rows + r] = v;
            }
        }
        Self {
            n_rows,
            n_cols,
            data,
        }
    }

    /// Builds the matrix from a column-major buffer of `n_rows × n_cols` values.
    #[must_use]
    pub fn from_columns(n_rows: usize, n_cols: usize, data: Vec<f64>) -> Self {
        debug_assert_eq!(data.len(), n_rows * n_cols);
        Self {
            n_rows,
            n_cols,
            data,
        }
    }

    /// Number of rows.
    #[must_use]
    pub fn n_rows(&self) -> usize {
        self.n_rows
    }

    /// Number of columns.
    #[must_use]
    pub fn n_cols(&self) -> usize {
        self.n_cols
    }

    /// Column `f`.
    #[must_use]
    pub fn col(&self, f: usize) -> &[f64] {
        &self.data[f * self.n_rows..(f + 1) * self.n_rows]
    }

    /// Value at row `r`, column `f`.
    #[must_use]
    pub fn get(&self, r: usize, f: usize) -> f64 {
        self.data[f * self.n_rows + r]
    }

    /// Row `r` written into `out` (resized to `n_cols`).
    pub fn row_into(&self, r: usize, out: &mut Vec<f64>) {
        out.clear();
        out.extend((0..self.n_cols).map(|f| self.data[f * self.n_rows + r]));
    }

    /// Row `r` as a new vector.
    #[must_use]
    pub fn row(&self, r: usize) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.n_cols);
        self.row_into(r, &mut v);
        v
    }

    /// The rows `rows` (in that order) followed by `extra` rows, as a new matrix.
    #[must_use]
    pub fn select_and_append(&self, rows: &[u32], extra: &[Vec<f64>]) -> Self {
        let n = rows.len() + extra.len();
        let mut data = Vec::with_capacity(n * self.n_cols);
        for f in 0..self.n_cols {
            let c = self.col(f);
            data.extend(rows.iter().map(|&r| c[r as usize]));
            data.extend(extra.iter().map(|e| e[f]));
        }
        Self::from_columns(n, self.n_cols, data)
    }

    /// Whether column `f` is constant (peak-to-peak 0, spec §6).
    #[must_use]
    pub fn is_constant(&self, f: usize) -> bool {
        let c = self.col(f);
        let (lo, hi) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        hi <= lo
    }
}

/// `0..n` as row ids.
#[must_use]
pub fn all_rows(n: usize) -> Vec<u32> {
    (0..n)
        .map(|i| u32::try_from(i).unwrap_or(u32::MAX))
        .collect()
}

/// Train/test split of `n` rows by a seeded permutation: the first ⌊(1 − test_fraction)·n⌋ rows of
/// the permutation train (spec §3 step 1). Both lists are sorted ascending.
#[must_use]
pub fn train_test_split(n: usize, test_fraction: f64, seed: u64) -> (Vec<u32>, Vec<u32>) {
    if test_fraction <= 0.0 {
        return (all_rows(n), Vec::new());
    }
    let mut r: ChaCha8Rng = rng::stream(seed, rng::STREAM_SPLIT);
    let perm = rng::permutation(&mut r, n);
    let n_train = n_train_rows(n, test_fraction);
    let mut train = perm[..n_train].to_vec();
    let mut test = perm[n_train..].to_vec();
    train.sort_unstable();
    test.sort_unstable();
    (train, test)
}

/// ⌊(1 − test_fraction)·n⌋, the size of the training split.
#[must_use]
pub fn n_train_rows(n: usize, test_fraction: f64) -> usize {
    let k = ((1.0 - test_fraction) * n as f64).floor() as usize;
    k.min(n)
}

/// The k folds of `n` rows: a seeded permutation cut into k parts of near-equal size (sizes
/// differ by at most one). Each fold's rows are sorted ascending.
#[must_use]
pub fn folds(n: usize, k: usize, seed: u64) -> Vec<Vec<u32>> {
    let mut r: ChaCha8Rng = rng::stream(seed, rng::STREAM_FOLDS);
    let perm = rng::permutation(&mut r, n);
    (0..k)
        .map(|i| {
            let mut f = perm[i * n / k..(i + 1) * n / k].to_vec();
            f.sort_unstable();
            f
        })
        .collect()
}

/// `all \ part`, both sorted ascending.
#[must_use]
pub fn complement(n: usize, part: &[u32]) -> Vec<u32> {
    let mut mark = vec![false; n];
    for &r in part {
        mark[r as usize] = true;
    }
    all_rows(n)
        .into_iter()
        .filter(|&r| !mark[r as usize])
        .collect()
}

/// Regression metrics of predictions against targets (paper eq. 12–14).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// Rows evaluated.
    pub n: usize,
    /// Mean absolute error.
    pub mae: f64,
    /// Mean squared error.
    pub mse: f64,
    /// √MSE.
    pub rmse: f64,
    /// 1 − Σ(ŷ−y)²/Σ(ȳ−y)², ȳ the mean of the evaluated targets; `None` when Σ(ȳ−y)² = 0.
    pub r2: Option<f64>,
}

/// Metrics of `pred` against `y` (same length, ≥ 1).
#[must_use]
pub fn metrics(pred: &[f64], y: &[f64]) -> Metrics {
    let n = y.len().max(1) as f64;
    let mean = y.iter().sum::<f64>() / n;
    let (mut abs, mut sq, mut tot) = (0.0, 0.0, 0.0);
    for (&p, &t) in pred.iter().zip(y) {
        abs += (p - t).abs();
        sq += (p - t) * (p - t);
        tot += (mean - t) * (mean - t);
    }
    let mse = sq / n;
    Metrics {
        n: y.len(),
        mae: abs / n,
        mse,
        rmse: mse.sqrt(),
        r2: (tot > 0.0).then(|| 1.0 - sq / tot),
    }
}

/// Mean and sample standard deviation (ddof = 1; 0 for fewer than two values).
#[must_use]
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len();
    if n == 0 {
        return (0.0, 0.0);
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    if n < 2 {
        return (mean, 0.0);
    }
    let ss: f64 = v.iter().map(|x| (x - mean) * (x - mean)).sum();
    (mean, (ss / (n - 1) as f64).sqrt())
}

/// Sample standard deviation (ddof = 1) computed on x/max|x|, so that no square overflows
/// whatever the magnitude of the values; 0 for fewer than two values.
#[must_use]
pub fn scaled_sd(v: &[f64]) -> f64 {
    let m = v.iter().fold(0.0f64, |a, &x| a.max(x.abs()));
    if m == 0.0 || !m.is_finite() {
        return 0.0;
    }
    let s: Vec<f64> = v.iter().map(|&x| x / m).collect();
    mean_sd(&s).1 * m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_sizes_and_disjointness() {
        let (tr, te) = train_test_split(850, 0.2, 7);
        assert_eq!(tr.len(), 680);
        assert_eq!(te.len(), 170);
        let mut all: Vec<u32> = tr.iter().chain(&te).copied().collect();
        all.sort_unstable();
        assert_eq!(all, all_rows(850));
        let f = folds(850, 5, 11);
        assert!(f.iter().all(|x| x.len() == 170));
        let f = folds(11, 3, 0);
        let sizes: Vec<usize> = f.iter().map(Vec::len).collect();
        assert_eq!(sizes.iter().sum::<usize>(), 11);
        assert!(sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1);
    }

    #[test]
    fn metrics_of_a_perfect_and_a_mean_predictor() {
        let y = [1.0, 2.0, 3.0];
        let m = metrics(&y, &y);
        assert_eq!((m.mse).to_bits(), f64::to_bits(0.0));
        assert_eq!(m.r2, Some(1.0));
        let m = metrics(&[2.0, 2.0, 2.0], &y);
        assert_eq!(m.r2, Some(0.0));
        assert!(metrics(&[1.0], &[1.0]).r2.is_none());
    }
}
