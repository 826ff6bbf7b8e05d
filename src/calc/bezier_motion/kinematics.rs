//! Kinematic peaks and checks of a Bezier law (spec §3.9): dense sampling, then refinement of the
//! best sample on its two neighbouring intervals to |Δλ| < 1e-12 (Newton on the next-derivative
//! polygon where the slope changes sign across them, golden section otherwise).
//!
//! The dense sampling only chooses the bracket: up to degree [`POWER_BASIS_MAX`] it runs on the
//! power-basis form about the nearer end (Horner, a few flops per sample, relative round-off
//! ≤ ~2^N ε), above it by the O(N) nested Bernstein form about the nearer end (de Casteljau costs
//! O(N²) per sample); the chosen sample and every refinement step
//! are evaluated by de Casteljau, so the returned values are de Casteljau's. One sampling of φ'
//! serves both the peak |φ'| and the least velocity.

use super::law::{BezierLaw, binomial, de_casteljau, de_casteljau_slope};

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

/// The sample positions λ_k = k/last, k = 0..=last, of a dense sampling of `samples` points (one
/// table serves φ', φ'' and φ''').
fn positions(samples: usize) -> Vec<f64> {
    let last = samples.max(2) - 1;
    let lf = last as f64;
    (0..=last).map(|k| k as f64 / lf).collect()
}

/// The first largest of a stream of values offered in index order (NaN never wins).
#[derive(Debug, Clone, Copy)]
struct FirstMax {
    k: usize,
    top: f64,
}

impl FirstMax {
    const EMPTY: Self = Self {
        k: 0,
        top: f64::NEG_INFINITY,
    };

    fn offer(&mut self, k: usize, v: f64) {
        if v > self.top {
            self.top = v;
            self.k = k;
        }
    }
}

/// The brackets of a dense sampling of the Bezier polynomial `f` with ordinates `c` at `xs`
/// (from [`positions`]): the index of the first largest `|f|`, and with `signed = Some(s)` also
/// of the first largest `s·f` (0 when not asked). The samples are never stored.
fn scan(c: &[f64], xs: &[f64], signed: Option<f64>) -> (usize, usize) {
    let mut abs = FirstMax::EMPTY;
    let mut sgn = FirstMax::EMPTY;
    match signed {
        Some(s) => for_each_sample(c, xs, |k, f| {
            abs.offer(k, f.abs());
            sgn.offer(k, s * f);
        }),
        None => for_each_sample(c, xs, |k, f| abs.offer(k, f.abs())),
    }
    (abs.k, sgn.k)
}

/// Hands `visit(k, f(xs[k]))` for every sample in index order, `f` the Bezier polynomial with
/// ordinates `c`: up to degree [`POWER_BASIS_MAX`] evaluated on the power basis about the nearer
/// end, eight points at a time, above it by the O(n) nested Bernstein form (see the module docs).
fn for_each_sample(c: &[f64], xs: &[f64], mut visit: impl FnMut(usize, f64)) {
    let last = xs.len().saturating_sub(1);
    let n = c.len().saturating_sub(1);
    if c.is_empty() {
        for k in 0..xs.len() {
            visit(k, 0.0);
        }
        return;
    }
    if n > POWER_BASIS_MAX {
        // The nested Bernstein form about the nearer end, O(n) per sample:
        // f = (1−λ)^n Σ C(n,i) c_i s^i with s = λ/(1−λ) ≤ 1 for λ ≤ ½ (mirrored above), whose
        // terms are bounded by the Bernstein terms themselves (round-off ~n ε of Σ|c_i| B_i,
        // de Casteljau's own order), where de Casteljau costs O(n²) per sample.
        let scaled = |rev: bool| -> Vec<f64> {
            (0..=n)
                .map(|i| binomial(n, i) * if rev { c[n - i] } else { c[i] })
                .collect()
        };
        let (fwd, bwd) = (scaled(false), scaled(true));
        let nn = i32::try_from(n).unwrap_or(i32::MAX);
        for (k, &x) in xs.iter().enumerate() {
            let (s, base, a) = if x <= 0.5 {
                (x / (1.0 - x), 1.0 - x, &fwd)
            } else {
                ((1.0 - x) / x, x, &bwd)
            };
            let acc = a.iter().rev().fold(0.0, |acc, &ai| acc * s + ai);
            visit(k, acc * base.powi(nn));
        }
        return;
    }
    // Power basis about the nearer end: a_j = C(n, j)·Δ^j c_0 in λ for λ ≤ ½, the same of the
    // reversed polygon in 1 − λ above (each term then ≤ C(n, j)·max|c|: round-off ~2^n ε).
    let mut lo = [0.0; POWER_BASIS_MAX + 1];
    let mut hi = [0.0; POWER_BASIS_MAX + 1];
    power_basis(c.iter().copied(), &mut lo[..=n]);
    power_basis(c.iter().rev().copied(), &mut hi[..=n]);
    let mid = last / 2 + 1;
    horner_at(&lo[..=n], 0..mid, |k| xs[k], &mut visit);
    horner_at(&hi[..=n], mid..last + 1, |k| xs[last - k], &mut visit);
}

