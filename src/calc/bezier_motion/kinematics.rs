//! Kinematic peaks and checks of a Bezier law (spec §3.9): dense sampling, then refinement of the
//! best sample on its two neighbouring intervals to |Δλ| < 1e-12 (Newton on the next-derivative
//! polygon where the slope changes sign across them, golden section otherwise).
//!
//! The dense sampling only chooses the bracket: up to degree [`POWER_BASIS_MAX`] it runs on the
//! power-basis form about the nearer end (Horner, a few flops per sample, relative round-off
//! ≤ ~2^N ε), above it by de Casteljau; the chosen sample and every refinement step
//! are evaluated by de Casteljau, so the returned values are de Casteljau's. One sampling of φ'
//! serves both the peak |φ'| and the least velocity.

use super::law::{BezierLaw, de_casteljau};

/// Refinement stops below this width in λ (spec §3.9).
const LAMBDA_TOL: f64 = 1e-12;
/// A velocity below `−REVERSAL_REL · peak` (against the direction of Phi) is a reversal (§3.7).
pub const REVERSAL_REL: f64 = 1e-9;

/// Peaks and checks of one law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Peak |φ'| [rad/s] and its time \[s\].
    pub peak_velocity: (f64, f64),
    /// Peak |φ''| [rad/s²] and its time \[s\].
    pub peak_accel: (f64, f64),
    /// Peak |φ'''| [rad/s³] and its time \[s\].
    pub peak_jerk: (f64, f64),
    /// Least velocity in the direction of Phi, `min sign(Phi)·φ'` [rad/s], and its time \[s\].
    pub min_velocity: (f64, f64),
    /// The motor reverses: `min sign(Phi)·φ' < −1e-9 · peak |φ'|`.
    pub motion_reversal: bool,
    /// Convex-hull bounds `max |V_i|`, `max |A_i|`, `max |J_i|` (≥ the true peaks).
    pub hull: [f64; 3],
}

/// Highest degree whose dense sampling runs on the power basis (about the nearer end: relative
/// round-off ≤ ~2^16 ε ≈ 1e-11, enough to choose a bracket).
pub const POWER_BASIS_MAX: usize = 16;

/// The Bezier polynomial with ordinates `c` at λ_k = k/last, k = 0..=last (for choosing a
/// bracket; see the module docs).
fn sampled(c: &[f64], samples: usize) -> Vec<f64> {
    let last = samples.max(2) - 1;
    let lf = last as f64;
    let n = c.len().saturating_sub(1);
    if c.is_empty() || n > POWER_BASIS_MAX {
        return (0..=last).map(|k| de_casteljau(c, k as f64 / lf)).collect();
    }
    // Power basis about the nearer end: a_j = C(n, j)·Δ^j c_0 in λ for λ ≤ ½, the same of the
    // reversed polygon in 1 − λ above (each term then ≤ C(n, j)·max|c|: round-off ~2^n ε).
    let rev: Vec<f64> = c.iter().rev().copied().collect();
    let (lo, hi) = (power_basis(c), power_basis(&rev));
    let mut out = vec![0.0; last + 1];
    let mid = last / 2 + 1;
    horner_at(&lo, |i| i as f64 / lf, &mut out[..mid]);
    horner_at(&hi, |i| (last - mid - i) as f64 / lf, &mut out[mid..]);
    out
}

/// `out[i] = Σ a_j x(i)^j` by Horner, eight points at a time (independent lanes the compiler
/// vectorises).
fn horner_at(a: &[f64], x_of: impl Fn(usize) -> f64, out: &mut [f64]) {
    const LANES: usize = 8;
    for (c, oc) in out.chunks_mut(LANES).enumerate() {
        let mut x = [0.0; LANES];
        for (l, x) in x.iter_mut().enumerate().take(oc.len()) {
            *x = x_of(c * LANES + l);
        }
        let top = a.last().copied().unwrap_or(0.0);
        let mut acc = [top; LANES];
        for &aj in a.iter().rev().skip(1) {
            for (acc, x) in acc.iter_mut().zip(&x) {
                *acc = *acc * x + aj;
            }
        }
        oc.copy_from_slice(&acc[..oc.len()]);
    }
}

