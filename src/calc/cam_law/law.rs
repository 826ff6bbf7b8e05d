//! The general 7-segment modified-trapezoidal law (spec §3.2).
//!
//! Conventions (spec §3.1–§3.2):
//! * `x` is the abscissa (time or cam angle, unit "x"), `s` the displacement (unit U), `v = ds/dx`
//!   [U/x], `a = d²s/dx²` [U/x²], `j = d³s/dx³` [U/x³]. No units are converted.
//! * Segment `k = 0..6` has duration `c_k = ĉ_k·Δt` and starts at knot `t_k`; `t_7` is pinned to
//!   `t_b`. Segments 0–2 form the first acceleration pulse (peak `A1`), 3 is the constant-velocity
//!   dwell, 4–6 form the second pulse (peak `A2`). For a rise `A1 > 0 > A2`, for a fall the reverse.
//! * Value convention at an acceleration jump: right-continuous inside `[t_a, t_b)`, left-continuous
//!   at `t_b` (so with `c0 = 0`, `a(t_a) = A1`; with `c6 = 0`, `a(t_b) = A2`).
//!
//! The law is built once ([`SevenSegmentLaw::try_new`], no heap allocation) and then evaluated
//! allocation-free ([`SevenSegmentLaw::eval`], [`SevenSegmentLaw::eval_quantity_into`]); the fit
//! constructs one law per candidate and evaluates it over the sample grid in its inner loop.

// `mul_add` compiles to a libm call on targets without a guaranteed FMA unit, which would more
// than double the per-sample cost of the hot loops below; the plain forms are accurate enough here
// (every quantity is evaluated relative to its segment start, errors stay at a few ulp).

use std::f64::consts::{FRAC_2_PI, FRAC_PI_2};

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

pub use super::error::LawError;

/// `K1 = 2/π` (spec §3.1): area of a unit quarter-sine pulse per unit duration.
pub const K1: f64 = FRAC_2_PI;
/// `K2 = 4/π²` (spec §3.1).
pub const K2: f64 = FRAC_2_PI * FRAC_2_PI;

/// A pulse whose normalized area `P̂ = K1ĉ0 + ĉ1 + K1ĉ2` (resp. `Q̂`) is below this is empty
/// (spec §6 item 1: `P < 1e-9·Δt`); its peak would scale like `1/P`.
pub const EMPTY_PULSE_TOL: f64 = 1e-9;

/// Normalized coefficients below this are set to exactly zero: such a segment is shorter than a
/// few ulp of the knot times and cannot be placed, and `π/(2c_k)` could overflow.
pub const NEGLIGIBLE_COEFFICIENT: f64 = 1e-15;

/// Segments shorter than this fraction of Δt have no finite jerk maximum in [`Peaks`]: they act
/// as acceleration jumps (spec §6 item 2).
pub const FINITE_JERK_MIN_SEGMENT: f64 = 1e-9;

/// Largest accepted magnitude of a boundary value (spec §6 item 9: cancellation in `b2` stays
/// harmless in f64 below it).
pub const MAX_MAGNITUDE: f64 = 1e12;

/// `Δt` must exceed this fraction of `max(|t_a|, |t_b|)`, else the knots cannot be resolved in f64.
pub const MIN_RELATIVE_INTERVAL: f64 = 1e-12;

/// Acceleration jumps smaller than this fraction of the largest acceleration magnitude are
/// round-off, not jumps (spec §3.2).
pub const JUMP_REL_TOL: f64 = 1e-12;

/// Boundary conditions of one motion segment (spec §2, the paper's constraint vector λ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryConditions {
    /// Segment start `t_a` \[x\].
    pub t_a: f64,
    /// Segment end `t_b` \[x\], `t_b > t_a`.
    pub t_b: f64,
    /// Displacement at the start `s_a` \[U\].
    pub s_a: f64,
    /// Displacement at the end `s_b` \[U\].
    pub s_b: f64,
    /// Velocity at the start `v_a` [U/x].
    pub v_a: f64,
    /// Velocity at the end `v_b` [U/x].
    pub v_b: f64,
    /// Acceleration at the start `a_a` [U/x²].
    pub a_a: f64,
    /// Acceleration at the end `a_b` [U/x²].
    pub a_b: f64,
}

