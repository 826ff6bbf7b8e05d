//! SMOGN for regression (Branco, Torgo, Ribeiro, "SMOGN: a pre-processing approach for imbalanced
//! regression", PMLR 74, 2017), with the explicit relevance of spec §2.4/§6.
//!
//! Samples are sorted by target; the relevance φ(y) is the PCHIP interpolant of the control
//! points, clipped to [0, 1] (constant beyond the first and last point); rare = φ ≥ threshold;
//! bins are maximal runs of consecutive sorted samples with the same status; the target size of a
//! bin is round(n / #bins). Normal bins larger than that are undersampled without replacement;
//! rare bins of two or more samples keep every sample and get `target − size` new cases: seed
//! s = j mod size, its k nearest neighbours in the bin (Euclidean on features scaled by their
//! range over the data), safe margin = median neighbour distance / 2, a neighbour c drawn at
//! random; SMOTE interpolation when dist(s, c) < margin (target = distance-weighted mean), else
//! Gaussian noise (sd of the bin × perturbation). Rare bins of one sample are kept as they are.

use rand_chacha::ChaCha8Rng;

use crate::numerics::Budget;
use crate::numerics::pchip::Pchip;

use super::data::Matrix;
use super::rng;

/// SMOGN settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SmognParams {
    /// Relevance control points (y, φ), y strictly increasing, φ ∈ [0, 1], at least two.
    pub relevance: Vec<(f64, f64)>,
    /// Rare when φ(y) ≥ threshold.
    pub threshold: f64,
    /// Neighbours per seed.
    pub k: usize,
    /// Relative sd of the Gaussian perturbation.
    pub perturbation: f64,
    /// Seed.
    pub seed: u64,
}

/// One bin of consecutive sorted samples.
#[derive(Debug, Clone, PartialEq)]
pub struct Bin {
    /// Rare (φ ≥ threshold) or normal.
    pub rare: bool,
    /// Samples in the bin.
    pub size: usize,
    /// Smallest and largest target in the bin.
    pub y_range: (f64, f64),
    /// Original samples kept.
    pub kept: usize,
    /// New cases created.
    pub created: usize,
}

/// The resampled set.
#[derive(Debug, Clone, PartialEq)]
pub struct Smogn {
    /// Original rows kept (indices into the input's row list, ascending).
    pub kept: Vec<u32>,
    /// New rows (features in the matrix's column order).
    pub new_rows: Vec<Vec<f64>>,
    /// Their targets.
    pub new_targets: Vec<f64>,
    /// Bins in ascending target order.
    pub bins: Vec<Bin>,
    /// New cases made by interpolation.
    pub interpolated: usize,
    /// New cases made by Gaussian perturbation.
    pub perturbed: usize,
    /// Per column: new values that are not among the column's original values, for columns
    /// with at most [`DISCRETE_LEVELS`] distinct values (discrete factors; hazard 8.6).
    pub off_grid: Vec<(usize, usize)>,
    /// Samples with φ ≥ threshold.
    pub rare_count: usize,
}

/// A column with at most this many distinct values is treated as a discrete factor.
pub const DISCRETE_LEVELS: usize = 20;

/// Why SMOGN cannot run.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SmognError {
    /// The relevance is degenerate over the data: every sample rare, or none.
    #[error(
        "the relevance makes {rare} of {n} samples rare: SMOGN needs both rare and normal samples"
    )]
    Degenerate {
        /// Rare samples.
        rare: usize,
        /// Samples.
        n: usize,
    },
    /// The budget ran out.
    #[error("time budget exhausted after {created} new SMOGN cases")]
    Deadline {
        /// New cases made so far.
        created: usize,
    },
}

/// The relevance function of the control points (PCHIP, clipped to [0, 1]).
///
/// # Errors
/// The control points are not strictly increasing in y (the validator rejects that first).
pub fn relevance_fn(
    points: &[(f64, f64)],
) -> Result<impl Fn(f64) -> f64, crate::numerics::pchip::PchipError> {
    let (ys, ps): (Vec<f64>, Vec<f64>) = points.iter().copied().unzip();
    let p = Pchip::new(&ys, &ps)?;
    Ok(move |y: f64| p.eval(y).clamp(0.0, 1.0))
}

