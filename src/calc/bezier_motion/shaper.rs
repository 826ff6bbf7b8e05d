//! The Bezier law beside the input shapers of industrial drives (ZV, ZVD, EI) on the same plant
//! and the same total move time (the `outputs.shaper_comparison` option).
//!
//! A shaper is a train of impulses `A_i` at times `t_i` convolved with a baseline move; with
//! `t_last` the last impulse time the baseline runs in `T0 = T − t_last`, so the shaped move ends
//! at `T`. Baselines: `trapezoid` (equal thirds, `φ'' = ±a0`, `a0 = 4.5 Phi/T0²`) and `cycloidal`
//! (`φ'' = (2π Phi/T0²) sin(2πt/T0)`). Definitions (`Td = 2π/ωd`, `K = exp(−ξπ/√(1−ξ²))`):
//! ZV `[1, K]/(1+K)` at `[0, Td/2]`; ZVD `[1, 2K, K²]/(1+K)²` at `[0, Td/2, Td]`; EI
//! `[(1+V)/4, (1−V)/2, (1+V)/4]` at `[0, Td/2, Td]`; none `[1]` at `[0]`.
//!
//! Everything is closed form, no ODE integrator: the baseline's end state `x0(T0)` from rest by
//! matrix exponentials of the plant augmented with its forcing (Van Loan: `[[Ac, b],[0, 0]]` over
//! each third of the trapezoid, `[[Ac, b e1ᵀ],[0, W]]` with the harmonic generator `W` over the
//! cycloid, which also covers resonance `ωd = 2π/T0` and ξ ≥ 1 of the stiffness sweep), then by
//! linearity and time invariance the shaped end state
//! `x(T) = Σ_i A_i e^{Ac (t_last − t_i)} x0(T0)` (the forcing is zero after each copy ends, so
//! every copy coasts freely for `T − t_i − T0 = t_last − t_i`). For ZV and ZVD the impulse sum
//! `Σ A_i e^{Ac(t_last − t_i)}` vanishes at the design stiffness (`e^{Ac Td/2} = −K I`), so the
//! residual energy is at round-off. Peaks are exact too: the shaped acceleration is piecewise
//! constant (trapezoid) or one sinusoid per interval between breakpoints (cycloidal), so its and
//! the velocity's extremes are at breakpoints or at the sinusoid's quarter-period points.

use std::f64::consts::{PI, TAU};

use nalgebra::DMatrix;

use super::plant::Plant;
use crate::numerics::linalg::expm;

/// Quarter-period points examined per interval of a cycloidal shaped move (an interval spans at
/// most one baseline period: 5 suffice).
const QUARTER_POINTS_MAX: u32 = 8;

/// An input shaper (impulse train) of the comparison: the request's shaper.
pub use super::wire::ShaperIn as Shaper;

/// The baseline move the shapers filter: the request's baseline.
pub use super::wire::BaselineIn as Baseline;

/// What the comparison computes.
#[derive(Debug, Clone, PartialEq)]
pub struct ShaperSpec {
    /// The baseline move.
    pub baseline: Baseline,
    /// The shapers, in request order.
    pub shapers: Vec<Shaper>,
    /// EI's tolerable residual vibration `V`.
    pub ei_tolerance: f64,
}

/// One impulse of a shaper.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impulse {
    /// Time \[s\].
    pub t: f64,
    /// Amplitude (the amplitudes of a shaper sum to 1).
    pub amplitude: f64,
}

/// The impulses of `shaper` designed for damped period `td` and `K = exp(−ξπ/√(1−ξ²))`.
#[must_use]
pub fn impulses(shaper: Shaper, td: f64, k: f64, v: f64) -> Vec<Impulse> {
    let at = |pairs: &[(f64, f64)]| {
        pairs
            .iter()
            .map(|&(t, amplitude)| Impulse { t, amplitude })
            .collect()
    };
    match shaper {
        Shaper::None => at(&[(0.0, 1.0)]),
        Shaper::Zv => {
            let s = 1.0 + k;
            at(&[(0.0, 1.0 / s), (0.5 * td, k / s)])
        }
        Shaper::Zvd => {
            let s = (1.0 + k) * (1.0 + k);
            at(&[(0.0, 1.0 / s), (0.5 * td, 2.0 * k / s), (td, k * k / s)])
        }
        Shaper::Ei => at(&[
            (0.0, 0.25 * (1.0 + v)),
            (0.5 * td, 0.5 * (1.0 - v)),
            (td, 0.25 * (1.0 + v)),
        ]),
    }
}

