//! The one place that builds the wire response of `POST /v1/cognates` from the domain output:
//! the normalised frame back to the caller's units, the optional outputs (snapshot, curves,
//! verification, geared five-bars, metrics) and the warnings.

use std::time::Instant;

use crate::numerics::{SolverReport, StopReason};

use super::compute::{
    CognatesOutput, Curve, FiveBar, MechOutput, Metrics, Notice, NoticeKind, SnapStatus,
    SnapshotResult,
};
use super::geometry::{self, C64, GrashofClass, LinkRole, LinkageType, Special, wrap_pi};
use super::input::CognatesInput;
use super::verify;
use super::wire::{
    CognatesResponse, CurveOut, FiveBarSnapshot, Footprint, GearedFiveBar, GrashofClassOut,
    GrashofOut, HausdorffCheck, ImplicitCheck, InputRangeOut, JointsOut, LinkRoleOut,
    LinkageTypeOut, Links, MechanismId, MechanismOut, Meta, MetricsOut, OriginalLink, RotationMap,
    SimilarSides, Similarity, SnapshotOut, SnapshotStatus, SpecialOut, SyncCheck, TurnsWith,
    Verification, Warning, WarningCode,
};

/// Builds the response: the normalised output back in the caller's units, and its cost
/// (`report`, and the deprecated `meta.compute_us`) counted from `start` (the request's arrival in [`run`](super::run)).
#[must_use]
pub fn respond(input: &CognatesInput, out: &CognatesOutput, start: Instant) -> CognatesResponse {
    let fr = Frame {
        origin: input.origin,
        scale: input.scale,
    };
    let family = &out.family;
    let orig = &family.mechs[0];
    let k = orig.k;
    let one = C64::new(1.0, 0.0);
    let c_pt = fr.pt(family.c);
    // Pivots echoed exactly where they are the caller's A and B.
    let pivots = [
        (input.a_raw, input.b_raw),
        (input.a_raw, c_pt),
        (c_pt, input.b_raw),
    ];
    let mechanisms = out
        .mechs
        .iter()
        .enumerate()
        .map(|(i, m)| mechanism_out(&fr, IDS[i], i, m, pivots[i], input.side.value(), k))
        .collect();
    let scale_l = orig.scale();
    let sync = out.sync.map(|s| SyncCheck {
        max_dev: fr.len(s.max_dev),
        max_dev_regular: fr.len(s.max_dev_regular),
        max_constraint_residual: fr.len(s.max_constraint_residual),
        n_samples: s.n_samples,
        n_near_toggle: s.n_near_toggle,
        n_skipped_locked: s.n_skipped_locked,
        passed: s.max_constraint_residual <= verify::SYNC_RESIDUAL_PASS_REL * scale_l
            && s.max_dev_regular <= verify::SYNC_DEV_PASS_REL * scale_l,
    });
    let implicit = out.implicit.map(|r| ImplicitCheck {
        max_dist: fr.len(r.max_dist),
        n_points: r.n_points,
        n_skipped_double_points: r.n_skipped,
        passed: r.max_dist <= verify::IMPLICIT_PASS_REL * scale_l,
    });
    let hausdorff = out.hausdorff.map(|(h1, h2, n)| HausdorffCheck {
        cognate1: h1.map(|x| fr.len(x)),
        cognate2: h2.map(|x| fr.len(x)),
        max: h1.zip(h2).map(|(a, b)| fr.len(a.max(b))),
        n_points: n,
    });
    let verification =
        (sync.is_some() || implicit.is_some() || hausdorff.is_some()).then_some(Verification {
            sync,
            implicit,
            hausdorff,
        });
    let mut resp = CognatesResponse {
        c: c_pt,
        similarity: Similarity {
            ratio_ac_ab: k.norm(),
            ratio_bc_ab: (one - k).norm(),
            angle_at_a_deg: k.arg().to_degrees(),
            k: [k.re, k.im],
        },
        mechanisms,
        verification,
        geared_fivebars: out
            .fivebars
            .as_ref()
            .map(|f| f.iter().map(|b| fivebar_out(&fr, b)).collect()),
        warnings: out.warnings.iter().map(warning).collect(),
        report: SolverReport {
            stop_reason: StopReason::Completed,
            iterations: 0,
            evaluations: 0,
            elapsed_ms: 0.0,
        },
        meta: Meta {
            points_total: out.points_total,
            compute_us: 0,
        },
    };
    let elapsed = start.elapsed();
    let points = u64::try_from(out.points_total).unwrap_or(u64::MAX);
    resp.report.iterations = points;
    resp.report.evaluations = points;
    resp.report.elapsed_ms = elapsed.as_secs_f64() * 1e3;
    resp.meta.compute_us = u64::try_from(elapsed.as_micros()).unwrap_or(u64::MAX);
    resp
}

