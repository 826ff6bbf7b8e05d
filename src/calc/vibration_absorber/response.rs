//! The analyses of spec §3.D on a state space: eigenvalues and stability, frequency response by
//! complex LU, the exact time response by matrix-exponential stepping of an augmented autonomous
//! system (exosystem), and exact step metrics with a refined settling time.

use nalgebra::{Complex, DMatrix, DVector};

use super::error::VibrationAbsorberError as Error;
use crate::numerics::linalg::{eigenvalues, expm};
use crate::numerics::roots::bisect;
use crate::numerics::{Budget, par_map_while};

/// Relative distance `|jω − λ| / max(|λ|max, ω)` below which `jωI − A` is treated as singular.
pub const SINGULAR_REL: f64 = 1e-11;
/// Stability threshold on max Re λ relative to max |λ| (spec §3.D.2).
pub const STABILITY_REL: f64 = 1e-9;
/// Re-anchor period of long time responses \[steps\] (spec §3.D.4).
pub const REANCHOR_EVERY: usize = 10_000;
/// Horizons longer than this many steps are re-anchored.
pub const REANCHOR_ABOVE: usize = 100_000;
/// Settling band (2 %).
pub const SETTLING_BAND: f64 = 0.02;
/// Samples of the dense settling scan (spec: ≥ 5000).
pub const SETTLING_SAMPLES: usize = 5000;

/// Stability label.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stab {
    /// max Re λ < −1e-9·max|λ|.
    Stable,
    /// |max Re λ| ≤ 1e-9·max|λ|.
    Marginal,
    /// otherwise.
    Unstable,
}

/// Eigen-analysis result.
#[derive(Debug, Clone)]
pub struct Eigen {
    /// All eigenvalues.
    pub values: Vec<Complex<f64>>,
    /// max Re λ [1/s].
    pub max_re: f64,
    /// Label.
    pub stability: Stab,
}

/// Eigenvalues and stability label of `a`.
///
/// # Errors
/// [`Error::EigenNotConverged`] when the Schur iteration fails.
pub fn eigen(a: &DMatrix<f64>) -> Result<Eigen, Error> {
    let values = eigenvalues(a).ok_or(Error::EigenNotConverged { size: a.nrows() })?;
    let max_re = values
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max);
    let max_abs = values.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let tol = STABILITY_REL * max_abs;
    let stability = if max_re < -tol {
        Stab::Stable
    } else if max_re.abs() <= tol {
        Stab::Marginal
    } else {
        Stab::Unstable
    };
    Ok(Eigen {
        values,
        max_re,
        stability,
    })
}

/// `C (jωI − A)⁻¹ B` for each output row at each ω [rad/s]; `None` where `jω` is (numerically)
/// an eigenvalue. Result indexed `[frequency][row]`. Stops with `None` rows when the budget
/// runs out (the caller checks).
pub fn frequency_response(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    rows: &[DVector<f64>],
    omegas: &[f64],
    eig: &[Complex<f64>],
    budget: &Budget,
) -> Result<Vec<Vec<Option<Complex<f64>>>>, Error> {
    let n = a.nrows();
    let max_abs = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let ac: DMatrix<Complex<f64>> = a.map(|x| Complex::new(-x, 0.0));
    let bc: DVector<Complex<f64>> = b.map(|x| Complex::new(x, 0.0));
    let total = omegas.len();
    let out = par_map_while(budget.threads(), omegas, |i, &w| {
        if budget.expired() || budget.cancelled() {
            return None;
        }
        if i % 64 == 0 {
            budget.progress(i as f64 / total as f64, None);
        }
        let jw = Complex::new(0.0, w);
        let near = eig
            .iter()
            .map(|l| (jw - l).norm())
            .fold(f64::INFINITY, f64::min);
        if near <= SINGULAR_REL * max_abs.max(w) {
            return Some(vec![None; rows.len()]);
        }
        let mut m = ac.clone();
        for k in 0..n {
            m[(k, k)] += jw;
        }
        let x = m.lu().solve(&bc);
        Some(
            rows.iter()
                .map(|c| {
                    let x = x.as_ref()?;
                    let h: Complex<f64> = c.iter().zip(x.iter()).map(|(ci, xi)| xi * *ci).sum();
                    (h.re.is_finite() && h.im.is_finite()).then_some(h)
                })
                .collect(),
        )
    });
    let done = out.iter().filter(|r| r.is_some()).count();
    if done < total {
        return Err(Error::Deadline {
            stage: "frequency response",
            done: done as u64,
            total: total as u64,
        });
    }
    Ok(out.into_iter().flatten().collect())
}