/// A shaped move: the baseline of duration `t0` and total rotation `phi`, convolved with
/// `impulses`.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapedMove {
    /// The baseline.
    pub baseline: Baseline,
    /// Total motor rotation \[rad\].
    pub phi: f64,
    /// Baseline duration `T0 = T − t_last` \[s\] (> 0).
    pub t0: f64,
    /// The impulses.
    pub impulses: Vec<Impulse>,
}

impl ShapedMove {
    /// Time of the last impulse.
    #[must_use]
    pub fn t_last(&self) -> f64 {
        self.impulses.iter().fold(0.0_f64, |m, i| m.max(i.t))
    }

    /// Baseline acceleration and velocity `(u0(s), v0(s))` at time `s` since its start (0 outside
    /// `[0, T0]`; at a breakpoint the right-hand value).
    #[must_use]
    pub fn base_at(&self, s: f64) -> (f64, f64) {
        let t0 = self.t0;
        if !(0.0..t0).contains(&s) {
            return (0.0, 0.0);
        }
        match self.baseline {
            Baseline::Trapezoid => {
                let a0 = 4.5 * self.phi / (t0 * t0);
                let h = t0 / 3.0;
                if s < h {
                    (a0, a0 * s)
                } else if s < 2.0 * h {
                    (0.0, a0 * h)
                } else {
                    (-a0, a0 * (t0 - s))
                }
            }
            Baseline::Cycloidal => {
                let w = TAU / t0;
                let a = self.phi * w / t0;
                let (sn, cs) = (w * s).sin_cos();
                (a * sn, self.phi / t0 * (1.0 - cs))
            }
        }
    }

    /// Shaped motor acceleration and velocity `(u(t), v(t))`.
    #[must_use]
    pub fn at(&self, t: f64) -> (f64, f64) {
        self.impulses.iter().fold((0.0, 0.0), |(u, v), i| {
            let (ub, vb) = self.base_at(t - i.t);
            (u + i.amplitude * ub, v + i.amplitude * vb)
        })
    }

    /// The breakpoints of the shaped acceleration, sorted (each impulse time plus the baseline's
    /// own breakpoints `0, T0/3, 2T0/3, T0` or `0, T0`).
    #[must_use]
    pub fn breakpoints(&self) -> Vec<f64> {
        let fractions: &[f64] = match self.baseline {
            Baseline::Trapezoid => &[0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0],
            Baseline::Cycloidal => &[0.0, 1.0],
        };
        let mut b: Vec<f64> = self
            .impulses
            .iter()
            .flat_map(|i| fractions.iter().map(move |f| i.t + f * self.t0))
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup_by(|a, b| (*a - *b).abs() <= 1e-15 * b.abs().max(1e-300));
        b
    }

