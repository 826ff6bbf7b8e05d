//! The one place that builds the wire response: units back (deg), optional groups, warnings and
//! the report.

use crate::calc::common::Warning;
use crate::numerics::{Budget, SolverReport, StopReason};

use super::compute::{
    Body3Out, CheckOut, ContactOut, FramesOut, PointKin, PointResult, RelOut,
    SpatialCouplingOutput, SweepSummary, plane_usable,
};
use super::input::SpatialCouplingInput;
use super::wire::{
    Body3Point, Check, Configuration, Contact, Frames, LemniscateBox, Point, PointEntry,
    PointError, PointFailure, Relative1, Relative2, SpatialCouplingResponse, Summary, SupportPlane,
};

/// |cos 2α| below this: the ratio peaks above 10 (spec §2 warning).
pub const WARN_ABS_COS_2ALPHA: f64 = 0.1;
/// min|D|/max|D| below this: the contact point is ill-conditioned (spec §2 warning).
pub const WARN_D_RATIO: f64 = 1e-3;
/// |rB|/a above this: the contact point is far away (B near infinity).
pub const WARN_RADIUS_OVER_A: f64 = 1e3;
/// |θ1| above this \[deg\]: one ulp of θ1 exceeds 1e-6°.
pub const WARN_LARGE_ANGLE_DEG: f64 = 8.0e9;

/// Builds the response.
#[must_use]
pub fn respond(
    input: &SpatialCouplingInput,
    out: &SpatialCouplingOutput,
    budget: &Budget,
) -> SpatialCouplingResponse {
    let cpl = &out.coupling;
    let c = cpl.c2a.abs();
    let configuration = Configuration {
        cardan_bend_angle_deg: 2.0 * input.alpha_deg,
        homokinetic: cpl.homokinetic(),
        ratio_range_abs: [c, 1.0 / c],
        fluctuation: 1.0 / c - c,
        i12_mean: if cpl.c2a > 0.0 { -1.0 } else { 1.0 },
        support_plane: SupportPlane {
            valid: plane_usable(cpl),
            d_at_0: cpl.d0,
            d_at_90: cpl.d90,
            d_min_over_max: cpl.d_min_over_max(),
            d_roots_theta1_deg: cpl.d_roots_deg(),
        },
    };
    let points = (!input.points.is_empty()).then(|| {
        out.points
            .iter()
            .map(|p| match p {
                PointResult::Ok(p) => PointEntry::Point(Box::new(point(p))),
                PointResult::AtInfinity { theta1_deg, d } => PointEntry::Error(PointFailure {
                    error: PointError {
                        code: "CONTACT_AT_INFINITY".to_owned(),
                        message: format!(
                            "the support plane is parallel to the line of planes P1 and P2 at \
                             θ1 = {theta1_deg}°: D = {d:e} is zero to round-off and the contact \
                             point B is at infinity"
                        ),
                        theta1_deg: *theta1_deg,
                    },
                }),
            })
            .collect()
    });
    let (summary, series) = match &out.sweep {
        Some(s) => (
            input
                .summary
                .then(|| summary(&s.summary, cpl.homokinetic())),
            s.series.as_ref().map(|v| v.iter().map(point).collect()),
        ),
        None => (None, None),
    };
    SpatialCouplingResponse {
        configuration,
        points,
        summary,
        series,
        warnings: warnings(input, out),
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations: out.evaluated,
            evaluations: out.evaluated,
            elapsed_ms: budget.elapsed_ms(),
        },
    }
}