/// Hands `visit(k, Σ a_j x(k)^j)` for every `k` of `range` in order, by Horner eight points at a
/// time (independent lanes the compiler vectorises).
fn horner_at(
    a: &[f64],
    range: std::ops::Range<usize>,
    x_of: impl Fn(usize) -> f64,
    visit: &mut impl FnMut(usize, f64),
) {
    const LANES: usize = 8;
    let top = a.last().copied().unwrap_or(0.0);
    let mut k0 = range.start;
    while k0 < range.end {
        let len = (range.end - k0).min(LANES);
        let mut x = [0.0; LANES];
        for (l, x) in x.iter_mut().enumerate().take(len) {
            *x = x_of(k0 + l);
        }
        let mut acc = [top; LANES];
        for &aj in a.iter().rev().skip(1) {
            for (acc, x) in acc.iter_mut().zip(&x) {
                *acc = *acc * x + aj;
            }
        }
        for (l, &f) in acc.iter().enumerate().take(len) {
            visit(k0 + l, f);
        }
        k0 += len;
    }
}

/// Power-basis coefficients `a_j = C(n, j)·Δ^j c_0` of the Bezier polynomial with ordinates
/// `c` (`a.len()` of them, n = `a.len()` − 1 ≤ [`POWER_BASIS_MAX`]).
fn power_basis(c: impl Iterator<Item = f64>, a: &mut [f64]) {
    let n = a.len() - 1;
    let mut d = [0.0; POWER_BASIS_MAX + 1];
    for (d, c) in d.iter_mut().zip(c) {
        *d = c;
    }
    let mut binom = 1.0;
    for (j, aj) in a.iter_mut().enumerate() {
        *aj = binom * d[0];
        for i in 0..n - j {
            d[i] = d[i + 1] - d[i];
        }
        binom = binom * (n - j) as f64 / (j + 1) as f64;
    }
}

/// What [`maximise`] maximises of the Bezier polynomial `f`: `|f|`, or `s·f`.
#[derive(Debug, Clone, Copy)]
enum Goal {
    Abs,
    Signed(f64),
}

/// First differences of a polygon (the derivative polygon up to the factor n/T).
fn differences(c: &[f64]) -> Vec<f64> {
    c.windows(2).map(|w| w[1] - w[0]).collect()
}