impl BoundaryConditions {
    /// Unit rise in unit time with zero end rates (the normalized laws of Appendix A).
    pub const UNIT_RISE: Self = Self {
        t_a: 0.0,
        t_b: 1.0,
        s_a: 0.0,
        s_b: 1.0,
        v_a: 0.0,
        v_b: 0.0,
        a_a: 0.0,
        a_b: 0.0,
    };

    /// The fields as `(name, value)` pairs, in wire order.
    #[must_use]
    pub fn named_values(&self) -> [(&'static str, f64); 8] {
        [
            ("t_a", self.t_a),
            ("t_b", self.t_b),
            ("s_a", self.s_a),
            ("s_b", self.s_b),
            ("v_a", self.v_a),
            ("v_b", self.v_b),
            ("a_a", self.a_a),
            ("a_b", self.a_b),
        ]
    }

    /// Whether all four end rates are exactly zero.
    #[must_use]
    pub fn zero_end_rates(&self) -> bool {
        [self.v_a, self.v_b, self.a_a, self.a_b]
            .iter()
            .all(|r| *r == 0.0)
    }

    /// First problem of the boundary conditions alone, if any.
    ///
    /// # Errors
    /// Non-finite or too large values, `t_b <= t_a`, or an interval too short to resolve.
    pub fn check(&self) -> Result<(), LawError> {
        for (name, value) in self.named_values() {
            if !value.is_finite() {
                return Err(LawError::NonFiniteBoundary { name, value });
            }
            if value.abs() > MAX_MAGNITUDE {
                return Err(LawError::MagnitudeTooLarge {
                    name,
                    value,
                    limit: MAX_MAGNITUDE,
                });
            }
        }
        if self.t_b <= self.t_a {
            return Err(LawError::IntervalNotIncreasing {
                t_a: self.t_a,
                t_b: self.t_b,
            });
        }
        let dt = self.t_b - self.t_a;
        let min = MIN_RELATIVE_INTERVAL * self.t_a.abs().max(self.t_b.abs());
        if dt <= min {
            return Err(LawError::IntervalTooShort { dt, min });
        }
        Ok(())
    }
}

/// A quantity of the motion law.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, ToSchema, crate::calc::Rules,
)]
#[schema(as = cam_law::Quantity)]
#[serde(rename_all = "lowercase")]
pub enum Quantity {
    /// Displacement `s` \[U\].
    S,
    /// Velocity `v = ds/dx` [U/x].
    V,
    /// Acceleration `a = d²s/dx²` [U/x²].
    A,
    /// Jerk `j = d³s/dx³` [U/x³].
    J,
}

impl Quantity {
    /// All four quantities in the order s, v, a, j.
    pub const ALL: [Self; 4] = [Self::S, Self::V, Self::A, Self::J];
}

/// The law's value at one abscissa.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Displacement \[U\].
    pub s: f64,
    /// Velocity [U/x].
    pub v: f64,
    /// Acceleration [U/x²] (right-continuous inside, left-continuous at `t_b`).
    pub a: f64,
    /// Jerk [U/x³] (finite part; impulses at acceleration jumps are not represented).
    pub j: f64,
}

impl Sample {
    /// The value of one quantity.
    #[must_use]
    pub fn get(&self, q: Quantity) -> f64 {
        match q {
            Quantity::S => self.s,
            Quantity::V => self.v,
            Quantity::A => self.a,
            Quantity::J => self.j,
        }
    }
}

/// A knot `t_k` of the law (start of segment `k`, or `t_b` for `k = 7`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law::Knot)]
pub struct Knot {
    /// Knot abscissa `t_k` \[x\].
    pub x: f64,
    /// Displacement `s_k` \[U\].
    pub s: f64,
    /// Velocity `v_k` [U/x].
    pub v: f64,
    /// Acceleration just left of the knot [U/x²] (`a_a` at `t_a`).
    pub a_left: f64,
    /// Acceleration just right of the knot [U/x²] (`a_b` at `t_b`).
    pub a_right: f64,
}