fn warnings(input: &SpatialCouplingInput, out: &SpatialCouplingOutput) -> Vec<Warning> {
    let cpl = &out.coupling;
    let mut w = Vec::new();
    if cpl.c2a.abs() < WARN_ABS_COS_2ALPHA {
        w.push(Warning::at(
            "NEAR_PERPENDICULAR_SHAFTS",
            "/alpha_deg",
            format!(
                "|cos 2α| = {:e} < {WARN_ABS_COS_2ALPHA}: |i12| peaks at 1/|cos 2α| = {:e} near \
                 θ1 = 0° and 180°, with very large output accelerations",
                cpl.c2a.abs(),
                1.0 / cpl.c2a.abs()
            ),
        ));
    }
    if !plane_usable(cpl) {
        w.push(Warning::at(
            "SUPPORT_PLANE_INVALID",
            "/beta_deg",
            format!(
                "cos(α−β)·cos 2α·cos(α+β) is not > 0 (D(0) = {:e}, D(90°) = {:e}): the contact \
                 point goes to infinity at θ1 = {:?}°; points there answer with an error object",
                cpl.d0,
                cpl.d90,
                cpl.d_roots_deg()
            ),
        ));
    } else if cpl.d_min_over_max() < WARN_D_RATIO {
        w.push(Warning::at(
            "CONTACT_ILL_CONDITIONED",
            "/beta_deg",
            format!(
                "min|D|/max|D| = {:e} < {WARN_D_RATIO}: the support plane is nearly parallel to \
                 the line of planes P1 and P2 at some θ1, the contact point is far away there",
                cpl.d_min_over_max()
            ),
        ));
    }
    if out.max_radius_over_a > WARN_RADIUS_OVER_A {
        w.push(Warning::at(
            "CONTACT_POINT_FAR",
            "/beta_deg",
            format!(
                "|rB| reaches {:e}·a: the contact point is far from the shafts",
                out.max_radius_over_a
            ),
        ));
    }
    let big = input
        .points
        .iter()
        .copied()
        .chain(input.sweep.iter().flat_map(|s| [s.start_deg, s.end_deg]))
        .any(|t| t.abs() > WARN_LARGE_ANGLE_DEG);
    if big {
        w.push(Warning::new(
            "LARGE_ANGLE",
            format!(
                "an input angle exceeds {WARN_LARGE_ANGLE_DEG:e}°: its resolution is coarser than \
                 1e-6° (reduced modulo 360°)"
            ),
        ));
    }
    w
}

fn summary(s: &SweepSummary, homokinetic: bool) -> Summary {
    Summary {
        n_points: s.n,
        homokinetic,
        i12_min: s.i12[0],
        i12_max: s.i12[1],
        ratio_range_abs: s.i12_abs,
        fluctuation: s.i12_abs[1] - s.i12_abs[0],
        theta31_amplitude_deg: 0.5 * (s.theta31[1] - s.theta31[0]),
        theta32_amplitude_deg: 0.5 * (s.theta32[1] - s.theta32[0]),
        rB_radius_range_m: s.r_b,
        vB_range_m_s: s.v_b,
        lemniscate_box_m: LemniscateBox { x: s.x2, z: s.z2 },
        omega31_max_abs: s.omega31,
        omega32_max_abs: s.omega32,
        D_min_over_max: s.d_abs[0] / s.d_abs[1],
    }
}

fn point(p: &PointKin) -> Point {
    Point {
        theta1_deg: p.theta1_deg,
        theta2_deg: p.theta2_deg,
        i12: p.i12,
        di12_dtheta1: p.di12,
        omega2_rad_s: p.omega2,
        epsilon2_rad_s2: p.epsilon2,
        contact: p.contact.as_ref().map(contact),
        relative_1: p.rel1.as_ref().map(|r: &RelOut| Relative1 {
            x1B_m: r.x,
            z1B_m: r.z,
            vx1B_m_s: r.vx,
            vz1B_m_s: r.vz,
            theta31_deg: r.theta_deg,
            omega31_rad_s: r.omega,
        }),
        relative_2: p.rel2.as_ref().map(|r: &RelOut| Relative2 {
            x2B_m: r.x,
            z2B_m: r.z,
            vx2B_m_s: r.vx,
            vz2B_m_s: r.vz,
            theta32_deg: r.theta_deg,
            omega32_rad_s: r.omega,
        }),
        frames: p.frames.as_ref().map(frames),
        body3_points: p.body3.as_ref().map(|v| v.iter().map(body3).collect()),
        check: p.check.as_ref().map(check),
    }
}

fn contact(c: &ContactOut) -> Contact {
    Contact {
        rB_m: c.r,
        vB_m_s: c.v,
        vB_mag: c.speed,
        D: c.d,
    }
}

fn frames(f: &FramesOut) -> Frames {
    let [i1, j1, k1] = f.frames.f1;
    let [i2, j2, k2] = f.frames.f2;
    let [i3, j3, k3] = f.frames.f3;
    Frames {
        i1,
        j1,
        k1,
        i2,
        j2,
        k2,
        i3,
        j3,
        k3,
        T13: f.t13,
        T23: f.t23,
    }
}

fn body3(b: &Body3Out) -> Body3Point {
    Body3Point {
        r0_m: b.r0,
        r1_m: b.r1,
        r2_m: b.r2,
        v0_m_s: b.v0,
        v1_m_s: b.v1,
        v2_m_s: b.v2,
    }
}

fn check(c: &CheckOut) -> Check {
    Check {
        max_residual: c.closure.iter().copied().fold(c.orthonormality, f64::max),
        closure: c.closure,
        orthonormality: c.orthonormality,
    }
}