/// Wire code of a domain finding.
impl From<NoticeKind> for WarningCode {
    fn from(k: NoticeKind) -> Self {
        match k {
            NoticeKind::ChangePoint => Self::ChangePoint,
            NoticeKind::Parallelogram => Self::Parallelogram,
            NoticeKind::Deltoid => Self::Deltoid,
            NoticeKind::InputLockedSegment => Self::InputLockedSegment,
            NoticeKind::CollinearCouplerTriangle => Self::CollinearCouplerTriangle,
            NoticeKind::NearDegenerateCognate => Self::NearDegenerateCognate,
            NoticeKind::SnapshotAtToggle => Self::SnapshotAtToggle,
            NoticeKind::ExtremeAspectRatio => Self::ExtremeAspectRatio,
            NoticeKind::FixedBranchDefaultBranches => Self::FixedBranchDefaultBranches,
        }
    }
}

/// The mechanisms in the order of [`CognatesOutput::mechs`].
const IDS: [MechanismId; 3] = [
    MechanismId::Original,
    MechanismId::Cognate1,
    MechanismId::Cognate2,
];

/// Wire form of a domain finding (angles back in degrees).
fn warning(n: &Notice) -> Warning {
    Warning {
        code: n.kind.into(),
        message: n.message.clone(),
        mechanism: n.mechanism.map(|i| IDS[i]),
        angles_deg: n
            .angles_rad
            .as_ref()
            .map(|a| a.iter().map(|x| x.to_degrees()).collect()),
    }
}

/// The normalised frame: caller = origin + scale·internal.
struct Frame {
    origin: C64,
    scale: f64,
}

impl Frame {
    fn pt(&self, z: C64) -> [f64; 2] {
        let w = self.origin + z * self.scale;
        [w.re, w.im]
    }
    fn len(&self, x: f64) -> f64 {
        x * self.scale
    }
}

fn deg(rad: f64) -> f64 {
    wrap_pi(rad).to_degrees()
}

