//! Validation of a [`SpatialCouplingRequest`] into the domain input (spec §2).
//!
//! Every offending field is reported with its JSON pointer. Codes: `PERPENDICULAR_SHAFTS`
//! (|cos 2α| < 1e-9), `INVALID_INPUT` otherwise. The support-plane validity test of a sweep is a
//! property of the whole configuration and fails in `compute` (`SUPPORT_PLANE_INVALID`).

use std::time::Duration;

use crate::calc::common::{Sign, time_limit};
use crate::calc::{CalcFailure, Validator};
use crate::numerics::angles::sin_cos_deg;

use super::wire::{
    A_M, ALPHA_DEG, BETA_DEG, BODY3_COORD_M, DECIMATE, MAX_BODY3_POINTS, MAX_THETA1_POINTS,
    MIN_ABS_COS_2ALPHA, N_POINTS, OMEGA1, SpatialCouplingRequest, THETA1_DEG, Vec3,
};

/// Default α \[deg\] (spec §2; the paper-like case).
pub const DEFAULT_ALPHA_DEG: f64 = 15.0;
/// Default sweep (spec §2): 0° … 360°, 721 points.
pub const DEFAULT_SWEEP: Sweep = Sweep {
    start_deg: 0.0,
    end_deg: 360.0,
    n_points: 721,
};

/// A uniform sweep of θ1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// First θ1 \[deg\].
    pub start_deg: f64,
    /// Last θ1 \[deg\].
    pub end_deg: f64,
    /// Number of points (≥ 2).
    pub n_points: usize,
}

impl Sweep {
    /// θ1 \[deg\] of point `k` (the last point is `end_deg` exactly).
    #[must_use]
    pub fn theta1_deg(&self, k: usize) -> f64 {
        if k + 1 >= self.n_points {
            return self.end_deg;
        }
        // Counts are ≤ 10⁶: exact in f64.
        let t = k as f64 / (self.n_points - 1) as f64;
        let span = self.end_deg - self.start_deg;
        if span.is_finite() {
            self.start_deg + t * span
        } else {
            // Ends of opposite sign near ±f64::MAX: the convex form cannot overflow.
            (1.0 - t) * self.start_deg + t * self.end_deg
        }
    }
}

/// Requested output groups.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Groups {
    /// Contact point.
    pub contact: bool,
    /// Relative to shaft 1.
    pub relative_1: bool,
    /// Relative to shaft 2.
    pub relative_2: bool,
    /// Frames.
    pub frames: bool,
    /// Closure check.
    pub check: bool,
}

/// The validated request (angles in degrees as given, lengths in m, rates in rad/s).
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialCouplingInput {
    /// α \[deg\].
    pub alpha_deg: f64,
    /// β \[deg\].
    pub beta_deg: f64,
    /// a \[m\].
    pub a: f64,
    /// ω1 [rad/s].
    pub omega1: f64,
    /// σ = ±1.
    pub sigma: f64,
    /// Single input angles \[deg\].
    pub points: Vec<f64>,
    /// Sweep, if any (the default sweep when neither points nor a sweep were given).
    pub sweep: Option<Sweep>,
    /// Body-3 points in frame 3 \[m\].
    pub body3: Vec<Vec3>,
    /// Output groups of every point.
    pub groups: Groups,
    /// Sweep summary.
    pub summary: bool,
    /// Sweep series.
    pub series: bool,
    /// Keep every `decimate`-th sweep point in the series.
    pub decimate: usize,
    /// The request's own time limit.
    pub time_limit: Option<Duration>,
}

impl TryFrom<SpatialCouplingRequest> for SpatialCouplingInput {
    type Error = CalcFailure;