/// Exact peaks of the law (spec §3.2, no sampling).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law::Peaks)]
pub struct Peaks {
    /// Peak of the first acceleration pulse `A1` [U/x²] (paper: A_pos; negative for a fall).
    pub a1: f64,
    /// Peak of the second acceleration pulse `A2` [U/x²] (paper: A_neg; positive for a fall).
    pub a2: f64,
    /// Largest |a| [U/x²]: `max(|a_a| if c0>0, |A1|, |A2|, |a_b| if c6>0)`.
    pub a_max_abs: f64,
    /// Largest |v| [U/x] (knots and interior stationary points of segments 0 and 6).
    pub v_max_abs: f64,
    /// First abscissa where |v| reaches `v_max_abs` \[x\].
    pub x_at_v_max: f64,
    /// Largest finite |jerk| [U/x³] over segments of at least 1e-9·Δt (0 if none; impulses at
    /// acceleration jumps excluded).
    pub jerk_max_abs_finite: f64,
}

/// An acceleration jump (jerk impulse) at a knot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
#[schema(as = cam_law::Jump)]
pub struct Jump {
    /// Abscissa of the jump \[x\].
    pub x: f64,
    /// Acceleration just left of `x` [U/x²].
    pub a_left: f64,
    /// Acceleration just right of `x` [U/x²].
    pub a_right: f64,
}

/// A non-fatal finding about a law or a fit (spec §4); the response lists its code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawNotice {
    /// The coefficients did not sum to 1 and were renormalized.
    CoefficientsRenormalized,
    /// Δs = 0 with zero end rates: the law is flat and does not depend on the coefficients.
    NonIdentifiable,
    /// A pulse peak has the sign opposite to the usual one for this rise or fall.
    PeakSignUnusual,
    /// (fit only) a channel was derived by numerical differentiation.
    DerivedChannelNoiseGain,
    /// (fit only) a segment is shorter than the sample spacing next to a jump.
    SegmentBelowResolution,
    /// (fit only) the optimizer stopped on its budget.
    BudgetExhausted,
}

/// A law sampled at given abscissae: the quantities asked for, each at every abscissa.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledCurves {
    /// Abscissae, in the caller's order.
    pub x: Vec<f64>,
    /// Displacement, when asked for.
    pub s: Option<Vec<f64>>,
    /// Velocity, when asked for.
    pub v: Option<Vec<f64>>,
    /// Acceleration, when asked for.
    pub a: Option<Vec<f64>>,
    /// Jerk, when asked for.
    pub j: Option<Vec<f64>>,
}

impl SampledCurves {
    /// No quantity yet at the abscissae `xs`.
    #[must_use]
    pub fn at(xs: &[f64]) -> Self {
        Self {
            x: xs.to_vec(),
            s: None,
            v: None,
            a: None,
            j: None,
        }
    }

    /// Store the samples of quantity `q`.
    pub fn set(&mut self, q: Quantity, values: Vec<f64>) {
        let slot = match q {
            Quantity::S => &mut self.s,
            Quantity::V => &mut self.v,
            Quantity::A => &mut self.a,
            Quantity::J => &mut self.j,
        };
        *slot = Some(values);
    }
}

/// Shape of the acceleration inside a segment (spec §3.2 table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    /// `a = a0 + d·sin(wτ)` (segments 0 and 4).
    Sin,
    /// `a = a0 + d·cos(wτ)` (segments 2 and 6).
    Cos,
    /// `a = a0` (segments 1, 3, 5).
    Const,
}

/// One non-empty segment, precomputed for evaluation.
#[derive(Debug, Clone, Copy)]
struct Segment {
    /// Start knot `t_k` [x].
    t0: f64,
    /// Duration `c_k` [x] (> 0).
    c: f64,
    /// `s_k` [U].
    s0: f64,
    /// `v_k` [U/x].
    v0: f64,
    /// Base acceleration (a_a, A1, 0, A2 or a_b) [U/x²].
    a0: f64,
    /// Amplitude of the sine/cosine part [U/x²].
    d: f64,
    /// `w = π/(2c)` [1/x].
    w: f64,
    /// `1/w = 2c/π` [x].
    inv_w: f64,
    shape: Shape,
}

const EMPTY_SEGMENT: Segment = Segment {
    t0: 0.0,
    c: 0.0,
    s0: 0.0,
    v0: 0.0,
    a0: 0.0,
    d: 0.0,
    w: 0.0,
    inv_w: 0.0,
    shape: Shape::Const,
};

impl Segment {
    /// Acceleration at the segment start.
    fn a_start(&self) -> f64 {
        match self.shape {
            Shape::Sin | Shape::Const => self.a0,
            Shape::Cos => self.a0 + self.d,
        }
    }