/// SMOGN over the rows `rows` of `x` with targets `y` (indexed like `x`'s rows). Returns the kept
/// rows as positions in `rows`.
///
/// # Errors
/// [`SmognError::Degenerate`] (every sample rare, or none), [`SmognError::Deadline`].
pub fn smogn(
    x: &Matrix,
    y: &[f64],
    rows: &[u32],
    p: &SmognParams,
    budget: &Budget,
) -> Result<Smogn, SmognError> {
    let n = rows.len();
    let phi = relevance_fn(&p.relevance).map_err(|_| SmognError::Degenerate { rare: 0, n })?;
    // Positions in `rows`, sorted by target (stable).
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| y[rows[a] as usize].total_cmp(&y[rows[b] as usize]));
    let rare: Vec<bool> = order
        .iter()
        .map(|&i| phi(y[rows[i] as usize]) >= p.threshold)
        .collect();
    let rare_count = rare.iter().filter(|&&r| r).count();
    if rare_count == 0 || rare_count == n {
        return Err(SmognError::Degenerate {
            rare: rare_count,
            n,
        });
    }
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for i in 1..=n {
        if i == n || rare[i] != rare[start] {
            runs.push((start, i));
            start = i;
        }
    }
    let target = ((n as f64) / runs.len() as f64).round().max(1.0) as usize;
    let scale = feature_ranges(x, rows);
    let mut r: ChaCha8Rng = rng::stream(p.seed, rng::STREAM_SMOGN);
    let mut out = Smogn {
        kept: Vec::with_capacity(n),
        new_rows: Vec::new(),
        new_targets: Vec::new(),
        bins: Vec::with_capacity(runs.len()),
        interpolated: 0,
        perturbed: 0,
        off_grid: Vec::new(),
        rare_count,
    };
    for &(a, b) in &runs {
        let members: Vec<usize> = order[a..b].to_vec();
        let size = members.len();
        let ys: Vec<f64> = members.iter().map(|&i| y[rows[i] as usize]).collect();
        let y_range = (ys[0], ys[size - 1]);
        let mut bin = Bin {
            rare: rare[a],
            size,
            y_range,
            kept: size,
            created: 0,
        };
        if !bin.rare {
            if size > target {
                let pick = rng::sample_sorted(&mut r, size, target);
                out.kept.extend(pick.iter().map(|&j| as_u32(members[j])));
                bin.kept = target;
            } else {
                out.kept.extend(members.iter().map(|&i| as_u32(i)));
            }
        } else {
            out.kept.extend(members.iter().map(|&i| as_u32(i)));
            if size >= 2 && target > size {
                let sd_x = (0..x.n_cols())
                    .map(|f| {
                        let v: Vec<f64> = members
                            .iter()
                            .map(|&i| x.get(rows[i] as usize, f))
                            .collect();
                        super::data::scaled_sd(&v)
                    })
                    .collect();
                let ctx = BinCtx {
                    x,
                    y,
                    rows,
                    members: &members,
                    scale: &scale,
                    sd_x,
                    sd_y: super::data::scaled_sd(&ys),
                };
                for j in 0..target - size {
                    if budget.expired() {
                        return Err(SmognError::Deadline {
                            created: out.new_rows.len(),
                        });
                    }
                    let (row, t, interp) = ctx.new_case(j % size, p, &mut r);
                    if interp {
                        out.interpolated += 1;
                    } else {
                        out.perturbed += 1;
                    }
                    out.new_rows.push(row);
                    out.new_targets.push(t);
                    bin.created += 1;
                }
            }
        }
        out.bins.push(bin);
    }
    out.kept.sort_unstable();
    out.off_grid = off_grid(x, rows, &out.new_rows);
    Ok(out)
}

fn as_u32(i: usize) -> u32 {
    u32::try_from(i).unwrap_or(u32::MAX)
}

/// Range (max − min) of every column over `rows`; 0 for constant columns (they add nothing to a
/// distance).
fn feature_ranges(x: &Matrix, rows: &[u32]) -> Vec<f64> {
    (0..x.n_cols())
        .map(|f| {
            let c = x.col(f);
            let (lo, hi) = rows
                .iter()
                .map(|&r| c[r as usize])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                });
            // hi − lo may overflow for values near ±f64::MAX: halve first.
            let half = hi * 0.5 - lo * 0.5;
            if half > 0.0 { half } else { 0.0 }
        })
        .collect()
}

struct BinCtx<'a> {
    x: &'a Matrix,
    y: &'a [f64],
    rows: &'a [u32],
    members: &'a [usize],
    scale: &'a [f64],
    /// Sample sd of every feature and of the target over the bin.
    sd_x: Vec<f64>,
    sd_y: f64,
}

