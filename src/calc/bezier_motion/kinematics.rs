//! Kinematic peaks and checks of a Bezier law (spec §3.9): dense sampling, then golden-section
//! refinement of the best sample on its two neighbouring intervals to |Δλ| < 1e-12.

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

/// `(λ*, g(λ*))` maximising `g` over [0, 1]: sampled at `samples` points, refined by golden
/// section on the best sample's two neighbouring intervals.
fn maximise(g: impl Fn(f64) -> f64, samples: usize) -> (f64, f64) {
    let last = samples.max(2) - 1;
    let lf = last as f64;
    let (mut best_k, mut best) = (0, f64::NEG_INFINITY);
    for k in 0..=last {
        let v = g(k as f64 / lf);
        if v > best {
            best = v;
            best_k = k;
        }
    }
    let mut a = (best_k.saturating_sub(1)) as f64 / lf;
    let mut b = ((best_k + 1).min(last)) as f64 / lf;
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
    let mut lam = best_k as f64 / lf;
    for (l, v) in [(c, gc), (d, gd)] {
        if v > best {
            best = v;
            lam = l;
        }
    }
    (lam, best)
}

/// Peaks and checks of `law` (`O(64 N²)` evaluations of de Casteljau, plus the refinements).
#[must_use]
pub fn kinematics(law: &BezierLaw) -> Kinematics {
    let n = law.accel_degree();
    let samples = 64 * (n + 1) + 1;
    let t = law.t;
    let peak = |c: &[f64]| {
        let (lam, v) = maximise(|l| de_casteljau(c, l).abs(), samples);
        (v, lam * t)
    };
    let sign = if law.s.last().copied().unwrap_or(1.0) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let peak_velocity = peak(&law.v);
    let min_velocity = min_velocity(law, sign, samples);
    let hull = |c: &[f64]| c.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    Kinematics {
        peak_velocity,
        peak_accel: peak(&law.a),
        peak_jerk: peak(&law.j),
        min_velocity,
        motion_reversal: min_velocity.0 < -REVERSAL_REL * peak_velocity.0,
        hull: [hull(&law.v), hull(&law.a), hull(&law.j)],
    }
}

/// `(min sign·φ', t)`; exactly 0 at the ends.
fn min_velocity(law: &BezierLaw, sign: f64, samples: usize) -> (f64, f64) {
    let (lam, v) = maximise(|l| -sign * de_casteljau(&law.v, l), samples);
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
    let n = law.accel_degree();
    let sign = law.s.last().copied().unwrap_or(1.0).signum();
    let samples = 64 * (n + 1) + 1;
    let (minv, _) = min_velocity(law, sign, samples);
    let (peak, _) = maximise(|l| de_casteljau(&law.v, l).abs(), samples);
    minv < -REVERSAL_REL * peak
}