    /// Acceleration at the segment end (exact: sin(π/2) = 1, cos(π/2) = 0).
    fn a_end(&self) -> f64 {
        match self.shape {
            Shape::Sin => self.a0 + self.d,
            Shape::Cos | Shape::Const => self.a0,
        }
    }

    /// Velocity and displacement at the segment end (the knot formulas of §3.2).
    fn end_state(&self) -> (f64, f64) {
        let c = self.c;
        let base_v = self.v0 + self.a0 * c;
        let base_s = self.s0 + self.v0 * c + 0.5 * self.a0 * c * c;
        match self.shape {
            Shape::Sin => (
                base_v + self.d * self.inv_w,
                base_s + self.d * self.inv_w * (c - self.inv_w),
            ),
            Shape::Cos => (
                base_v + self.d * self.inv_w,
                base_s + self.d * self.inv_w * self.inv_w,
            ),
            Shape::Const => (base_v, base_s),
        }
    }

    /// Largest |jerk| inside the segment.
    fn jerk_max(&self) -> f64 {
        match self.shape {
            Shape::Const => 0.0,
            Shape::Sin | Shape::Cos => self.d.abs() * self.w,
        }
    }

    #[inline]
    fn s(&self, tau: f64) -> f64 {
        let base = self.s0 + tau * (self.v0 + 0.5 * self.a0 * tau);
        match self.shape {
            Shape::Sin => base + self.d * self.inv_w * (tau - self.inv_w * (self.w * tau).sin()),
            Shape::Cos => base + self.d * self.inv_w * self.inv_w * (1.0 - (self.w * tau).cos()),
            Shape::Const => base,
        }
    }

    #[inline]
    fn v(&self, tau: f64) -> f64 {
        let base = self.v0 + self.a0 * tau;
        match self.shape {
            Shape::Sin => base + self.d * self.inv_w * (1.0 - (self.w * tau).cos()),
            Shape::Cos => base + self.d * self.inv_w * (self.w * tau).sin(),
            Shape::Const => base,
        }
    }

    #[inline]
    fn a(&self, tau: f64) -> f64 {
        match self.shape {
            Shape::Sin => self.a0 + self.d * (self.w * tau).sin(),
            Shape::Cos => self.a0 + self.d * (self.w * tau).cos(),
            Shape::Const => self.a0,
        }
    }

    #[inline]
    fn j(&self, tau: f64) -> f64 {
        match self.shape {
            Shape::Sin => self.d * self.w * (self.w * tau).cos(),
            Shape::Cos => -self.d * self.w * (self.w * tau).sin(),
            Shape::Const => 0.0,
        }
    }

    fn sample(&self, tau: f64) -> Sample {
        let (sn, cs) = (self.w * tau).sin_cos();
        let base_s = self.s0 + tau * (self.v0 + 0.5 * self.a0 * tau);
        let base_v = self.v0 + self.a0 * tau;
        match self.shape {
            Shape::Sin => Sample {
                s: base_s + self.d * self.inv_w * (tau - self.inv_w * sn),
                v: base_v + self.d * self.inv_w * (1.0 - cs),
                a: self.a0 + self.d * sn,
                j: self.d * self.w * cs,
            },
            Shape::Cos => Sample {
                s: base_s + self.d * self.inv_w * self.inv_w * (1.0 - cs),
                v: base_v + self.d * self.inv_w * sn,
                a: self.a0 + self.d * cs,
                j: -self.d * self.w * sn,
            },
            Shape::Const => Sample {
                s: base_s,
                v: base_v,
                a: self.a0,
                j: 0.0,
            },
        }
    }
}