impl BinCtx<'_> {
    fn feature(&self, member: usize, f: usize) -> f64 {
        self.x.get(self.rows[self.members[member]] as usize, f)
    }

    fn target(&self, member: usize) -> f64 {
        self.y[self.rows[self.members[member]] as usize]
    }

    /// Scaled Euclidean distance between two points given as feature closures.
    fn dist(&self, a: impl Fn(usize) -> f64, b: impl Fn(usize) -> f64) -> f64 {
        let mut s = 0.0;
        for (f, &sc) in self.scale.iter().enumerate() {
            if sc > 0.0 {
                let d = a(f) / sc * 0.5 - b(f) / sc * 0.5;
                s += d * d;
            }
        }
        s.sqrt()
    }

    /// New case from seed `s` (position in the bin): (features, target, interpolated?).
    fn new_case(&self, s: usize, p: &SmognParams, r: &mut ChaCha8Rng) -> (Vec<f64>, f64, bool) {
        let size = self.members.len();
        let d = self.scale.len();
        let mut nb: Vec<(f64, usize)> = (0..size)
            .filter(|&j| j != s)
            .map(|j| (self.dist(|f| self.feature(s, f), |f| self.feature(j, f)), j))
            .collect();
        let k = p.k.min(nb.len()).max(1);
        nb.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        nb.truncate(k);
        nb.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let median = if k % 2 == 1 {
            nb[k / 2].0
        } else {
            0.5 * (nb[k / 2 - 1].0 + nb[k / 2].0)
        };
        let margin = median / 2.0;
        let (dc, c) = nb[rng::index(r, k)];
        if dc < margin {
            let u = rng::uniform(r);
            let row: Vec<f64> = (0..d)
                .map(|f| {
                    let (a, b) = (self.feature(s, f), self.feature(c, f));
                    a * (1.0 - u) + b * u
                })
                .collect();
            let ds = self.dist(|f| row[f], |f| self.feature(s, f));
            let dcn = self.dist(|f| row[f], |f| self.feature(c, f));
            let (ys, yc) = (self.target(s), self.target(c));
            let t = if ds + dcn > 0.0 {
                (dcn * ys + ds * yc) / (ds + dcn)
            } else {
                0.5 * (ys + yc)
            };
            (row, t, true)
        } else {
            // Noise that would leave f64 (data near ±1.8e308) keeps the seed's value.
            let noisy = |v: f64, sd: f64, z: f64| {
                let w = v + z * sd * p.perturbation;
                if w.is_finite() { w } else { v }
            };
            let row: Vec<f64> = (0..d)
                .map(|f| noisy(self.feature(s, f), self.sd_x[f], rng::normal(r)))
                .collect();
            let t = noisy(self.target(s), self.sd_y, rng::normal(r));
            (row, t, false)
        }
    }
}

/// (column, count) of new values off the original grid of discrete columns.
fn off_grid(x: &Matrix, rows: &[u32], new_rows: &[Vec<f64>]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for f in 0..x.n_cols() {
        let c = x.col(f);
        let mut levels: Vec<f64> = rows.iter().map(|&r| c[r as usize]).collect();
        levels.sort_unstable_by(f64::total_cmp);
        levels.dedup_by(|a, b| *a <= *b);
        if levels.len() > DISCRETE_LEVELS {
            continue;
        }
        let count = new_rows
            .iter()
            .filter(|row| {
                let v = row[f];
                let i = levels.partition_point(|&l| l < v);
                levels.get(i).is_none_or(|&l| l > v)
            })
            .count();
        if count > 0 {
            out.push((f, count));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data() -> (Matrix, Vec<f64>) {
        let rows: Vec<Vec<f64>> = (0..40)
            .map(|i| vec![f64::from(i % 4), f64::from(i) * 0.1])
            .collect();
        let y: Vec<f64> = (0..40)
            .map(|i| {
                if i < 34 {
                    f64::from(i) * 0.01
                } else {
                    1.0 + f64::from(i) * 0.01
                }
            })
            .collect();
        (Matrix::from_rows(rows, 2), y)
    }

    #[test]
    fn rare_rows_are_kept_and_oversampled() {
        let (x, y) = data();
        let rows = super::super::data::all_rows(40);
        let p = SmognParams {
            relevance: vec![(0.5, 0.0), (1.0, 1.0)],
            threshold: 0.5,
            k: 5,
            perturbation: 0.02,
            seed: 0,
        };
        let s = smogn(&x, &y, &rows, &p, &Budget::unlimited()).unwrap();
        assert_eq!(s.rare_count, 6);
        assert_eq!(s.bins.len(), 2);
        // target = 20: the normal bin (34) is cut to 20, the rare bin (6) gets 14 new cases.
        assert_eq!(s.bins[0].kept, 20);
        assert_eq!(s.bins[1].created, 14);
        for i in 34..40u32 {
            assert!(s.kept.contains(&i));
        }
        assert_eq!(s.interpolated + s.perturbed, 14);
        assert!(s.new_targets.iter().all(|t| t.is_finite()));
    }

    #[test]
    fn degenerate_relevance_is_an_error() {
        let (x, y) = data();
        let rows = super::super::data::all_rows(40);
        let p = SmognParams {
            relevance: vec![(-10.0, 1.0), (10.0, 1.0)],
            threshold: 0.5,
            k: 5,
            perturbation: 0.02,
            seed: 0,
        };
        assert!(matches!(
            smogn(&x, &y, &rows, &p, &Budget::unlimited()),
            Err(SmognError::Degenerate { rare: 40, n: 40 })
        ));
    }
}
