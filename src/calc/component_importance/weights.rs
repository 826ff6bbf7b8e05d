//! Variable weights, comprehensive importance and ranking (paper Eqs. 16–18, spec §3.9).

use std::cmp::Ordering;

/// Variable weights ω_b(i) and comprehensive importance CI_i of one component from its two
/// normalized indices `fp = [fp¹_i, fp²_i]` and the constant weights `wc = [ω_c¹, ω_c²]`.
///
/// Both indices positive: ω_b^u ∝ ω_c^u / fp^u ("inversely proportional to the index value", the
/// reading of the garbled Eq. 17 that reproduces Tables 7–8), so CI is the ω_c-weighted harmonic
/// mean 1/Σ_u(ω_c^u/fp^u). Evaluated as ω_b¹ = a/(a+b) with a = ω_c¹·fp², b = ω_c²·fp¹ (no
/// division by a small fp); if a and b underflow, in log space. Zero indices follow the limit
/// rule of §3.9 (spec §6 H5): all zero → ω_b = ω_c; some zero → the zero indices share the
/// weight in proportion to ω_c, the others get 0. CI = 0 whenever an index is 0.
#[must_use]
pub fn variable_weights(fp: [f64; 2], wc: [f64; 2]) -> ([f64; 2], f64) {
    match (fp[0] > 0.0, fp[1] > 0.0) {
        (false, false) => (wc, 0.0),
        (false, true) => ([1.0, 0.0], 0.0),
        (true, false) => ([0.0, 1.0], 0.0),
        (true, true) => {
            let a = wc[0] * fp[1];
            let b = wc[1] * fp[0];
            let w = if a >= f64::MIN_POSITIVE && b >= f64::MIN_POSITIVE {
                let s = a + b;
                [a / s, b / s]
            } else {
                let la = wc[0].ln() + fp[1].ln();
                let lb = wc[1].ln() + fp[0].ln();
                [1.0 / (1.0 + (lb - la).exp()), 1.0 / (1.0 + (la - lb).exp())]
            };
            let ci = w[0].mul_add(fp[0], w[1] * fp[1]);
            (w, ci)
        }
    }
}

/// Ranks (1 = most important) by descending CI; exactly equal values keep input order
/// (the paper ranks M = J = 0 as 9 and 10).
#[must_use]
pub fn rank_descending(ci: &[f64]) -> Vec<u32> {
    let mut order: Vec<usize> = (0..ci.len()).collect();
    order.sort_by(|&a, &b| {
        ci[b]
            .partial_cmp(&ci[a])
            .unwrap_or(Ordering::Equal)
            .then(a.cmp(&b))
    });
    let mut rank = vec![0u32; ci.len()];
    for (r, &i) in order.iter().enumerate() {
        rank[i] = u32::try_from(r + 1).unwrap_or(u32::MAX);
    }
    rank
}

/// Entropy weights of the two normalized index columns (spec §3.9):
/// p = fp/Σfp, e_u = −Σ p ln p / ln n (0·ln 0 = 0), d_u = 1 − e_u, ω = d/Σd.
/// A column that is all zero carries no information (e = 1). Returns `None` when Σd = 0
/// (both columns uniform or zero), where the weights are undefined.
#[must_use]
pub fn entropy_weights(fp1: &[f64], fp2: &[f64]) -> Option<[f64; 2]> {
    let n = fp1.len();
    if n < 2 {
        return None;
    }
    let ln_n = f64::from(u32::try_from(n).unwrap_or(u32::MAX)).ln();
    let d = |col: &[f64]| -> f64 {
        let total: f64 = col.iter().sum();
        if total <= 0.0 {
            return 0.0;
        }
        let h: f64 = col
            .iter()
            .filter(|&&x| x > 0.0)
            .map(|&x| {
                let p = x / total;
                -p * p.ln()
            })
            .sum();
        (1.0 - h / ln_n).max(0.0)
    };
    let (d1, d2) = (d(fp1), d(fp2));
    let s = d1 + d2;
    (s > 0.0).then(|| [d1 / s, d2 / s])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_mean() {
        let (w, ci) = variable_weights([0.2, 0.4], [0.5, 0.5]);
        assert!((w[0] - 2.0 / 3.0).abs() < 1e-15);
        assert!((ci - 1.0 / (0.5 / 0.2 + 0.5 / 0.4)).abs() < 1e-15);
        let (w, ci) = variable_weights([1e-320, 1e-321], [0.5, 0.5]);
        assert!((w[0] + w[1] - 1.0).abs() < 1e-12 && ci.is_finite() && ci > 0.0);
        assert_eq!(variable_weights([0.0, 0.3], [0.4, 0.6]), ([1.0, 0.0], 0.0));
    }

    #[test]
    fn ranks_with_ties() {
        assert_eq!(rank_descending(&[0.1, 0.0, 0.3, 0.0]), vec![2, 3, 1, 4]);
    }
}