/// Validate and normalize a coefficient vector: finite, non-negative, negligible entries set to
/// zero, `Σĉ = 1`, both pulses non-empty.
///
/// # Errors
/// [`LawError::NonFiniteCoefficient`], [`LawError::NegativeCoefficient`],
/// [`LawError::EmptyFirstPulse`], [`LawError::EmptySecondPulse`].
pub fn normalize_coefficients(c: &[f64; 7]) -> Result<[f64; 7], LawError> {
    for (index, &value) in c.iter().enumerate() {
        if !value.is_finite() {
            return Err(LawError::NonFiniteCoefficient { index, value });
        }
        if value < 0.0 {
            return Err(LawError::NegativeCoefficient { index, value });
        }
    }
    let mut hat = *c;
    for _ in 0..2 {
        let sum: f64 = hat.iter().sum();
        if !(sum > 0.0 && sum.is_finite()) {
            // All zero (or overflowing sum of huge entries: rescale first).
            let max = hat.iter().copied().fold(0.0, f64::max);
            if max > 0.0 {
                hat.iter_mut().for_each(|h| *h /= max);
                continue;
            }
            return Err(LawError::EmptyFirstPulse { area: 0.0 });
        }
        for h in &mut hat {
            *h /= sum;
            if *h < NEGLIGIBLE_COEFFICIENT {
                *h = 0.0;
            }
        }
    }
    let sum: f64 = hat.iter().sum();
    hat.iter_mut().for_each(|h| *h /= sum);
    let p = K1 * hat[0] + hat[1] + K1 * hat[2];
    if p < EMPTY_PULSE_TOL {
        return Err(LawError::EmptyFirstPulse { area: p });
    }
    let q = K1 * hat[4] + hat[5] + K1 * hat[6];
    if q < EMPTY_PULSE_TOL {
        return Err(LawError::EmptySecondPulse { area: q });
    }
    Ok(hat)
}

/// The right-hand sides `b1, b2` of §3.2 for absolute durations `d`.
fn rhs(d: &[f64; 7], bc: &BoundaryConditions) -> (f64, f64) {
    let dt = bc.t_b - bc.t_a;
    let b1 = (bc.v_b - bc.v_a) - (1.0 - K1) * (bc.a_a * d[0] + bc.a_b * d[6]);
    let b2 = (bc.s_b - bc.s_a)
        - bc.v_a * dt
        - bc.a_a * ((0.5 - K1 + K2) * d[0] * d[0] + (1.0 - K1) * d[0] * (dt - d[0]))
        - bc.a_b * (0.5 - K2) * d[6] * d[6];
    (b1, b2)
}

/// `A1, A2` by the impulse/centroid form of §3.2 from absolute durations (used by the law).
fn centroid_form(d: &[f64; 7], bc: &BoundaryConditions) -> (f64, f64) {
    let dt = bc.t_b - bc.t_a;
    let p = K1 * d[0] + d[1] + K1 * d[2];
    let q = K1 * d[4] + d[5] + K1 * d[6];
    let mp = K2 * d[0] * d[0]
        + d[1] * (d[0] + 0.5 * d[1])
        + K1 * d[2] * (d[0] + d[1])
        + (K1 - K2) * d[2] * d[2];
    let mn = K2 * d[4] * d[4]
        + d[5] * (d[4] + 0.5 * d[5])
        + K1 * d[6] * (d[4] + d[5])
        + (K1 - K2) * d[6] * d[6];
    let tau_p = mp / p;
    let tau_n = (d[0] + d[1] + d[2] + d[3]) + mn / q;
    let (b1, b2) = rhs(d, bc);
    let i1 = (b2 - b1 * (dt - tau_n)) / (tau_n - tau_p);
    let i2 = b1 - i1;
    (i1 / p, i2 / q)
}

fn durations_of(hat: &[f64; 7], bc: &BoundaryConditions) -> [f64; 7] {
    let dt = bc.t_b - bc.t_a;
    hat.map(|h| h * dt)
}

/// `A1, A2` by Cramer's rule on the 2×2 system of §3.2 (for cross-checking, spec §5.5 item 3).
/// `c` is normalized internally; `None` when the coefficients or boundary conditions are invalid.
#[must_use]
pub fn accelerations_cramer(c: &[f64; 7], bc: &BoundaryConditions) -> Option<(f64, f64)> {
    bc.check().ok()?;
    let hat = normalize_coefficients(c).ok()?;
    let d = durations_of(&hat, bc);
    let p = K1 * d[0] + d[1] + K1 * d[2];
    let q = K1 * d[4] + d[5] + K1 * d[6];
    let r = K1 * d[0] * (d[0] - K1 * d[0])
        + 0.5 * d[1] * d[1]
        + K2 * d[2] * d[2]
        + K1 * d[0] * (d[1] + d[2])
        + d[1] * d[2]
        + p * (d[3] + d[4] + d[5] + d[6]);
    let s = K1 * d[4] * (d[4] - K1 * d[4])
        + 0.5 * d[5] * d[5]
        + K2 * d[6] * d[6]
        + K1 * d[4] * (d[5] + d[6])
        + d[5] * d[6];
    let (b1, b2) = rhs(&d, bc);
    let det = p * s - q * r;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    Some(((b1 * s - q * b2) / det, (p * b2 - r * b1) / det))
}