    fn try_from(req: SpatialCouplingRequest) -> Result<Self, Self::Error> {
        let mut v = Validator::new();
        let alpha_deg = req.alpha_deg.unwrap_or(DEFAULT_ALPHA_DEG);
        let alpha_ok = v.range("/alpha_deg", "alpha_deg", alpha_deg, ALPHA_DEG);
        if alpha_ok {
            let c2a = sin_cos_deg(2.0 * alpha_deg).1;
            v.ensure_code(
                c2a.abs() >= MIN_ABS_COS_2ALPHA,
                "PERPENDICULAR_SHAFTS",
                "/alpha_deg",
                || {
                    format!(
                        "|cos 2α| must be ≥ {MIN_ABS_COS_2ALPHA:e} (α = ±45° makes the shafts \
                         perpendicular: dead points, i12 = 0/0), got |cos 2α| = {:e} at α = \
                         {alpha_deg}°",
                        c2a.abs()
                    )
                },
            );
        }
        let a = req.a_m.unwrap_or(1.0);
        v.range("/a_m", "a_m", a, A_M);
        let beta_deg = req.beta_deg.unwrap_or(alpha_deg);
        // β defaults to α: an invalid α is reported once, at /alpha_deg.
        if req.beta_deg.is_some() || alpha_ok {
            v.range("/beta_deg", "beta_deg", beta_deg, BETA_DEG);
        }
        let omega1 = req.omega1_rad_s.unwrap_or(1.0);
        v.range("/omega1_rad_s", "omega1_rad_s", omega1, OMEGA1);
        let points = req.theta1_deg.unwrap_or_default();
        v.ensure(points.len() <= MAX_THETA1_POINTS, "/theta1_deg", || {
            format!(
                "at most {MAX_THETA1_POINTS} input angles per request (use a sweep), got {}",
                points.len()
            )
        });
        v.all_in("/theta1_deg", "theta1_deg", &points, THETA1_DEG);
        let sweep = req.sweep.map(|s| {
            let start_deg = s.start_deg.unwrap_or(DEFAULT_SWEEP.start_deg);
            let end_deg = s.end_deg.unwrap_or(DEFAULT_SWEEP.end_deg);
            let n = s.n_points.unwrap_or(721);
            v.range("/sweep/start_deg", "start_deg", start_deg, THETA1_DEG);
            v.range("/sweep/end_deg", "end_deg", end_deg, THETA1_DEG);
            let n_ok = v.uint("/sweep/n_points", "n_points", n, N_POINTS);
            Sweep {
                start_deg,
                end_deg,
                n_points: if n_ok {
                    usize::try_from(n).unwrap_or(DEFAULT_SWEEP.n_points)
                } else {
                    DEFAULT_SWEEP.n_points
                },
            }
        });
        let sweep = if sweep.is_none() && points.is_empty() {
            Some(DEFAULT_SWEEP)
        } else {
            sweep
        };
        let body3 = req.body3_points_m.unwrap_or_default();
        v.ensure(body3.len() <= MAX_BODY3_POINTS, "/body3_points_m", || {
            format!(
                "at most {MAX_BODY3_POINTS} body-3 points, got {}",
                body3.len()
            )
        });
        for (i, p) in body3.iter().enumerate() {
            v.all_in(
                &format!("/body3_points_m/{i}"),
                "coordinate",
                p,
                BODY3_COORD_M,
            );
        }
        let o = req.outputs;
        let decimate_ok = v.uint("/outputs/decimate", "decimate", o.decimate, DECIMATE);
        let time_limit = time_limit(&mut v, req.time_limit_ms);
        v.finish()?;
        Ok(Self {
            alpha_deg,
            beta_deg,
            a,
            omega1,
            sigma: match req.branch.unwrap_or_default() {
                Sign::Plus => 1.0,
                Sign::Minus => -1.0,
            },
            points,
            sweep,
            body3,
            groups: Groups {
                contact: o.contact,
                relative_1: o.relative_1,
                relative_2: o.relative_2,
                frames: o.frames,
                check: o.check,
            },
            summary: o.summary,
            series: o.series,
            decimate: if decimate_ok {
                usize::try_from(o.decimate).unwrap_or(1)
            } else {
                1
            },
            time_limit,
        })
    }
}
