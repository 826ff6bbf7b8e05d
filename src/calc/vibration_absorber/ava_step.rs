//! Fixed-base absorber step metrics `G_ec`, `G_err` (spec §3.B) on fixed-size matrices.
//!
//! Same method as [`step_metrics`](crate::calc::vibration_absorber::response::step_metrics) (kept there as the reference): the exact step
//! response of the 3-state absorber, augmented with a constant input state, sampled at
//! [`SETTLING_SAMPLES`] steps of `Φ = expm(A_aug h)` over `[0, 10/min|Re λ|]`, the last exit from
//! the 2 % band refined by bisection on the exact response between two samples. What changes is
//! the cost: 4 × 4 stack matrices (no allocation per step), one state sequence shared by both
//! transfer functions (they differ only in the output row), and the bisection steps the state
//! from the bracket's left end with one exponential per step size `h/2^j`
//! (`exp(A_aug·h/2^j)`, computed once per level and shared by both refinements) instead of one
//! exponential per bisection step.

use nalgebra::{SMatrix, SVector};

use crate::calc::vibration_absorber::model::{Device, Gains};
use crate::calc::vibration_absorber::response::{
    SETTLING_BAND, SETTLING_SAMPLES, STABILITY_REL, StepMetrics,
};
use crate::numerics::linalg::{eigenvalues, expm4};

type M4 = SMatrix<f64, 4, 4>;
type V4 = SVector<f64, 4>;

/// Bisection halvings at most (as `numerics::roots::bisect`).
const MAX_HALVINGS: usize = 200;

/// `exp(A_aug·h/2^j)` for `j = 1, 2, …`, computed on first use.
struct Levels {
    /// `A_aug h`.
    aug_h: M4,
    /// Cached levels (index `j − 1`); `None` inside when the exponential was not finite.
    cache: Vec<Option<M4>>,
    /// Exponentials evaluated.
    expms: u64,
}

impl Levels {
    fn get(&mut self, j: usize) -> Option<M4> {
        while self.cache.len() < j {
            let level = self.cache.len() + 1;
            self.expms += 1;
            let scale = 0.5_f64.powi(i32::try_from(level).unwrap_or(i32::MAX));
            self.cache.push(expm4(&(self.aug_h * scale)));
        }
        self.cache[j - 1]
    }
}

/// The sampled step response shared by both outputs.
struct Sampled {
    /// Sample spacing \[s\].
    h: f64,
    /// Whether every pole decays (a settling time exists).
    decays: bool,
    /// States `s_k`, `k = 0..=SETTLING_SAMPLES`.
    states: Vec<V4>,
}

/// Exact step metrics of `G_ec = X_a/E_c` and, with gains, `G_err = X_a/Err` (spec §3.B), as
/// [`step_metrics`](crate::calc::vibration_absorber::response::step_metrics) computes them one at a time.
#[must_use]
pub fn step_pair(
    dev: &Device,
    gains: Option<&Gains>,
    keep_series: bool,
) -> (StepMetrics, Option<StepMetrics>) {
    let (a, b) = dev.fixed_base();
    let dc_ec = (dev.ka > 0.0).then(|| dev.kc / (dev.ka * dev.r));
    let rows = (
        V4::new(1.0, 0.0, 0.0, 0.0),
        gains.map(|g| (V4::new(g.kp, g.kd, 0.0, 0.0), dc_ec.map(|d| d * g.kp))),
    );
    let eig = eigenvalues(&a).unwrap_or_default();
    let slowest = eig.iter().map(|z| z.re.abs()).fold(f64::INFINITY, f64::min);
    let fastest = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let decays = eig.iter().all(|z| z.re < 0.0) && slowest > STABILITY_REL * fastest;
    let horizon = if decays && slowest.is_finite() {
        10.0 / slowest
    } else {
        10.0
    };
    let h = horizon / SETTLING_SAMPLES as f64;
    let mut aug = M4::zeros();
    aug.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&a.fixed_view::<3, 3>(0, 0));
    aug.fixed_view_mut::<3, 1>(0, 3)
        .copy_from(&b.fixed_rows::<3>(0));
    let aug_h = aug * h;
    let none = |dc: Option<f64>, expms: u64| StepMetrics {
        settling: None,
        overshoot_pct: 0.0,
        dc,
        series: None,
        expms,
    };
    let Some(phi) = expm4(&aug_h) else {
        return (none(dc_ec, 1), rows.1.map(|(_, dc)| none(dc, 1)));
    };
    let mut states = Vec::with_capacity(SETTLING_SAMPLES + 1);
    let mut s = V4::new(0.0, 0.0, 0.0, 1.0);
    for _ in 0..=SETTLING_SAMPLES {
        let next = phi * s;
        states.push(std::mem::replace(&mut s, next));
    }
    let sampled = Sampled { h, decays, states };
    let mut levels = Levels {
        aug_h,
        cache: Vec::with_capacity(64),
        expms: 1,
    };
    let ec = metrics(&sampled, &rows.0, dc_ec, keep_series, &mut levels);
    let err = rows.1.map(|(c, dc)| {
        levels.expms = 0;
        metrics(&sampled, &c, dc, keep_series, &mut levels)
    });
    (ec, err)
}