fn mechanism_out(
    fr: &Frame,
    id: MechanismId,
    i: usize,
    m: &MechOutput,
    (pin, pout): ([f64; 2], [f64; 2]),
    t2: f64,
    k_orig: C64,
) -> MechanismOut {
    let mech = &m.mech;
    let one = C64::new(1.0, 0.0);
    let gamma = mech.ground_angle();
    let (cj, rj) = (mech.crank_joint_to_p(), mech.rocker_joint_to_p());
    let similar = match i {
        0 => (mech.coupler, cj, rj),
        1 => (cj, mech.coupler, rj),
        _ => (rj, cj, mech.coupler),
    };
    let side = if i == 0 { t2 } else { -t2 };
    let intervals = m.range.intervals();
    let rotation_map = match i {
        1 => Some(RotationMap {
            crank: TurnsWith {
                turns_with: OriginalLink::Coupler,
                offset_deg: deg(k_orig.arg()),
            },
            coupler: TurnsWith {
                turns_with: OriginalLink::Crank,
                offset_deg: deg(k_orig.arg()),
            },
            rocker: TurnsWith {
                turns_with: OriginalLink::Rocker,
                offset_deg: deg(k_orig.arg()),
            },
            same_timing_as_original: false,
        }),
        2 => Some(RotationMap {
            crank: TurnsWith {
                turns_with: OriginalLink::Crank,
                offset_deg: deg((one - k_orig).arg()),
            },
            coupler: TurnsWith {
                turns_with: OriginalLink::Rocker,
                offset_deg: deg((k_orig - one).arg()),
            },
            rocker: TurnsWith {
                turns_with: OriginalLink::Coupler,
                offset_deg: deg((k_orig - one).arg()),
            },
            same_timing_as_original: true,
        }),
        _ => None,
    };
    MechanismOut {
        id,
        input_pivot: pin,
        output_pivot: pout,
        ground_angle_deg: deg(gamma),
        links: Links {
            ground: fr.len(mech.ground),
            crank: fr.len(mech.crank),
            coupler: fr.len(mech.coupler),
            rocker: fr.len(mech.rocker),
            crank_joint_to_p: fr.len(cj),
            rocker_joint_to_p: fr.len(rj),
            coupler_side: if side > 0.0 { 1 } else { -1 },
            coupler_angle_at_crank_joint_deg: mech.k.arg().abs().to_degrees(),
            k: [mech.k.re, mech.k.im],
        },
        similar_sides: SimilarSides {
            b: fr.len(similar.0),
            d: fr.len(similar.1),
            e: fr.len(similar.2),
        },
        grashof: grashof_out(fr, &m.grashof),
        input_range: InputRangeOut {
            intervals_rel_deg: intervals
                .iter()
                .map(|(lo, hi)| [lo.to_degrees(), hi.to_degrees()])
                .collect(),
            intervals_abs_deg: intervals
                .iter()
                .map(|(lo, hi)| {
                    let start = deg(lo + gamma);
                    [start, start + (hi - lo).to_degrees()]
                })
                .collect(),
            full_rotation: m.range.full_rotation(),
            toggle_angles_abs_deg: m
                .range
                .toggles()
                .into_iter()
                .map(|t| deg(t + gamma))
                .collect(),
            n_circuits: m.range.circuits().len(),
        },
        rotation_map,
        snapshot: m
            .snapshot
            .as_ref()
            .map(|s| snapshot_out(fr, s, gamma, (pin, pout))),
        curves: m
            .curves
            .as_ref()
            .map(|cs| cs.iter().map(|c| curve_out(fr, c)).collect()),
        metrics: m.metrics.as_ref().map(|x| metrics_out(fr, i, m, x)),
    }
}

fn grashof_out(fr: &Frame, g: &geometry::Grashof) -> GrashofOut {
    let role = |r: LinkRole| match r {
        LinkRole::Ground => LinkRoleOut::Ground,
        LinkRole::Input => LinkRoleOut::Input,
        LinkRole::Coupler => LinkRoleOut::Coupler,
        LinkRole::Output => LinkRoleOut::Output,
    };
    GrashofOut {
        class: match g.class {
            GrashofClass::Grashof => GrashofClassOut::Grashof,
            GrashofClass::NonGrashof => GrashofClassOut::NonGrashof,
            GrashofClass::ChangePoint => GrashofClassOut::ChangePoint,
        },
        kind: match g.kind {
            LinkageType::DoubleCrank => LinkageTypeOut::DoubleCrank,
            LinkageType::CrankRocker => LinkageTypeOut::CrankRocker,
            LinkageType::DoubleRocker => LinkageTypeOut::DoubleRocker,
            LinkageType::RockerCrank => LinkageTypeOut::RockerCrank,
            LinkageType::TripleRocker => LinkageTypeOut::TripleRocker,
            LinkageType::ChangePoint => LinkageTypeOut::ChangePoint,
        },
        barker: g.barker.map(str::to_string),
        special: g.special.map(|s| match s {
            Special::Parallelogram => SpecialOut::Parallelogram,
            Special::DeltoidCrankGround | Special::DeltoidCrankCoupler => SpecialOut::Deltoid,
            Special::Rhombus => SpecialOut::Rhombus,
        }),
        margin: fr.len(g.margin),
        s_plus_l: fr.len(g.s_plus_l),
        p_plus_q: fr.len(g.p_plus_q),
        shortest: role(g.shortest),
        longest: role(g.longest),
    }
}