    /// `(max |u|, max |v|)` over the move, exact: the shaped acceleration is constant between
    /// breakpoints (trapezoid; the velocity is then linear) or one sinusoid of the baseline's
    /// frequency `Ω` (cycloidal), whose and whose integral's extremes inside an interval are at
    /// the quarter-period points `Ωt + θ ∈ (π/2)ℤ`.
    #[must_use]
    pub fn peaks(&self) -> (f64, f64) {
        let b = self.breakpoints();
        let (mut pu, mut pv) = (0.0_f64, 0.0_f64);
        let mut offer = |t: f64, mid: f64| {
            // The acceleration on the interval is the one at its midpoint (it jumps at a
            // breakpoint); the velocity is continuous.
            let (u, _) = self.at(mid);
            let (_, v) = self.at(t);
            pu = pu.max(u.abs());
            pv = pv.max(v.abs());
        };
        for w in b.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            let mid = 0.5 * (lo + hi);
            match self.baseline {
                Baseline::Trapezoid => {
                    offer(lo, mid);
                    offer(hi, mid);
                }
                Baseline::Cycloidal => {
                    offer(lo, mid);
                    offer(hi, mid);
                    // Active copies on (lo, hi): u = Im(C e^{iΩt}) with C = Σ a A_i e^{−iΩ t_i}.
                    let om = TAU / self.t0;
                    let (mut cr, mut ci) = (0.0, 0.0);
                    for i in &self.impulses {
                        if (0.0..self.t0).contains(&(mid - i.t)) {
                            let (s, c) = (om * i.t).sin_cos();
                            cr += i.amplitude * c;
                            ci -= i.amplitude * s;
                        }
                    }
                    let theta = ci.atan2(cr);
                    // Ωt + θ = jπ/2 for t in (lo, hi).
                    let q = 0.5 * PI;
                    let j0 = ((om * lo + theta) / q).floor() + 1.0;
                    // An interval is at most T0 long: ≤ 5 quarter periods (the cap also ends the
                    // loop where j is too large for j + 1 to be a different float).
                    for step in 0..QUARTER_POINTS_MAX {
                        let t = ((j0 + f64::from(step)) * q - theta) / om;
                        if t >= hi {
                            break;
                        }
                        if t > lo {
                            // Inside the interval: no jump, the value at t is the interval's.
                            offer(t, t);
                        }
                    }
                }
            }
        }
        (pu, pv)
    }

    /// The end state `x(T) = [ψ(T), ψ'(T)]` on `plant` (closed form, see the module docs), or
    /// `None` when the matrix exponential is not finite.
    #[must_use]
    pub fn end_state(&self, plant: &Plant) -> Option<[f64; 2]> {
        let x0 = baseline_end_state(plant, self.baseline, self.phi, self.t0)?;
        let t_last = self.t_last();
        let mut x = [0.0, 0.0];
        for i in &self.impulses {
            let y = plant.propagate(x0, t_last - i.t);
            x[0] += i.amplitude * y[0];
            x[1] += i.amplitude * y[1];
        }
        Some(x)
    }
}

/// `Ac` of the plant and `b = [0, −z]` as the top-left blocks of an augmented matrix of size `n`.
fn augmented(plant: &Plant, n: usize) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(n, n);
    m[(0, 1)] = 1.0;
    m[(1, 0)] = -plant.wn * plant.wn;
    m[(1, 1)] = -2.0 * plant.xi * plant.wn;
    m[(1, 2)] = -plant.z;
    m
}

/// The baseline's state at its end `T0`, from rest (Van Loan exponentials of the plant augmented
/// with the forcing's generator).
fn baseline_end_state(plant: &Plant, baseline: Baseline, phi: f64, t0: f64) -> Option<[f64; 2]> {
    match baseline {
        Baseline::Trapezoid => {
            // exp([[Ac, b], [0, 0]] h) = [[e^{Ac h}, ∫₀ʰ e^{Ac s} b ds], [0, 1]].
            let h = t0 / 3.0;
            let a0 = 4.5 * phi / (t0 * t0);
            let e = expm(&(augmented(plant, 3) * h))?;
            let g = [e[(0, 2)] * a0, e[(1, 2)] * a0];
            let x1 = g;
            let x2 = plant.propagate(x1, h);
            let x3 = plant.propagate(x2, h);
            Some([x3[0] - g[0], x3[1] - g[1]])
        }
        Baseline::Cycloidal => {
            // Forcing u = a·w1 with w1'' = −Ω² w1, w1(0) = 0, w1'(0) = Ω.
            let om = TAU / t0;
            let a = phi * om / t0;
            let mut m = augmented(plant, 4);
            m[(2, 3)] = 1.0;
            m[(3, 2)] = -om * om;
            let e = expm(&(m * t0))?;
            let w = a * om;
            Some([e[(0, 3)] * w, e[(1, 3)] * w])
        }
    }
}