/// Reductions (and optional series) of an exact time response.
#[derive(Debug, Clone, Default)]
pub struct TimeSeries {
    /// max |y| per row.
    pub max_abs: Vec<f64>,
    /// max |y| per row over samples `k ≥ last_from`.
    pub max_last: Vec<f64>,
    /// RMS per row.
    pub rms: Vec<f64>,
    /// Kept samples per row (every `decimate`-th), when asked.
    pub series: Option<Vec<Vec<f64>>>,
    /// Kept sample times \[s\].
    pub t: Option<Vec<f64>>,
    /// Matrix exponentials evaluated.
    pub expms: u64,
}

/// The autonomous augmented system of spec §3.D.4 and what to sample.
#[derive(Debug, Clone)]
pub struct Stepper<'a> {
    /// `A_aug`.
    pub a: &'a DMatrix<f64>,
    /// `s_aug(0)`.
    pub s0: &'a DVector<f64>,
    /// Output rows (length of `A_aug`).
    pub rows: &'a [DVector<f64>],
    /// Steps K (samples K + 1).
    pub steps: usize,
    /// Output step h \[s\].
    pub dt: f64,
    /// First sample of the "last period" window.
    pub last_from: usize,
    /// Keep every k-th sample (None: no series).
    pub decimate: Option<usize>,
}

impl Stepper<'_> {
    /// `s_{k+1} = Φ s_k` with `Φ = expm(A_aug h)`, re-anchored with `expm(A_aug t_k) s(0)` every
    /// [`REANCHOR_EVERY`] steps beyond [`REANCHOR_ABOVE`] steps. Exact for any h up to round-off.
    ///
    /// # Errors
    /// [`Error::NonFinite`] when Φ or the state overflows; [`Error::Deadline`] when the budget
    /// runs out (checked every 1024 steps).
    pub fn run(&self, budget: &Budget) -> Result<TimeSeries, Error> {
        let phi = expm(&(self.a * self.dt)).ok_or_else(|| Error::NonFinite {
            stage: "transition matrix expm(A h)",
            detail: format!("‖A h‖ = {:.3e}", (self.a * self.dt).abs().max()),
        })?;
        let nr = self.rows.len();
        let mut ts = TimeSeries {
            max_abs: vec![0.0; nr],
            max_last: vec![0.0; nr],
            rms: vec![0.0; nr],
            expms: 1,
            ..TimeSeries::default()
        };
        let keep = self.decimate.map(|d| d.max(1));
        let mut series: Option<Vec<Vec<f64>>> =
            keep.map(|d| vec![Vec::with_capacity(self.steps / d + 1); nr]);
        let mut times = keep.map(|d| Vec::with_capacity(self.steps / d + 1));
        let mut s = self.s0.clone();
        let mut next = s.clone();
        let reanchor = self.steps > REANCHOR_ABOVE;
        let mut sumsq = vec![0.0; nr];
        for k in 0..=self.steps {
            if k > 0 {
                if reanchor && k % REANCHOR_EVERY == 0 {
                    let t = k as f64 * self.dt;
                    let e = expm(&(self.a * t)).ok_or_else(|| Error::NonFinite {
                        stage: "re-anchoring expm(A t)",
                        detail: format!("t = {t} s"),
                    })?;
                    ts.expms += 1;
                    s = e * self.s0;
                } else {
                    next.gemv(1.0, &phi, &s, 0.0);
                    std::mem::swap(&mut s, &mut next);
                }
                if k % 1024 == 0 {
                    if budget.check(ts.expms).is_some() {
                        return Err(Error::Deadline {
                            stage: "time response",
                            done: k as u64,
                            total: self.steps as u64,
                        });
                    }
                    budget.progress(k as f64 / self.steps as f64, None);
                    if !s.iter().all(|x| x.is_finite()) {
                        return Err(Error::NonFinite {
                            stage: "time response",
                            detail: format!("state overflowed at t = {} s", k as f64 * self.dt),
                        });
                    }
                }
            }
            for (j, c) in self.rows.iter().enumerate() {
                let y = c.dot(&s);
                let ay = y.abs();
                ts.max_abs[j] = ts.max_abs[j].max(ay);
                if k >= self.last_from {
                    ts.max_last[j] = ts.max_last[j].max(ay);
                }
                sumsq[j] += y * y;
                if let (Some(ser), Some(d)) = (series.as_mut(), keep)
                    && k % d == 0
                {
                    ser[j].push(y);
                }
            }
            if let (Some(t), Some(d)) = (times.as_mut(), keep)
                && k % d == 0
            {
                t.push(k as f64 * self.dt);
            }
        }
        let count = (self.steps + 1) as f64;
        ts.rms = sumsq.iter().map(|s| (s / count).sqrt()).collect();
        ts.series = series;
        ts.t = times;
        let all = ts.max_abs.iter().chain(&ts.rms);
        if !all.clone().all(|x| x.is_finite()) {
            return Err(Error::NonFinite {
                stage: "time response",
                detail: "the response overflowed".to_owned(),
            });
        }
        Ok(ts)
    }
}