/// Power-basis coefficients `a_j = C(n, j)·Δ^j c_0` of the Bezier polynomial with ordinates `c`.
fn power_basis(c: &[f64]) -> Vec<f64> {
    let n = c.len() - 1;
    let mut d = c.to_vec();
    let mut a = vec![0.0; n + 1];
    let mut binom = 1.0;
    for (j, aj) in a.iter_mut().enumerate() {
        *aj = binom * d[0];
        for i in 0..n - j {
            d[i] = d[i + 1] - d[i];
        }
        binom = binom * (n - j) as f64 / (j + 1) as f64;
    }
    a
}

/// What [`maximise`] maximises of the Bezier polynomial `f`: `|f|`, or `s·f`.
#[derive(Debug, Clone, Copy)]
enum Goal {
    Abs,
    Signed(f64),
}

/// Index of the first largest value (0 when empty or all NaN).
fn first_max(values: impl Iterator<Item = f64>) -> usize {
    let mut best_k = 0;
    let mut top = f64::NEG_INFINITY;
    for (k, v) in values.enumerate() {
        if v > top {
            top = v;
            best_k = k;
        }
    }
    best_k
}

/// First differences of a polygon (the derivative polygon up to the factor n/T).
fn differences(c: &[f64]) -> Vec<f64> {
    c.windows(2).map(|w| w[1] - w[0]).collect()
}

/// `(λ*, g(λ*))` maximising `g` = |f| or s·f over [0, 1], `f` the Bezier polynomial with
/// ordinates `c`: the best of `values` (≈ f at uniform samples) chooses the bracket, its two
/// neighbouring intervals; where the slope of `g` changes sign across the bracket the critical
/// point is found by safeguarded Newton on the next-derivative polygon (spec §3.9), otherwise
/// (a peak at an end, or a flat stretch) by golden section, both to |Δλ| < 1e-12. Every value
/// returned is de Casteljau's.
fn maximise(c: &[f64], goal: Goal, values: &[f64]) -> (f64, f64) {
    let g = |l: f64| {
        let f = de_casteljau(c, l);
        match goal {
            Goal::Abs => f.abs(),
            Goal::Signed(s) => s * f,
        }
    };
    let last = values.len().max(2) - 1;
    let lf = last as f64;
    let best_k = match goal {
        Goal::Abs => first_max(values.iter().map(|f| f.abs())),
        Goal::Signed(s) => first_max(values.iter().map(|f| s * f)),
    };
    let lam_k = best_k as f64 / lf;
    let mut best = g(lam_k);
    let a = (best_k.saturating_sub(1)) as f64 / lf;
    let b = ((best_k + 1).min(last)) as f64 / lf;
    let refined = if c.len() >= 3 {
        let sigma = match goal {
            Goal::Abs if de_casteljau(c, lam_k) < 0.0 => -1.0,
            Goal::Abs => 1.0,
            Goal::Signed(s) => s,
        };
        let d1 = differences(c);
        let slope = |l: f64| sigma * de_casteljau(&d1, l);
        if slope(a) > 0.0 && slope(b) < 0.0 {
            let d2 = differences(&d1);
            let curvature = |l: f64| sigma * (d1.len() - 1) as f64 * de_casteljau(&d2, l);
            newton_peak(slope, curvature, (a, b), lam_k)
        } else if best_k == 0 && sigma_polygon_sign(&d1, sigma, b, true) {
            // g falls on all of [0, b] (convex hull of the slope's polygon there): the peak is λ = 0.
            vec![0.0]
        } else if best_k == last && sigma_polygon_sign(&d1, -sigma, a, false) {
            vec![1.0]
        } else {
            golden(&g, a, b)
        }
    } else {
        golden(&g, a, b)
    };
    let mut lam = lam_k;
    for l in refined {
        let v = g(l);
        if v > best {
            best = v;
            lam = l;
        }
    }
    (lam, best)
}