/// `A1, A2` by the impulse/centroid form of §3.2 (the form the law uses). `c` is normalized
/// internally; `None` when the coefficients or boundary conditions are invalid.
#[must_use]
pub fn accelerations_centroid(c: &[f64; 7], bc: &BoundaryConditions) -> Option<(f64, f64)> {
    bc.check().ok()?;
    let hat = normalize_coefficients(c).ok()?;
    Some(centroid_form(&durations_of(&hat, bc), bc))
}

/// The general 7-segment modified-trapezoidal law with arbitrary end velocities and
/// accelerations (spec §3.2; paper Appendix A, errata of §3.7 applied).
///
/// Construction is `O(1)` without heap allocation; evaluation is allocation-free.
#[derive(Debug, Clone)]
pub struct SevenSegmentLaw {
    bc: BoundaryConditions,
    hat: [f64; 7],
    dur: [f64; 7],
    /// Knot abscissae `t_0..t_7` (`t_7 = t_b` exactly).
    t: [f64; 8],
    /// Knot displacements `s_0..s_7`.
    s: [f64; 8],
    /// Knot velocities `v_0..v_7`.
    v: [f64; 8],
    a1: f64,
    a2: f64,
    /// Non-empty segments in order (`active[..n_active]`).
    active: [Segment; 7],
    /// Original index `k` of each active segment.
    active_k: [usize; 7],
    n_active: usize,
}

impl SevenSegmentLaw {
    /// Build the law from 7 non-negative duration coefficients (normalized internally to Σ = 1)
    /// and the boundary conditions. No heap allocation.
    ///
    /// # Errors
    /// Invalid boundary conditions (non-finite, `|value| > 1e12`, `t_b <= t_a`), negative or
    /// non-finite coefficients, an empty or near-empty pulse (`P` or `Q < 1e-9·Δt`), or a law
    /// whose peaks overflow f64.
    pub fn try_new(coefficients: &[f64; 7], bc: &BoundaryConditions) -> Result<Self, LawError> {
        bc.check()?;
        let hat = normalize_coefficients(coefficients)?;
        let dur = durations_of(&hat, bc);
        let (a1, a2) = centroid_form(&dur, bc);
        if !a1.is_finite() {
            return Err(LawError::Overflow {
                quantity: "first pulse peak A1",
            });
        }
        if !a2.is_finite() {
            return Err(LawError::Overflow {
                quantity: "second pulse peak A2",
            });
        }

        let mut t = [0.0; 8];
        t[0] = bc.t_a;
        for k in 0..7 {
            t[k + 1] = t[k] + dur[k];
        }
        // Pin t_7 = t_b and the knots of empty trailing segments with it; round-off of the
        // cumulative sum must never put a knot beyond t_b (spec §6 item 5).
        t[7] = bc.t_b;
        for k in (1..7).rev() {
            if dur[k] > 0.0 {
                break;
            }
            t[k] = bc.t_b;
        }
        for tk in &mut t {
            *tk = tk.min(bc.t_b);
        }

        // (base acceleration, amplitude, shape) per segment, spec §3.2 table.
        let shapes = [
            (bc.a_a, a1 - bc.a_a, Shape::Sin),
            (a1, 0.0, Shape::Const),
            (0.0, a1, Shape::Cos),
            (0.0, 0.0, Shape::Const),
            (0.0, a2, Shape::Sin),
            (a2, 0.0, Shape::Const),
            (bc.a_b, a2 - bc.a_b, Shape::Cos),
        ];
        let mut s = [0.0; 8];
        let mut v = [0.0; 8];
        s[0] = bc.s_a;
        v[0] = bc.v_a;
        let mut active = [EMPTY_SEGMENT; 7];
        let mut active_k = [0usize; 7];
        let mut n_active = 0;
        for k in 0..7 {
            let c = dur[k];
            if c > 0.0 {
                let (a0, d, shape) = shapes[k];
                let w = FRAC_PI_2 / c;
                let seg = Segment {
                    t0: t[k],
                    c,
                    s0: s[k],
                    v0: v[k],
                    a0,
                    d,
                    w,
                    inv_w: K1 * c,
                    shape,
                };
                if !(seg.jerk_max().is_finite() && w.is_finite()) {
                    return Err(LawError::Overflow { quantity: "jerk" });
                }
                let (v_end, s_end) = seg.end_state();
                v[k + 1] = v_end;
                s[k + 1] = s_end;
                active[n_active] = seg;
                active_k[n_active] = k;
                n_active += 1;
            } else {
                v[k + 1] = v[k];
                s[k + 1] = s[k];
            }
        }
        if !(v.iter().all(|x| x.is_finite())) {
            return Err(LawError::Overflow {
                quantity: "velocity",
            });
        }
        if !(s.iter().all(|x| x.is_finite())) {
            return Err(LawError::Overflow {
                quantity: "displacement",
            });
        }
        Ok(Self {
            bc: *bc,
            hat,
            dur,
            t,
            s,
            v,
            a1,
            a2,
            active,
            active_k,
            n_active,
        })
    }