/// Exact step metrics of one single-input system.
#[derive(Debug, Clone, PartialEq)]
pub struct StepMetrics {
    /// 2 % settling time \[s\], `None` when the response does not settle.
    pub settling: Option<f64>,
    /// Overshoot [%].
    pub overshoot_pct: f64,
    /// DC gain (`None` when infinite).
    pub dc: Option<f64>,
    /// Samples `(t, y)` when asked.
    pub series: Option<(Vec<f64>, Vec<f64>)>,
    /// Matrix exponentials evaluated (one for the transition matrix, one per refinement step).
    pub expms: u64,
}

/// Step response `y = c·x` of `ẋ = A x + b·1(t)`, `x(0) = 0`, computed exactly (augmented
/// matrix exponential) on [`SETTLING_SAMPLES`] samples over `[0, 10/min|Re λ|]`; the last exit
/// from the 2 % band is refined by bisection on the exact response between two samples.
#[must_use]
pub fn step_metrics(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    c: &DVector<f64>,
    dc: Option<f64>,
    keep_series: bool,
) -> StepMetrics {
    let n = a.nrows();
    let mut aug = DMatrix::zeros(n + 1, n + 1);
    aug.view_mut((0, 0), (n, n)).copy_from(a);
    aug.view_mut((0, n), (n, 1)).copy_from(b);
    let mut s0 = DVector::zeros(n + 1);
    s0[n] = 1.0;
    let mut caug = DVector::zeros(n + 1);
    caug.rows_mut(0, n).copy_from(c);
    let eig = eigenvalues(a).unwrap_or_default();
    let slowest = eig.iter().map(|z| z.re.abs()).fold(f64::INFINITY, f64::min);
    let fastest = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let decays = eig.iter().all(|z| z.re < 0.0) && slowest > STABILITY_REL * fastest;
    let horizon = if decays && slowest.is_finite() {
        10.0 / slowest
    } else {
        10.0
    };
    let h = horizon / SETTLING_SAMPLES as f64;
    let none = StepMetrics {
        settling: None,
        overshoot_pct: 0.0,
        dc,
        series: None,
        expms: 1,
    };
    let Some(phi) = expm(&(&aug * h)) else {
        return none;
    };
    let mut states = Vec::with_capacity(SETTLING_SAMPLES + 1);
    let mut s = s0;
    for _ in 0..=SETTLING_SAMPLES {
        let next = &phi * &s;
        states.push(std::mem::replace(&mut s, next));
    }
    let ys: Vec<f64> = states.iter().map(|s| caug.dot(s)).collect();
    let series = keep_series.then(|| ((0..ys.len()).map(|k| k as f64 * h).collect(), ys.clone()));
    let Some(yinf) = dc.filter(|d| *d != 0.0 && d.is_finite()) else {
        return StepMetrics { series, ..none };
    };
    let sgn = yinf.signum();
    let peak = ys.iter().map(|y| y * sgn).fold(f64::NEG_INFINITY, f64::max);
    let overshoot_pct = ((peak - yinf.abs()) / yinf.abs() * 100.0).max(0.0);
    let band = SETTLING_BAND * yinf.abs();
    let last_out = ys.iter().rposition(|y| (y - yinf).abs() > band);
    let mut expms = 1;
    let settling = match last_out {
        Some(k) if decays && k + 1 < ys.len() => {
            let sk = &states[k];
            let g = |tau: f64| {
                expms += 1;
                expm(&(&aug * tau)).map_or(f64::NAN, |e| (caug.dot(&(e * sk)) - yinf).abs() - band)
            };
            bisect(g, 0.0, h).map(|tau| k as f64 * h + tau)
        }
        Some(_) => None,
        None => Some(0.0),
    };
    StepMetrics {
        settling,
        overshoot_pct,
        dc: Some(yinf),
        series,
        expms,
    }
}