/// Metrics of the output `y = c·s` of the sampled response.
fn metrics(
    sampled: &Sampled,
    c: &V4,
    dc: Option<f64>,
    keep_series: bool,
    levels: &mut Levels,
) -> StepMetrics {
    let h = sampled.h;
    let ys: Vec<f64> = sampled.states.iter().map(|s| c.dot(s)).collect();
    let series = keep_series.then(|| ((0..ys.len()).map(|k| k as f64 * h).collect(), ys.clone()));
    let Some(yinf) = dc.filter(|d| *d != 0.0 && d.is_finite()) else {
        return StepMetrics {
            settling: None,
            overshoot_pct: 0.0,
            dc,
            series,
            expms: levels.expms,
        };
    };
    let sgn = yinf.signum();
    let peak = ys.iter().map(|y| y * sgn).fold(f64::NEG_INFINITY, f64::max);
    let overshoot_pct = ((peak - yinf.abs()) / yinf.abs() * 100.0).max(0.0);
    let band = SETTLING_BAND * yinf.abs();
    let last_out = ys.iter().rposition(|y| (y - yinf).abs() > band);
    let settling = match last_out {
        Some(k) if sampled.decays && k + 1 < ys.len() => {
            let g = |s: &V4| (c.dot(s) - yinf).abs() - band;
            refine(sampled, k, g, levels).map(|tau| k as f64 * h + tau)
        }
        Some(_) => None,
        None => Some(0.0),
    };
    StepMetrics {
        settling,
        overshoot_pct,
        dc: Some(yinf),
        series,
        expms: levels.expms,
    }
}

/// The root of `g(s(t_k + τ))` in `τ ∈ [0, h]` by bisection to the last bit (the steps of
/// `numerics::roots::bisect`), the state at the bracket's left end carried along: the midpoint
/// of level `j` lies `h/2^j` after it. `None` without a sign change or with a non-finite level.
fn refine(sampled: &Sampled, k: usize, g: impl Fn(&V4) -> f64, levels: &mut Levels) -> Option<f64> {
    let (mut lo, mut hi) = (0.0, sampled.h);
    let mut s_lo = sampled.states[k];
    let mut flo = g(&s_lo);
    let fhi = g(&sampled.states[k + 1]);
    if flo == 0.0 {
        return Some(lo);
    }
    if fhi == 0.0 {
        return Some(hi);
    }
    if flo.signum() == fhi.signum() || !flo.is_finite() || !fhi.is_finite() {
        return None;
    }
    for j in 1..=MAX_HALVINGS {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let s_mid = levels.get(j)? * s_lo;
        let fm = g(&s_mid);
        if fm == 0.0 {
            return Some(mid);
        }
        if fm.signum() == flo.signum() {
            lo = mid;
            flo = fm;
            s_lo = s_mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}
