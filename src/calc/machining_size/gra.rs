//! Grey relational analysis (paper eq. 2–4, spec §6): each series normalised by its mean (or
//! not), Δ_i(k) = |x_0(k) − x_i(k)| against the reference series x_0, Δmin and Δmax over all
//! compared series, ζ_i(k) = (Δmin + ρΔmax)/(Δ_i(k) + ρΔmax), grade r_i = mean_k ζ_i(k).
//!
//! ζ is invariant to a common scale of all Δ, so the normalised series are divided by their
//! largest magnitude before differencing: no difference overflows whatever the data. When
//! Δmax = 0 every series equals the reference and every grade is 1 (hazard 8.7).

/// Normalisation of each series before comparison: the request's `gra.normalise`.
pub use super::wire::GraNormalise as Normalise;

/// Why GRA cannot be computed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GraError {
    /// A series has mean 0 (or one too small against its values to divide by).
    #[error(
        "series {series} has a mean of 0 (or too small against its values): use normalise \"none\""
    )]
    ZeroMean {
        /// Index of the series in the input (0 = the reference).
        series: usize,
    },
}

/// Mean of a series computed on x/max|x| (no overflow), with that scale.
fn scaled_mean(s: &[f64]) -> (f64, f64) {
    let m = s.iter().fold(0.0f64, |a, &v| a.max(v.abs()));
    if m == 0.0 {
        return (0.0, 1.0);
    }
    (
        s.iter().map(|&v| v / m).sum::<f64>() / s.len().max(1) as f64,
        m,
    )
}

/// Grades of `series[1..]` against the reference `series[0]` (all of one length, ≥ 1).
///
/// # Errors
/// [`GraError::ZeroMean`] when normalising by a zero mean.
pub fn grades(series: &[&[f64]], rho: f64, normalise: Normalise) -> Result<Vec<f64>, GraError> {
    let mut norm: Vec<Vec<f64>> = Vec::with_capacity(series.len());
    for (i, s) in series.iter().enumerate() {
        let v: Vec<f64> = match normalise {
            Normalise::None => s.to_vec(),
            Normalise::Mean => {
                let (mean, m) = scaled_mean(s);
                let v: Vec<f64> = s.iter().map(|&x| (x / m) / mean).collect();
                if mean == 0.0 || v.iter().any(|x| !x.is_finite()) {
                    return Err(GraError::ZeroMean { series: i });
                }
                v
            }
        };
        norm.push(v);
    }
    let scale = norm
        .iter()
        .flatten()
        .fold(0.0f64, |a, &v| a.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    let reference: Vec<f64> = norm[0].iter().map(|v| v / scale).collect();
    let deltas: Vec<Vec<f64>> = norm[1..]
        .iter()
        .map(|s| {
            s.iter()
                .zip(&reference)
                .map(|(v, r)| (r - v / scale).abs())
                .collect()
        })
        .collect();
    let (dmin, dmax) = deltas
        .iter()
        .flatten()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &d| {
            (lo.min(d), hi.max(d))
        });
    if dmax <= 0.0 {
        return Ok(vec![1.0; deltas.len()]);
    }
    Ok(deltas
        .iter()
        .map(|ds| {
            ds.iter()
                .map(|&d| (dmin + rho * dmax) / (d + rho * dmax))
                .sum::<f64>()
                / ds.len() as f64
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_series_compared_with_itself_has_grade_one() {
        let y = [1.0, 2.0, 4.0, 3.0];
        let a = [2.0, 1.0, 1.0, 5.0];
        let g = grades(&[&y, &y, &a], 0.5, Normalise::Mean).unwrap();
        assert!((g[0] - 1.0).abs() < 1e-15);
        assert!(g[1] > 0.0 && g[1] < 1.0);
    }

    #[test]
    fn hand_computed_grades() {
        // Normalise none, ρ = 0.5: Δ1 = [0, 1], Δ2 = [2, 0]; Δmin 0, Δmax 2.
        // ζ1 = [1, 1/2], ζ2 = [1/3, 1]: grades 0.75 and 2/3.
        let g = grades(
            &[&[1.0, 1.0], &[1.0, 2.0], &[3.0, 1.0]],
            0.5,
            Normalise::None,
        )
        .unwrap();
        assert!((g[0] - 0.75).abs() < 1e-15);
        assert!((g[1] - 2.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn zero_mean_is_an_error() {
        let e = grades(&[&[1.0, 2.0], &[-1.0, 1.0]], 0.5, Normalise::Mean).unwrap_err();
        assert_eq!(e, GraError::ZeroMean { series: 1 });
    }
}