    /// Normalized coefficients `ĉ` (Σ = 1, entries below 1e-15 set to 0).
    #[must_use]
    pub fn coefficients(&self) -> &[f64; 7] {
        &self.hat
    }

    /// Absolute segment durations `c_k = ĉ_k·Δt` \[x\].
    #[must_use]
    pub fn durations(&self) -> &[f64; 7] {
        &self.dur
    }

    /// Knot abscissae `t_0..t_7` \[x\] (`t_7 = t_b` exactly).
    #[must_use]
    pub fn knot_times(&self) -> &[f64; 8] {
        &self.t
    }

    /// Peak of the first pulse `A1` [U/x²].
    #[must_use]
    pub fn a1(&self) -> f64 {
        self.a1
    }

    /// Peak of the second pulse `A2` [U/x²].
    #[must_use]
    pub fn a2(&self) -> f64 {
        self.a2
    }

    /// The boundary conditions the law was built for.
    #[must_use]
    pub fn bc(&self) -> &BoundaryConditions {
        &self.bc
    }

    fn active(&self) -> &[Segment] {
        &self.active[..self.n_active]
    }

    /// Index into `active` of the segment that owns `x`, walking forward from `hint` (restarts
    /// from the first segment when `x` lies before the hint's segment).
    #[inline]
    fn locate(&self, x: f64, hint: usize) -> usize {
        let segs = self.active();
        let mut i = if x < segs[hint].t0 { 0 } else { hint };
        while i + 1 < segs.len() && segs[i + 1].t0 <= x {
            i += 1;
        }
        i
    }

    /// Local time inside `seg` for abscissa `x` (clamped; `x >= t_b` maps to the segment end so
    /// that the law is left-continuous at `t_b`).
    #[inline]
    fn tau(&self, seg: &Segment, x: f64) -> f64 {
        if x >= self.bc.t_b {
            seg.c
        } else {
            (x - seg.t0).clamp(0.0, seg.c)
        }
    }

    /// All four quantities at one abscissa (outside `[t_a, t_b]` the end values are returned).
    #[must_use]
    pub fn eval(&self, x: f64) -> Sample {
        let seg = &self.active()[self.locate(x, 0)];
        seg.sample(self.tau(seg, x))
    }

    /// One quantity at every abscissa of `xs`, written to `out` (which must have the same length;
    /// extra elements of the longer slice are ignored). Allocation-free; walks the segments
    /// monotonically when `xs` is sorted and stays correct for unsorted input.
    pub fn eval_quantity_into(&self, xs: &[f64], q: Quantity, out: &mut [f64]) {
        match q {
            Quantity::S => self.eval_with(xs, out, Segment::s),
            Quantity::V => self.eval_with(xs, out, Segment::v),
            Quantity::A => self.eval_with(xs, out, Segment::a),
            Quantity::J => self.eval_with(xs, out, Segment::j),
        }
    }

    #[inline]
    fn eval_with(&self, xs: &[f64], out: &mut [f64], f: impl Fn(&Segment, f64) -> f64) {
        let mut i = 0;
        for (x, o) in xs.iter().zip(out.iter_mut()) {
            i = self.locate(*x, i);
            let seg = &self.active[i];
            *o = f(seg, self.tau(seg, *x));
        }
    }