fn snapshot_out(
    fr: &Frame,
    s: &SnapshotResult,
    gamma: f64,
    (pin, pout): ([f64; 2], [f64; 2]),
) -> SnapshotOut {
    SnapshotOut {
        status: match s.status {
            SnapStatus::Ok => SnapshotStatus::Ok,
            SnapStatus::Toggle => SnapshotStatus::Toggle,
            SnapStatus::NotAssemblable => SnapshotStatus::NotAssemblable,
            SnapStatus::Singular => SnapshotStatus::Singular,
        },
        input_angle_deg: s.theta.map(deg),
        input_angle_rel_deg: s.theta.map(|t| deg(t - gamma)),
        branch: s.branch.map(geometry::Sign::as_i8),
        joints: s.joints.map(|(d, e, p)| JointsOut {
            input_pivot: pin,
            crank_joint: fr.pt(d),
            rocker_joint: fr.pt(e),
            output_pivot: pout,
            p: fr.pt(p),
        }),
        transmission_angle_deg: s.mu.map(f64::to_degrees),
    }
}

fn curve_out(fr: &Frame, c: &Curve) -> CurveOut {
    CurveOut {
        closed: c.closed,
        points: c.points.iter().map(|p| fr.pt(*p)).collect(),
        input_deg: c.theta.iter().map(|t| t.to_degrees()).collect(),
        branch: c.branch.iter().map(|b| b.as_i8()).collect(),
        n_singular_excluded: c.n_singular,
    }
}

fn metrics_out(fr: &Frame, i: usize, m: &MechOutput, x: &Metrics) -> MetricsOut {
    let mech = &m.mech;
    let (lo, hi) = (fr.pt(x.min), fr.pt(x.max));
    let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
    MetricsOut {
        link_length_sum: fr.len(mech.ground + mech.crank + mech.coupler + mech.rocker),
        ground_span: fr.len(mech.ground),
        coupler_max_side: fr.len(
            mech.coupler
                .max(mech.crank_joint_to_p())
                .max(mech.rocker_joint_to_p()),
        ),
        footprint: Footprint {
            min: lo,
            max: hi,
            width: w,
            height: h,
            area: w * h,
        },
        transmission_angle_min_deg: x.mu_min.to_degrees(),
        transmission_angle_max_deg: x.mu_max.to_degrees(),
        full_rotation: m.range.full_rotation(),
        timing_equals_original: i != 1,
        n_samples: x.n,
    }
}

fn fivebar_out(fr: &Frame, b: &FiveBar) -> GearedFiveBar {
    GearedFiveBar {
        pivot_names: b.names.map(str::to_string),
        pivots: b.pivots.map(|p| fr.pt(p)),
        from: b.from.map(str::to_string),
        crank1: fr.len(b.cranks[0]),
        crank2: fr.len(b.cranks[1]),
        phase_deg: b.phase.to_degrees(),
        dyad1: fr.len(b.dyads[0]),
        dyad2: fr.len(b.dyads[1]),
        snapshot: b
            .snapshot
            .map(|(angles, tips, p, residual)| FiveBarSnapshot {
                crank1_angle_deg: deg(angles[0]),
                crank2_angle_deg: deg(angles[1]),
                crank1_tip: fr.pt(tips[0]),
                crank2_tip: fr.pt(tips[1]),
                p: fr.pt(p),
                dyad_residual: fr.len(residual),
            }),
    }
}