/// `(λ*, g(λ*))` maximising `g` = |f| or s·f over [0, 1], `f` the Bezier polynomial with
/// ordinates `c`: the best sample `best_k` of a dense sampling at `xs` (from [`scan`]) chooses
/// the bracket, its two neighbouring intervals; where the slope of `g` changes sign across the bracket the critical
/// point is found by safeguarded Newton on the next-derivative polygon (spec §3.9), otherwise
/// (a peak at an end, or a flat stretch) by golden section, both to |Δλ| < 1e-12. Every value
/// returned is de Casteljau's.
fn maximise(c: &[f64], goal: Goal, xs: &[f64], best_k: usize) -> (f64, f64) {
    let of = |f: f64| match goal {
        Goal::Abs => f.abs(),
        Goal::Signed(s) => s * f,
    };
    let g = |l: f64| of(de_casteljau(c, l));
    let last = xs.len().max(2) - 1;
    let best_k = best_k.min(last);
    let lam_k = xs[best_k];
    let f_k = de_casteljau(c, lam_k);
    let mut best = of(f_k);
    let a = xs[best_k.saturating_sub(1)];
    let b = xs[(best_k + 1).min(last)];
    let refined = if c.len() >= 3 {
        let sigma = match goal {
            Goal::Abs if f_k < 0.0 => -1.0,
            Goal::Abs => 1.0,
            Goal::Signed(s) => s,
        };
        let d1 = differences(c);
        let (slope_a, slope_b) = (sigma * de_casteljau(&d1, a), sigma * de_casteljau(&d1, b));
        if slope_a > 0.0 && slope_b < 0.0 {
            // Slope and curvature (up to the common factor n/T) from one pass over the slope's
            // polygon; Newton starts from the secant root of the slope across the bracket.
            let slope_curvature = |l: f64| {
                let (s1, s2) = de_casteljau_slope(&d1, l);
                (sigma * s1, sigma * s2)
            };
            let start = a + (b - a) * (slope_a / (slope_a - slope_b));
            [newton_peak(slope_curvature, (a, b), start), f64::NAN]
        } else if best_k == 0 && sigma_polygon_sign(&d1, sigma, b, true) {
            // g falls on all of [0, b] (convex hull of the slope's polygon there): the peak is λ = 0.
            [0.0, f64::NAN]
        } else if best_k == last && sigma_polygon_sign(&d1, -sigma, a, false) {
            [1.0, f64::NAN]
        } else {
            golden(&g, a, b)
        }
    } else {
        golden(&g, a, b)
    };
    // The candidates (a NaN slot is no candidate: it never compares greater).
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

/// The root of the slope in (a, b) (positive at a, negative at b) by Newton steps from `start`,
/// with bisection where a step leaves the bracket or the curvature is not negative;
/// `slope_curvature(λ)` gives both.
fn newton_peak(
    slope_curvature: impl Fn(f64) -> (f64, f64),
    (mut lo, mut hi): (f64, f64),
    start: f64,
) -> f64 {
    let mut x = if start > lo && start < hi {
        start
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..200 {
        let (s1, s2) = slope_curvature(x);
        if s1 == 0.0 {
            break;
        }
        if s1 > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
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
    x
}

/// Golden-section search for the maximum of `g` on [a, b] to width 1e-12; returns the last two
/// interior points.
fn golden(g: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> [f64; 2] {
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
    [c, d]
}

/// Peaks and checks of `law`: three dense scans (φ', φ'', φ''' at 64(N+1)+1 points, O(N) each
/// on the power basis, nothing stored) and four refinements by de Casteljau.
#[must_use]
pub fn kinematics(law: &BezierLaw) -> Kinematics {
    let xs = positions(samples(law));
    let t = law.t;
    let peak = |c: &[f64], best_k: usize| {
        let (lam, v) = maximise(c, Goal::Abs, &xs, best_k);
        (v, lam * t)
    };
    let sign = direction(law);
    let (v_abs, v_min) = scan(&law.v, &xs, Some(-sign));
    let peak_velocity = peak(&law.v, v_abs);
    let min_velocity = min_velocity(law, sign, &xs, v_min);
    let hull = |c: &[f64]| c.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    Kinematics {
        peak_velocity,
        peak_accel: peak(&law.a, scan(&law.a, &xs, None).0),
        peak_jerk: peak(&law.j, scan(&law.j, &xs, None).0),
        min_velocity,
        motion_reversal: min_velocity.0 < -REVERSAL_REL * peak_velocity.0,
        hull: [hull(&law.v), hull(&law.a), hull(&law.j)],
    }
}

/// The direction of the move: −1 when Phi < 0, else +1.
fn direction(law: &BezierLaw) -> f64 {
    if law.s.last().copied().unwrap_or(1.0) < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Dense samples of spec §3.9: 64(N+1)+1 points.
fn samples(law: &BezierLaw) -> usize {
    64 * (law.accel_degree() + 1) + 1
}

/// `(min sign·φ', t)` refined from the sample `best_k` of φ' at `xs` that maximises −sign·φ'
/// (the bracket); exactly 0 at the ends.
fn min_velocity(law: &BezierLaw, sign: f64, xs: &[f64], best_k: usize) -> (f64, f64) {
    let (lam, v) = maximise(&law.v, Goal::Signed(-sign), xs, best_k);
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
    let sign = direction(law);
    let xs = positions(samples(law));
    let (v_abs, v_min) = scan(&law.v, &xs, Some(-sign));
    let (minv, _) = min_velocity(law, sign, &xs, v_min);
    let (peak, _) = maximise(&law.v, Goal::Abs, &xs, v_abs);
    minv < -REVERSAL_REL * peak
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dense samples themselves (what [`scan`] looks at).
    fn sampled(c: &[f64], samples: usize) -> Vec<f64> {
        let mut out = vec![f64::NAN; samples.max(2)];
        for_each_sample(c, &positions(samples), |k, f| out[k] = f);
        out
    }

    /// [`maximise`] with the bracket chosen from `values` as [`scan`] chooses it.
    fn maximise_on(c: &[f64], goal: Goal, values: &[f64]) -> (f64, f64) {
        let xs = positions(values.len());
        let mut best = FirstMax::EMPTY;
        for (k, v) in values.iter().enumerate() {
            best.offer(
                k,
                match goal {
                    Goal::Abs => v.abs(),
                    Goal::Signed(s) => s * v,
                },
            );
        }
        maximise(c, goal, &xs, best.k)
    }

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

    /// The fused scan picks the first largest |f| and s·f of the stored samples, on both sides
    /// of the power-basis limit.
    #[test]
    fn scan_brackets_are_the_first_maxima_of_the_samples() {
        for len in 1..=POWER_BASIS_MAX + 4 {
            for seed in 0..20 {
                let c = polygon(len, 500 + seed);
                let samples = 64 * len + 1;
                let values = sampled(&c, samples);
                let xs = positions(samples);
                for s in [1.0, -1.0] {
                    let (abs_k, sgn_k) = scan(&c, &xs, Some(s));
                    let first = |f: &dyn Fn(f64) -> f64| {
                        let top = values
                            .iter()
                            .map(|&v| f(v))
                            .fold(f64::NEG_INFINITY, f64::max);
                        values.iter().position(|&v| f(v) >= top)
                    };
                    assert_eq!(
                        Some(abs_k),
                        first(&|v: f64| v.abs()),
                        "len {len} seed {seed}"
                    );
                    assert_eq!(Some(sgn_k), first(&|v: f64| s * v), "len {len} seed {seed}");
                    assert_eq!(scan(&c, &xs, None).0, abs_k);
                }
            }
        }
    }

    #[test]
    fn peaks_are_de_casteljau_values_at_their_refined_times() {
        for seed in 0..50 {
            let c = polygon(8, seed);
            let values = sampled(&c, 449);
            let (lam, v) = maximise_on(&c, Goal::Abs, &values);
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
                let (lam, v) = maximise_on(&c, Goal::Abs, &values);
                let g = |l: f64| de_casteljau(&c, l).abs();
                let lf = (values.len() - 1) as f64;
                let k = (lam * lf).round();
                let (a, b) = (((k - 1.0) / lf).max(0.0), ((k + 1.0) / lf).min(1.0));
                let gold = golden(&g, a, b);
                let vg = gold.iter().map(|&l| g(l)).fold(g(k / lf), f64::max);
                assert!((v - vg).abs() <= 1e-14 * scale, "{v} vs golden {vg}");
                // Golden section keeps the largest of many values that are flat to round-off
                // near the peak, so it may beat the value at the exact critical point by
                // de Casteljau's rounding (≤ ~2n ε of the scale), never by more.
                let rounding = 2.0 * len as f64 * f64::EPSILON * scale;
                assert!(
                    v >= vg - rounding,
                    "len {len} seed {seed}: {v} vs golden {vg} (λ {lam}, scale {scale})"
                );
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