/// One shaper's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ShaperRow {
    /// The shaper.
    pub shaper: Shaper,
    /// The shaped move.
    pub motion: ShapedMove,
    /// Residual energy at T on the nominal plant \[J\].
    pub energy: f64,
    /// `max |u|` [rad/s²].
    pub peak_accel: f64,
    /// `max |∫u|` [rad/s].
    pub peak_vel: f64,
    /// `(factor, E(T))` on `k·factor` when a stiffness sweep is asked for.
    pub sensitivity: Option<Vec<(f64, f64)>>,
}

/// Why a comparison or one of its rows is not computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShaperSkip {
    /// ξ ≥ 1: there is no damped period to design for.
    NotOscillatory {
        /// Damping ratio.
        xi: f64,
    },
    /// The shaper lasts `t_last ≥ T`: no time is left for the baseline.
    TooLong {
        /// The shaper.
        shaper: Shaper,
        /// Its last impulse time \[s\].
        t_last: f64,
        /// The move time \[s\].
        t: f64,
    },
}

/// The Bezier law's row: its residual energy, peaks and stiffness sweep (from the module's
/// own results).
#[derive(Debug, Clone, PartialEq)]
pub struct LawRow {
    /// Residual energy at T \[J\].
    pub energy: f64,
    /// Peak |φ''| [rad/s²].
    pub peak_accel: f64,
    /// Peak |φ'| [rad/s].
    pub peak_vel: f64,
    /// `(factor, E(T))` of the sensitivity sweep.
    pub sensitivity: Option<Vec<(f64, f64)>>,
}

/// The whole comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// What was asked.
    pub spec: ShaperSpec,
    /// Damped period `Td` \[s\].
    pub td: f64,
    /// One row per requested shaper (`None`: it does not fit in T).
    pub rows: Vec<Option<ShaperRow>>,
    /// The Bezier law.
    pub law: LawRow,
}

/// The damped period `Td` \[s\], one row per requested shaper, and the rows skipped.
pub type Compared = (f64, Vec<Option<ShaperRow>>, Vec<ShaperSkip>);

/// The shaper rows: `Ok((td, rows, skips))` with one `None` row per shaper that does not fit in
/// `T` (and its [`ShaperSkip`]). An energy that is not finite (a stiffness factor at the bottom of
/// the `k` range) is returned as NaN for the caller to refuse.
///
/// # Errors
/// [`ShaperSkip::NotOscillatory`] when the nominal plant has ξ ≥ 1.
pub fn compare(
    plant: &Plant,
    spec: &ShaperSpec,
    (phi, t): (f64, f64),
    factors: Option<&[f64]>,
) -> Result<Compared, ShaperSkip> {
    let Some(wd) = plant.omega_d() else {
        return Err(ShaperSkip::NotOscillatory { xi: plant.xi });
    };
    let td = TAU / wd;
    let k = (-plant.xi * plant.wn * PI / wd).exp();
    let mut skips = Vec::new();
    let rows = spec
        .shapers
        .iter()
        .map(|&shaper| {
            let imp = impulses(shaper, td, k, spec.ei_tolerance);
            let t_last = imp.iter().fold(0.0_f64, |m, i| m.max(i.t));
            let t0 = t - t_last;
            if t0.is_nan() || t0 <= 0.0 {
                skips.push(ShaperSkip::TooLong { shaper, t_last, t });
                return None;
            }
            let motion = ShapedMove {
                baseline: spec.baseline,
                phi,
                t0,
                impulses: imp,
            };
            let energy = motion
                .end_state(plant)
                .map_or(f64::NAN, |x| plant.energy(x));
            let (peak_accel, peak_vel) = motion.peaks();
            let sensitivity = factors.map(|fs| {
                fs.iter()
                    .map(|&f| {
                        let pf = plant.with_stiffness_factor(f);
                        let e = motion.end_state(&pf).map_or(f64::NAN, |x| pf.energy(x));
                        (f, e)
                    })
                    .collect()
            });
            Some(ShaperRow {
                shaper,
                motion,
                energy,
                peak_accel,
                peak_vel,
                sensitivity,
            })
        })
        .collect();
    Ok((td, rows, skips))
}
