//! The rules of a [`SpatialCouplingRequest`] that JSON Schema cannot state (spec §2), turning it
//! into the domain input. Every range and list length is declared on the wire types and checked
//! at the door; what is left is `PERPENDICULAR_SHAFTS` (|cos 2α| < 1e-9, a hole in α's range).
//! The support-plane validity test of a sweep is a property of the whole configuration and fails
//! in `compute` (`SUPPORT_PLANE_INVALID`). Every rule is listed in [`CROSS_FIELD_RULES`].

use std::time::Duration;

use crate::calc::common::Sign;
use crate::calc::rules::ensure_rule;
use crate::calc::{CalcFailure, Validator};
use crate::numerics::angles::sin_cos_deg;

use super::wire::{MIN_ABS_COS_2ALPHA, SpatialCouplingRequest, Vec3};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/spatial-coupling`, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid PERPENDICULAR_SHAFTS ["/alpha_deg"]
        "|cos 2α| ≥ 1e-9: α = ±45° makes the shafts perpendicular (dead points, i12 = 0/0).";
    /// A sweep's contact point stays finite (found while computing).
    infeasible SUPPORT_PLANE_INVALID ["/beta_deg", "/alpha_deg", "/sweep"]
        "With a `sweep`, cos(α−β)·cos 2α·cos(α+β) > 0 (the contact point is finite at every θ1).";
    /// The work fits the time budget (found while computing).
    too_large DEADLINE_EXCEEDED ["/time_limit_ms", "/sweep/n_points", "/theta1_deg"]
        "The requested points are computed within the request's time limit.";
    listed crate::calc::common::RESPONSE_TOO_LARGE_RULE;
}

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
        // Every range and list length is checked at the door.
        let mut v = Validator::new();
        let alpha_deg = req.alpha_deg.unwrap_or(DEFAULT_ALPHA_DEG);
        let c2a = sin_cos_deg(2.0 * alpha_deg).1;
        ensure_rule!(v, c2a.abs() >= MIN_ABS_COS_2ALPHA, PERPENDICULAR_SHAFTS, "/alpha_deg";
            "|cos 2α| must be ≥ {MIN_ABS_COS_2ALPHA:e} (α = ±45° makes the shafts \
                     perpendicular: dead points, i12 = 0/0), got |cos 2α| = {:e} at α = \
                     {alpha_deg}°",
            c2a.abs());
        let a = req.a_m.unwrap_or(1.0);
        // β defaults to α.
        let beta_deg = req.beta_deg.unwrap_or(alpha_deg);
        let omega1 = req.omega1_rad_s.unwrap_or(1.0);
        let points = req.theta1_deg.unwrap_or_default();
        let sweep = req.sweep.map(|s| Sweep {
            start_deg: s.start_deg.unwrap_or(DEFAULT_SWEEP.start_deg),
            end_deg: s.end_deg.unwrap_or(DEFAULT_SWEEP.end_deg),
            // n ≤ 1e6 (checked at the door): the conversion cannot fail.
            n_points: s.n_points.map_or(DEFAULT_SWEEP.n_points, |n| {
                usize::try_from(n).unwrap_or(DEFAULT_SWEEP.n_points)
            }),
        });
        let sweep = if sweep.is_none() && points.is_empty() {
            Some(DEFAULT_SWEEP)
        } else {
            sweep
        };
        let body3: Vec<Vec3> = req.body3_points_m.unwrap_or_default();
        let o = req.outputs;
        let time_limit = req.time_limit_ms.map(Duration::from_millis);
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
            // decimate ≤ 1e6 (checked at the door): the conversion cannot fail.
            decimate: usize::try_from(o.decimate).unwrap_or(1),
            time_limit,
        })
    }
}
