//! Circuit-aware coupler-curve sampling (spec §4.8).
//!
//! Every circuit is parametrised by `u ∈ [0, 2π)`:
//! * full rotation (case 1 of §4.3): `φ = −π + u`, fixed branch;
//! * limited interval `[lo, hi]`, `auto` spacing: `φ = (lo+hi)/2 − ((hi−lo)/2)·cos u` (cosine spacing,
//!   dense where the curve speed `dP/dφ ~ 1/h` is large), branch +1 for `u ≤ π`, −1 after;
//! * limited interval, `uniform` spacing: `φ` piecewise linear in `u` (up on +1, back on −1).
//!
//! Sample `j` of `N` sits at `u_j = 2πj/N`.

use std::f64::consts::PI;

use super::geometry::{C64, Circuit, FourBar, Sign, Solve};

/// How samples are spaced along a circuit: the request's `spacing`.
pub use super::wire::Spacing;

/// Input angle relative to the ground line \[rad\] and branch at circuit parameter `u ∈ [0, 2π]`.
#[must_use]
pub fn circuit_param(circuit: &Circuit, u: f64, spacing: Spacing) -> (f64, Sign) {
    match *circuit {
        Circuit::Full(t) => (-PI + u, t),
        Circuit::Limited { lo, hi } => {
            let branch = if u <= PI { Sign::Plus } else { Sign::Minus };
            let phi = match spacing {
                // (lo+hi)/2 − ((hi−lo)/2)·cos u, written from the nearer end so that u = 0 and u = π
                // land exactly on the toggles lo and hi.
                Spacing::Auto => {
                    let c = u.cos();
                    if c >= 0.0 {
                        lo + (hi - lo) * (0.5 * (1.0 - c))
                    } else {
                        hi - (hi - lo) * (0.5 * (1.0 + c))
                    }
                }
                Spacing::Uniform => {
                    let t = u / PI;
                    if t <= 0.5 {
                        lo + (hi - lo) * t
                    } else if t <= 1.5 {
                        hi - (hi - lo) * (t - 1.0).abs()
                    } else {
                        lo + (hi - lo) * (2.0 - t)
                    }
                }
            };
            (phi.clamp(lo, hi), branch)
        }
    }
}

/// Parameter of sample `j` of `n` on a closed circuit.
#[must_use]
pub fn sample_u(j: usize, n: usize) -> f64 {
    // j < n ≤ 100 000 here: both convert to f64 exactly.
    let t = j as f64 / n as f64;
    2.0 * PI * t
}

/// Coupler point of `mech` at circuit parameter `u` (the "truth" for chord errors); `None` where the
/// crank tip sits on the output pivot.
#[must_use]
pub fn curve_point(mech: &FourBar, circuit: &Circuit, u: f64, spacing: Spacing) -> Option<C64> {
    let (phi, t) = circuit_param(circuit, u, spacing);
    match mech.solve(phi + mech.ground_angle(), t, true) {
        Solve::Pose(p) => Some(p.p),
        Solve::NotAssemblable { .. } | Solve::Singular { .. } => None,
    }
}

/// A sweep of one mechanism's input: either a closed circuit or a fixed-branch interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sweep {
    /// A closed circuit (`circuits` mode).
    Circuit(Circuit),
    /// A fixed-branch sweep of `[lo, hi]` (relative, rad); `closed` for a full turn (`fixed_branch`).
    Fixed {
        /// Start.
        lo: f64,
        /// End.
        hi: f64,
        /// Branch.
        branch: Sign,
        /// Full turn (the last point connects to the first).
        closed: bool,
    },
}

impl Sweep {
    /// Relative input angle and branch of sample `j` of `n`.
    #[must_use]
    pub fn sample(&self, j: usize, n: usize, spacing: Spacing) -> (f64, Sign) {
        match self {
            Self::Circuit(c) => circuit_param(c, sample_u(j, n), spacing),
            Self::Fixed {
                lo,
                hi,
                branch,
                closed,
            } => {
                // j < n ≤ 100 000: exact in f64.
                let t = if *closed {
                    j as f64 / n as f64
                } else {
                    j as f64 / (n.max(2) - 1) as f64
                };
                (lo + (hi - lo) * t, *branch)
            }
        }
    }

    /// Whether the traced polyline closes.
    #[must_use]
    pub fn closed(&self) -> bool {
        match self {
            Self::Circuit(_) => true,
            Self::Fixed { closed, .. } => *closed,
        }
    }
}

/// The sweeps of a mechanism in `fixed_branch` mode: each feasible interval on `branch`.
#[must_use]
pub fn fixed_sweeps(mech: &FourBar, branch: Sign) -> Vec<Sweep> {
    let range = mech.input_range();
    let full = range.full_rotation();
    range
        .intervals()
        .into_iter()
        .map(|(lo, hi)| Sweep::Fixed {
            lo,
            hi,
            branch,
            closed: full,
        })
        .collect()
}

/// The sweeps of a mechanism in `circuits` mode.
#[must_use]
pub fn circuit_sweeps(mech: &FourBar) -> Vec<Sweep> {
    mech.input_range()
        .circuits()
        .into_iter()
        .map(Sweep::Circuit)
        .collect()
}

/// Distance from `q` to the segment `a–b`.
#[must_use]
pub fn point_segment_distance(q: C64, a: C64, b: C64) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_sqr();
    let t = if len2 > 0.0 {
        (((q - a).re * ab.re + (q - a).im * ab.im) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (q - (a + ab * t)).norm()
}

/// Chord error of `circuits`-mode sampling with `n` samples per circuit (spec §8): the largest
/// distance between the true curve and the chord of two consecutive samples, the truth evaluated at
/// `sub` sub-samples per chord in the natural parameter `u`. Samples where the mechanism is singular
/// are skipped. Cost: `n·(sub + 1)` position solves per circuit.
#[must_use]
pub fn chord_error(mech: &FourBar, n: usize, spacing: Spacing, sub: usize) -> f64 {
    let mut worst = 0.0_f64;
    for circuit in mech.input_range().circuits() {
        for j in 0..n {
            let (u0, u1) = (sample_u(j, n), sample_u(j + 1, n));
            let (Some(p0), Some(p1)) = (
                curve_point(mech, &circuit, u0, spacing),
                curve_point(mech, &circuit, u1, spacing),
            ) else {
                continue;
            };
            for s in 1..sub {
                // s < sub ≤ a few hundred: exact in f64.
                let u = u0 + (u1 - u0) * (s as f64 / sub as f64);
                if let Some(q) = curve_point(mech, &circuit, u, spacing) {
                    worst = worst.max(point_segment_distance(q, p0, p1));
                }
            }
        }
    }
    worst
}