/// Whether every ordinate of `s·d` restricted to [0, x] (`left`) or [x, 1] is ≤ 0, so that
/// `s·d` ≤ 0 there (the convex-hull property); the restriction by de Casteljau subdivision.
fn sigma_polygon_sign(d: &[f64], s: f64, x: f64, left: bool) -> bool {
    let n = d.len();
    let mut b = d.to_vec();
    let mut part = Vec::with_capacity(n);
    let mu = 1.0 - x;
    for r in 0..n {
        part.push(if left { b[0] } else { b[n - 1 - r] });
        for i in 0..n - 1 - r {
            b[i] = mu * b[i] + x * b[i + 1];
        }
    }
    part.iter().all(|p| s * p <= 0.0)
}

/// The root of `slope` in (a, b) (positive at a, negative at b) by Newton steps with bisection
/// where a step leaves the bracket or the curvature is not negative.
fn newton_peak(
    slope: impl Fn(f64) -> f64,
    curvature: impl Fn(f64) -> f64,
    (mut lo, mut hi): (f64, f64),
    start: f64,
) -> Vec<f64> {
    let mut x = if start > lo && start < hi {
        start
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..200 {
        let s1 = slope(x);
        if s1 == 0.0 {
            break;
        }
        if s1 > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let s2 = curvature(x);
        let mut nx = x - s1 / s2;
        if !(s2 < 0.0 && nx > lo && nx < hi) {
            nx = 0.5 * (lo + hi);
        }
        let done = (nx - x).abs() < LAMBDA_TOL || hi - lo < LAMBDA_TOL;
        x = nx;
        if done {
            break;
        }
    }
    vec![x]
}

/// Golden-section search for the maximum of `g` on [a, b] to width 1e-12; returns the last two
/// interior points.
fn golden(g: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> Vec<f64> {
    let r = 0.5 * (5.0_f64.sqrt() - 1.0);
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    while b - a > LAMBDA_TOL {
        if gc >= gd {
            b = d;
            d = c;
            gd = gc;
            c = b - r * (b - a);
            gc = g(c);
        } else {
            a = c;
            c = d;
            gc = gd;
            d = a + r * (b - a);
            gd = g(d);
        }
    }
    vec![c, d]
}

/// Peaks and checks of `law`: three dense samplings (φ', φ'', φ''' at 64(N+1)+1 points, O(N)
/// each on the power basis) and four refinements by de Casteljau.
#[must_use]
pub fn kinematics(law: &BezierLaw) -> Kinematics {
    let samples = samples(law);
    let t = law.t;
    let peak = |c: &[f64], values: &[f64]| {
        let (lam, v) = maximise(c, Goal::Abs, values);
        (v, lam * t)
    };
    let sign = if law.s.last().copied().unwrap_or(1.0) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let v_samples = sampled(&law.v, samples);
    let peak_velocity = peak(&law.v, &v_samples);
    let min_velocity = min_velocity(law, sign, &v_samples);
    let hull = |c: &[f64]| c.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    Kinematics {
        peak_velocity,
        peak_accel: peak(&law.a, &sampled(&law.a, samples)),
        peak_jerk: peak(&law.j, &sampled(&law.j, samples)),
        min_velocity,
        motion_reversal: min_velocity.0 < -REVERSAL_REL * peak_velocity.0,
        hull: [hull(&law.v), hull(&law.a), hull(&law.j)],
    }
}

/// Dense samples of spec §3.9: 64(N+1)+1 points.
fn samples(law: &BezierLaw) -> usize {
    64 * (law.accel_degree() + 1) + 1
}

/// `(min sign·φ', t)` from φ' sampled at the §3.9 points; exactly 0 at the ends.
fn min_velocity(law: &BezierLaw, sign: f64, v_samples: &[f64]) -> (f64, f64) {
    let (lam, v) = maximise(&law.v, Goal::Signed(-sign), v_samples);
    (-v, lam * law.t)
}

/// Whether the velocity polygon has an ordinate against the direction of Phi (the convex-hull
/// test: no such ordinate ⇒ no reversal; one ⇒ check the curve).
#[must_use]
pub fn polygon_against_motion(law: &BezierLaw) -> bool {
    let sign = law.s.last().copied().unwrap_or(1.0).signum();
    law.v.iter().any(|v| sign * v < 0.0)
}

/// Whether the curve itself reverses (cheap when the polygon is one-signed).
#[must_use]
pub fn reverses(law: &BezierLaw) -> bool {
    if !polygon_against_motion(law) {
        return false;
    }
    let sign = law.s.last().copied().unwrap_or(1.0).signum();
    let v_samples = sampled(&law.v, samples(law));
    let (minv, _) = min_velocity(law, sign, &v_samples);
    let (peak, _) = maximise(&law.v, Goal::Abs, &v_samples);
    minv < -REVERSAL_REL * peak
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random polygon of `len` ordinates in [−1, 1].
    fn polygon(len: usize, seed: u64) -> Vec<f64> {
        let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        (0..len)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    #[test]
    fn power_basis_samples_match_de_casteljau() {
        for len in 1..=POWER_BASIS_MAX + 3 {
            for seed in 0..20 {
                let c = polygon(len, seed);
                let scale = c.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
                let s = sampled(&c, 257);
                assert_eq!(s.len(), 257);
                for (k, v) in s.iter().enumerate() {
                    let exact = de_casteljau(&c, k as f64 / 256.0);
                    assert!(
                        (v - exact).abs() <= 1e-11 * scale,
                        "degree {}, sample {k}: {v} vs {exact}",
                        len - 1
                    );
                }
            }
        }
    }

    #[test]
    fn peaks_are_de_casteljau_values_at_their_refined_times() {
        for seed in 0..50 {
            let c = polygon(8, seed);
            let values = sampled(&c, 449);
            let (lam, v) = maximise(&c, Goal::Abs, &values);
            assert_eq!(v.to_bits(), de_casteljau(&c, lam).abs().to_bits());
            // No sample of the exact curve is above the refined peak.
            for k in 0..=448 {
                assert!(de_casteljau(&c, f64::from(k) / 448.0).abs() <= v);
            }
        }
    }

    /// Newton on the next-derivative polygon finds the same peaks as golden section on the
    /// values (its λ is the more accurate: golden section compares values that are flat to
    /// round-off near a peak, so its λ is good to ~sqrt(ε) only).
    #[test]
    fn newton_refinement_agrees_with_golden_section() {
        let mut newton_used = 0;
        for len in 3..=13 {
            for seed in 0..40 {
                let c = polygon(len, 1000 + seed);
                let scale = c.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
                let values = sampled(&c, 64 * len + 1);
                let (lam, v) = maximise(&c, Goal::Abs, &values);
                let g = |l: f64| de_casteljau(&c, l).abs();
                let lf = (values.len() - 1) as f64;
                let k = (lam * lf).round();
                let (a, b) = (((k - 1.0) / lf).max(0.0), ((k + 1.0) / lf).min(1.0));
                let gold = golden(&g, a, b);
                let vg = gold.iter().map(|&l| g(l)).fold(g(k / lf), f64::max);
                assert!((v - vg).abs() <= 1e-14 * scale, "{v} vs golden {vg}");
                assert!(v >= vg - 1e-15 * scale);
                let lg = gold[0];
                if (lam - k / lf).abs() > 0.0 && lam > 0.0 && lam < 1.0 {
                    newton_used += 1;
                    assert!((lam - lg).abs() <= 1e-6, "λ {lam} vs golden {lg}");
                }
            }
        }
        assert!(newton_used > 50, "interior peaks refined: {newton_used}");
    }
}