    /// The 8 knots with their displacement, velocity and one-sided accelerations.
    #[must_use]
    pub fn knots(&self) -> [Knot; 8] {
        let segs = self.active();
        let ks = &self.active_k[..self.n_active];
        std::array::from_fn(|k| {
            let a_left = ks
                .iter()
                .rposition(|&sk| sk < k)
                .map_or(self.bc.a_a, |i| segs[i].a_end());
            let a_right = ks
                .iter()
                .position(|&sk| sk >= k)
                .map_or(self.bc.a_b, |i| segs[i].a_start());
            Knot {
                x: self.t[k],
                s: self.s[k],
                v: self.v[k],
                a_left,
                a_right,
            }
        })
    }

    /// Largest |a| the law can take, including `a_a`/`a_b` (the scale for jump detection).
    fn a_scale(&self) -> f64 {
        self.a1
            .abs()
            .max(self.a2.abs())
            .max(self.bc.a_a.abs())
            .max(self.bc.a_b.abs())
    }

    /// Exact peaks (spec §3.2).
    #[must_use]
    pub fn peaks(&self) -> Peaks {
        let dt = self.bc.t_b - self.bc.t_a;
        let mut a_max = self.a1.abs().max(self.a2.abs());
        if self.dur[0] > 0.0 {
            a_max = a_max.max(self.bc.a_a.abs());
        }
        if self.dur[6] > 0.0 {
            a_max = a_max.max(self.bc.a_b.abs());
        }

        // |v| candidates in abscissa order so that ties keep the first abscissa; knots of empty
        // segments repeat their neighbours' values and need no visit.
        let mut v_max = self.v[0].abs();
        let mut x_at = self.t[0];
        let mut consider = |x: f64, v: f64| {
            if v.abs() > v_max {
                v_max = v.abs();
                x_at = x;
            }
        };
        for (seg, &k) in self.active().iter().zip(&self.active_k) {
            // Interior stationary points of v (a = 0) exist only in segments 0 and 6.
            let ratio = match k {
                0 if self.bc.a_a * self.a1 < 0.0 => Some(-self.bc.a_a / (self.a1 - self.bc.a_a)),
                6 if self.a2 * self.bc.a_b < 0.0 => Some(-self.bc.a_b / (self.a2 - self.bc.a_b)),
                _ => None,
            };
            if let Some(r) = ratio {
                let r = r.clamp(0.0, 1.0);
                let tau = (if k == 0 { r.asin() } else { r.acos() } * seg.inv_w).clamp(0.0, seg.c);
                consider((seg.t0 + tau).min(self.bc.t_b), seg.v(tau));
            }
            consider(self.t[k + 1], self.v[k + 1]);
        }

        let min_c = FINITE_JERK_MIN_SEGMENT * dt;
        let jerk = self
            .active()
            .iter()
            .filter(|sg| sg.c >= min_c)
            .map(Segment::jerk_max)
            .fold(0.0, f64::max);
        Peaks {
            a1: self.a1,
            a2: self.a2,
            a_max_abs: a_max,
            v_max_abs: v_max,
            x_at_v_max: x_at,
            jerk_max_abs_finite: jerk,
        }
    }

    /// Acceleration jumps (jerk impulses), one per distinct abscissa, in order (spec §3.2).
    #[must_use]
    pub fn jumps(&self) -> Vec<Jump> {
        let mut out = Vec::new();
        self.for_each_jump(|j| out.push(j));
        out
    }

    /// Allocation-free form of [`Self::jumps`].
    pub fn for_each_jump(&self, mut f: impl FnMut(Jump)) {
        let tol = JUMP_REL_TOL * self.a_scale();
        let mut check = |x: f64, a_left: f64, a_right: f64| {
            if (a_left - a_right).abs() > tol {
                f(Jump { x, a_left, a_right });
            }
        };
        let segs = self.active();
        check(self.bc.t_a, self.bc.a_a, segs[0].a_start());
        for pair in segs.windows(2) {
            check(pair[1].t0, pair[0].a_end(), pair[1].a_start());
        }
        check(self.bc.t_b, segs[segs.len() - 1].a_end(), self.bc.a_b);
    }
}
