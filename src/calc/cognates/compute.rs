//! The cognates computation in the normalised frame of [`CognatesInput`]: classification, ranges,
//! construction, snapshot/pose map, and — only when asked — curves, verification, geared five-bars
//! and metrics (spec §4).

use crate::numerics::Budget;

use super::error::CognatesError;
use super::geometry::{
    ASSEMBLY_SLACK_REL, C64, Family, FourBar, Grashof, GrashofClass, InputRange, SINGULAR_REL,
    Sign, Solve, Special, TOGGLE_REL, cognate1_branch, cognates, map_pose, wrap_pi,
};
use super::input::{CognatesInput, CurveMode, Options, SnapshotSpec, VerifyKind};
use super::sampling::{Spacing, Sweep, circuit_sweeps, fixed_sweeps};
use super::verify::{ImplicitResult, SyncAcc, hausdorff, implicit_check, segments};
// Request options carried by the validated input (read only: no wire type is built here).

/// Server cap on sampled points per request (spec §3 suggests 1e6): bounds memory (~50 MB of
/// curves) and time (~0.1 s) of one request.
pub const MAX_POINTS_TOTAL: u64 = 1_000_000;
/// Samples between two budget checks: a check costs ~25 ns, 1024 samples ~30 µs.
const BUDGET_CHECK_EVERY: u64 = 1024;
/// `|k|` or `|1 − k|` below this makes a cognate tiny next to the original (spec §7).
pub const NEAR_DEGENERATE_K: f64 = 1e-3;
/// Ratio of the largest to the smallest length above which a warning is issued (spec §7).
pub const EXTREME_ASPECT: f64 = 1e6;

/// Status of a mechanism at the snapshot pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SnapStatus {
    /// Assembled.
    Ok,
    /// Assembled at a toggle.
    Toggle,
    /// Outside the feasible range.
    NotAssemblable,
    /// Crank tip on the output pivot (dyad undetermined).
    Singular,
}

/// One mechanism at the snapshot pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnapshotResult {
    /// Status of the mechanism's own input at this pose.
    pub status: SnapStatus,
    /// Own absolute input angle \[rad\], if determined.
    pub theta: Option<f64>,
    /// Own branch, if determined.
    pub branch: Option<Sign>,
    /// Crank joint, rocker joint, coupler point.
    pub joints: Option<(C64, C64, C64)>,
    /// Transmission angle \[rad\].
    pub mu: Option<f64>,
}

/// A traced curve (normalised units).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Curve {
    /// Whether the polyline closes.
    pub closed: bool,
    /// Coupler points.
    pub points: Vec<C64>,
    /// Absolute input angles \[rad\], wrapped to (−π, π].
    pub theta: Vec<f64>,
    /// Branches.
    pub branch: Vec<Sign>,
    /// Samples dropped at singular poses.
    pub n_singular: usize,
}

/// Comparison metrics accumulated over a mechanism's circuits (normalised units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// Lower-left corner of the footprint.
    pub min: C64,
    /// Upper-right corner.
    pub max: C64,
    /// Smallest transmission angle \[rad\].
    pub mu_min: f64,
    /// Largest transmission angle \[rad\].
    pub mu_max: f64,
    /// Samples.
    pub n: usize,
}

impl Metrics {
    fn new(m: &FourBar) -> Self {
        let mut s = Self {
            min: C64::new(f64::INFINITY, f64::INFINITY),
            max: C64::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
            mu_min: f64::INFINITY,
            mu_max: 0.0,
            n: 0,
        };
        s.include(m.input_pivot);
        s.include(m.output_pivot);
        s
    }

    fn include(&mut self, p: C64) {
        self.min = C64::new(self.min.re.min(p.re), self.min.im.min(p.im));
        self.max = C64::new(self.max.re.max(p.re), self.max.im.max(p.im));
    }
}

/// Everything computed for one mechanism.
#[derive(Debug, Clone, PartialEq)]
pub struct MechOutput {
    /// The mechanism.
    pub mech: FourBar,
    /// Classification.
    pub grashof: Grashof,
    /// Feasible range.
    pub range: InputRange,
    /// Snapshot, if requested.
    pub snapshot: Option<SnapshotResult>,
    /// Curves, if requested.
    pub curves: Option<Vec<Curve>>,
    /// Metrics, if requested (with at least one sample).
    pub metrics: Option<Metrics>,
}

/// A geared five-bar equivalent (spec §4.10), normalised units.
#[derive(Debug, Clone, PartialEq)]
pub struct FiveBar {
    /// Pivot names.
    pub names: [&'static str; 2],
    /// Pivots.
    pub pivots: [C64; 2],
    /// Which family links the cranks are.
    pub from: [&'static str; 2],
    /// Crank lengths.
    pub cranks: [f64; 2],
    /// Phase ψ \[rad\].
    pub phase: f64,
    /// Dyad lengths (crank tip to P).
    pub dyads: [f64; 2],
    /// Snapshot: crank angles, tips, P, dyad residual.
    pub snapshot: Option<([f64; 2], [C64; 2], C64, f64)>,
}

/// Kind of a finding about fragile or special geometry (spec §5; wire code in output.rs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoticeKind {
    /// Grashof equality within tolerance: folded configurations, ambiguous branches.
    ChangePoint,
    /// A mechanism is a parallelogram (or a rhombus).
    Parallelogram,
    /// A mechanism is a deltoid (kite).
    Deltoid,
    /// Part of the curve is traced while the mechanism's input link stands still.
    InputLockedSegment,
    /// P lies on the line DE: the ground pivots are collinear.
    CollinearCouplerTriangle,
    /// |k| or |1−k| < 1e-3: a cognate is tiny or huge.
    NearDegenerateCognate,
    /// The snapshot is at a toggle: its branch label is ambiguous.
    SnapshotAtToggle,
    /// The lengths span more than 6 orders of magnitude.
    ExtremeAspectRatio,
    /// `fixed_branch` curves without an assembled snapshot used default branches.
    FixedBranchDefaultBranches,
}

/// A finding about fragile or special geometry, with its message in the caller's units.
#[derive(Debug, Clone, PartialEq)]
pub struct Notice {
    /// Kind.
    pub kind: NoticeKind,
    /// Human explanation naming the mechanism and values.
    pub message: String,
    /// The mechanism concerned (index into [`CognatesOutput::mechs`]), if one.
    pub mechanism: Option<usize>,
    /// Related absolute input angles \[rad\], e.g. the folded positions of a change point.
    pub angles_rad: Option<Vec<f64>>,
}

/// Output of [`compute`], normalised units (see [`CognatesInput`] for the frame).
#[derive(Debug, Clone, PartialEq)]
pub struct CognatesOutput {
    /// The family (pivots and mechanisms).
    pub family: Family,
    /// `[original, cognate1, cognate2]`.
    pub mechs: Vec<MechOutput>,
    /// `sync` result, if requested.
    pub sync: Option<SyncAcc>,
    /// `implicit` result, if requested.
    pub implicit: Option<ImplicitResult>,
    /// `hausdorff` distances (cognate 1, cognate 2) and points per curve, if requested.
    pub hausdorff: Option<(Option<f64>, Option<f64>, usize)>,
    /// Geared five-bars, if requested.
    pub fivebars: Option<Vec<FiveBar>>,
    /// Findings, in order.
    pub warnings: Vec<Notice>,
    /// Curve points returned.
    pub points_total: usize,
}

const NAMES: [&str; 3] = ["original", "cognate 1", "cognate 2"];

/// Runs the computation (pure, deterministic; checks the budget while sampling).
///
/// # Errors
/// [`CognatesError::NotAssemblable`] when no input angle assembles the linkage,
/// [`CognatesError::TooManyPoints`] above [`MAX_POINTS_TOTAL`], [`CognatesError::Deadline`] when the
/// budget runs out while sampling.
pub fn compute(input: &CognatesInput, budget: &Budget) -> Result<CognatesOutput, CognatesError> {
    let orig = input.mech;
    if !orig.assemblable(ASSEMBLY_SLACK_REL) {
        return Err(not_assemblable(&orig, input.scale));
    }
    let opts = &input.options;
    let family = cognates(&orig);
    let mut mechs: Vec<MechOutput> = family
        .mechs
        .iter()
        .map(|m| MechOutput {
            mech: *m,
            grashof: m.grashof(opts.grashof_rtol),
            range: m.input_range(),
            snapshot: None,
            curves: None,
            metrics: None,
        })
        .collect();
    let mut warnings = Vec::new();

    // Snapshot and pose map (§4.4, §4.6).
    if let Some(spec) = input.snapshot {
        let snaps = snapshots(&family, spec);
        for (m, s) in mechs.iter_mut().zip(snaps) {
            m.snapshot = Some(s);
        }
    }

    let n = opts.points();
    let need_circuits = work_plan(opts, &mechs)?;

    let mut counter = 0_u64;
    let mut sync = opts
        .verifies(VerifyKind::Sync)
        .then(|| SyncAcc::new(&family));
    let mut circuit_curves: Vec<Vec<Curve>> = Vec::new();
    if need_circuits {
        for (idx, m) in mechs.iter_mut().enumerate() {
            let sweeps = circuit_sweeps(&m.mech);
            let sync_here = if idx == 0 { sync.as_mut() } else { None };
            let (curves, metrics) = trace(
                &family,
                idx,
                &sweeps,
                (n, opts.spacing, opts.metrics),
                sync_here,
                budget,
                &mut counter,
            )?;
            if opts.metrics && metrics.n > 0 {
                m.metrics = Some(metrics);
            }
            circuit_curves.push(curves);
        }
    }
    let implicit = opts.verifies(VerifyKind::Implicit).then(|| {
        implicit_check(
            &family,
            circuit_curves
                .iter()
                .skip(1)
                .flatten()
                .flat_map(|c| c.points.iter()),
        )
    });
    let hausdorff_out = opts.verifies(VerifyKind::Hausdorff).then(|| {
        let segs: Vec<_> = circuit_curves
            .iter()
            .map(|cs| segments(cs.iter().map(|c| (c.points.as_slice(), c.closed))))
            .collect();
        (
            hausdorff(&segs[0], &segs[1]),
            hausdorff(&segs[0], &segs[2]),
            n,
        )
    });
    if opts.curves {
        if opts.curve_mode == CurveMode::Circuits {
            for (m, c) in mechs.iter_mut().zip(circuit_curves) {
                m.curves = Some(c);
            }
        } else {
            fixed_branch_curves(
                input,
                &family,
                &mut mechs,
                (budget, &mut counter),
                &mut warnings,
            )?;
        }
    }
    let points_total = mechs
        .iter()
        .flat_map(|m| m.curves.iter().flatten())
        .map(|c| c.points.len())
        .sum();
    let fivebars = opts
        .geared_fivebars
        .then(|| geared_fivebars(&family, mechs[0].snapshot.as_ref()));
    collect_warnings(input, &family, &mechs, &mut warnings);
    Ok(CognatesOutput {
        family,
        mechs,
        sync,
        implicit,
        hausdorff: hausdorff_out,
        fivebars,
        warnings,
        points_total,
    })
}

/// Work plan and point cap: whether circuits must be traced (for circuit curves, a verification
/// or the metrics); [`CognatesError::TooManyPoints`] when the planned samples exceed
/// [`MAX_POINTS_TOTAL`].
fn work_plan(opts: &Options, mechs: &[MechOutput]) -> Result<bool, CognatesError> {
    let need_circuits = (opts.curves && opts.curve_mode == CurveMode::Circuits)
        || opts.any_verify()
        || opts.metrics;
    let need_fixed = opts.curves && opts.curve_mode == CurveMode::FixedBranch;
    let n_u64 = opts.points_per_circuit;
    let circuits: u64 = mechs.iter().map(|m| m.range.circuits().len() as u64).sum();
    let intervals: u64 = mechs.iter().map(|m| m.range.intervals().len() as u64).sum();
    let requested = n_u64
        .saturating_mul(u64::from(need_circuits) * circuits + u64::from(need_fixed) * intervals);
    if requested > MAX_POINTS_TOTAL {
        return Err(CognatesError::TooManyPoints {
            requested,
            cap: MAX_POINTS_TOTAL,
        });
    }
    Ok(need_circuits)
}

/// Paper-style curves: each mechanism's own input over its range on the branch of the snapshot
/// (defaults, with a notice, without an assembled snapshot).
fn fixed_branch_curves(
    input: &CognatesInput,
    family: &Family,
    mechs: &mut [MechOutput],
    (budget, counter): (&Budget, &mut u64),
    warnings: &mut Vec<Notice>,
) -> Result<(), CognatesError> {
    let opts = &input.options;
    let (branches, defaulted) = fixed_branches(mechs, input.snapshot);
    if defaulted {
        warnings.push(notice(
            NoticeKind::FixedBranchDefaultBranches,
            "fixed_branch curves need an assembled snapshot to know each mechanism's branch; used original \
             `branch`, cognate 1 +1, cognate 2 the opposite of `branch`"
                .to_string(),
            None,
        ));
    }
    for (idx, m) in mechs.iter_mut().enumerate() {
        let sweeps = fixed_sweeps(&m.mech, branches[idx]);
        let (curves, _) = trace(
            family,
            idx,
            &sweeps,
            (opts.points(), opts.spacing, false),
            None,
            budget,
            counter,
        )?;
        m.curves = Some(curves);
    }
    Ok(())
}

fn not_assemblable(m: &FourBar, scale: f64) -> CognatesError {
    let links = [
        ("ground", m.ground),
        ("crank", m.crank),
        ("coupler", m.coupler),
        ("rocker", m.rocker),
    ];
    let (name, longest) = links
        .iter()
        .copied()
        .fold(("ground", 0.0), |acc, l| if l.1 > acc.1 { l } else { acc });
    let sum: f64 = links.iter().map(|l| l.1).sum();
    CognatesError::NotAssemblable {
        longest_name: name,
        longest: longest * scale,
        others: (sum - longest) * scale,
    }
}

fn notice(kind: NoticeKind, message: String, mechanism: Option<usize>) -> Notice {
    Notice {
        kind,
        message,
        mechanism,
        angles_rad: None,
    }
}

/// Snapshot of all three mechanisms for the original's input `spec` (spec §4.4, §4.6).
fn snapshots(family: &Family, spec: SnapshotSpec) -> [SnapshotResult; 3] {
    let orig = &family.mechs[0];
    let one = C64::new(1.0, 0.0);
    let t1 = spec.branch;
    let theta2_cog2 = wrap_pi(spec.theta + (one - orig.k).arg());
    let undetermined = |status, theta, branch| SnapshotResult {
        status,
        theta,
        branch,
        joints: None,
        mu: None,
    };
    match orig.solve(spec.theta, t1, false) {
        Solve::Pose(pose) => {
            let maps = map_pose(family, &pose);
            let mut out = [undetermined(SnapStatus::Ok, None, None); 3];
            for (i, slot) in out.iter_mut().enumerate() {
                let m = &family.mechs[i];
                let (di, ei) = maps[i];
                let (h, s) = m.dyad_height(di, ei);
                let status = if s <= SINGULAR_REL * m.scale() {
                    SnapStatus::Singular
                } else if h <= TOGGLE_REL * m.coupler {
                    SnapStatus::Toggle
                } else {
                    SnapStatus::Ok
                };
                let branch = match i {
                    0 => t1,
                    1 => cognate1_branch(orig, &pose).unwrap_or(Sign::Plus),
                    _ => t1.flip(),
                };
                let theta = if i == 0 {
                    spec.theta
                } else {
                    (di - m.input_pivot).arg()
                };
                *slot = SnapshotResult {
                    status,
                    theta: Some(theta),
                    branch: Some(branch),
                    joints: Some((di, ei, pose.p)),
                    mu: Some(m.transmission_angle(di, ei)),
                };
            }
            out
        }
        Solve::NotAssemblable { .. } => [
            undetermined(SnapStatus::NotAssemblable, Some(spec.theta), Some(t1)),
            undetermined(SnapStatus::NotAssemblable, None, None),
            undetermined(
                SnapStatus::NotAssemblable,
                Some(theta2_cog2),
                Some(t1.flip()),
            ),
        ],
        Solve::Singular { .. } => [
            undetermined(SnapStatus::Singular, Some(spec.theta), Some(t1)),
            undetermined(SnapStatus::Singular, None, None),
            undetermined(SnapStatus::Singular, Some(theta2_cog2), None),
        ],
    }
}

/// Branches for `fixed_branch` curves; `true` when defaults had to be used.
fn fixed_branches(mechs: &[MechOutput], spec: Option<SnapshotSpec>) -> ([Sign; 3], bool) {
    let t1 = spec.map_or(Sign::Plus, |s| s.branch);
    let assembled = mechs[0].snapshot.is_some_and(|s| {
        matches!(s.status, SnapStatus::Ok | SnapStatus::Toggle) && s.joints.is_some()
    });
    if assembled {
        let b1 = mechs[1]
            .snapshot
            .and_then(|s| s.branch)
            .unwrap_or(Sign::Plus);
        ([t1, b1, t1.flip()], false)
    } else {
        ([t1, Sign::Plus, t1.flip()], true)
    }
}

/// Samples one mechanism over `sweeps` with `(n, spacing, metrics)`: curves, metrics (when asked)
/// and, for the original, the `sync` check.
fn trace(
    family: &Family,
    idx: usize,
    sweeps: &[Sweep],
    (n, spacing, want_metrics): (usize, Spacing, bool),
    mut sync: Option<&mut SyncAcc>,
    budget: &Budget,
    counter: &mut u64,
) -> Result<(Vec<Curve>, Metrics), CognatesError> {
    let m = &family.mechs[idx];
    let gamma = m.ground_angle();
    let s_min = m.singular_tol();
    let mut metrics = Metrics::new(m);
    let mut curves = Vec::with_capacity(sweeps.len());
    for sweep in sweeps {
        let mut curve = Curve {
            closed: sweep.closed(),
            points: Vec::with_capacity(n),
            theta: Vec::with_capacity(n),
            branch: Vec::with_capacity(n),
            n_singular: 0,
        };
        for j in 0..n {
            *counter += 1;
            if (*counter).is_multiple_of(BUDGET_CHECK_EVERY) && budget.check(*counter).is_some() {
                return Err(CognatesError::Deadline {
                    stage: "curve sampling",
                    samples: *counter,
                });
            }
            let (phi, t) = sweep.sample(j, n, spacing);
            let theta = phi + gamma;
            match m.solve_tol(theta, t, true, s_min) {
                Solve::Pose(pose) => {
                    curve.points.push(pose.p);
                    curve.theta.push(wrap_pi(theta));
                    curve.branch.push(t);
                    if want_metrics {
                        metrics.include(pose.d);
                        metrics.include(pose.e);
                        metrics.include(pose.p);
                        let mu = m.transmission_angle(pose.d, pose.e);
                        metrics.mu_min = metrics.mu_min.min(mu);
                        metrics.mu_max = metrics.mu_max.max(mu);
                        metrics.n += 1;
                    }
                    if let Some(acc) = sync.as_deref_mut() {
                        acc.add(family, &pose, t);
                    }
                }
                Solve::NotAssemblable { .. } | Solve::Singular { .. } => curve.n_singular += 1,
            }
        }
        curves.push(curve);
    }
    Ok((curves, metrics))
}

/// One row of the §4.10 table: pivot names, pivots, crank origins, crank lengths, phase, dyads.
type FiveBarRow = (
    [&'static str; 2],
    [C64; 2],
    [&'static str; 2],
    [f64; 2],
    f64,
    [f64; 2],
);

/// The three 1:1 geared five-bars (spec §4.10).
fn geared_fivebars(family: &Family, snap: Option<&SnapshotResult>) -> Vec<FiveBar> {
    let [orig, cog1, cog2] = &family.mechs;
    let one = C64::new(1.0, 0.0);
    let k = orig.k;
    let (a, b, c) = (orig.input_pivot, orig.output_pivot, family.c);
    let specs: [FiveBarRow; 3] = [
        (
            ["A", "C"],
            [a, c],
            ["original.crank", "cognate2.crank"],
            [orig.crank, cog2.crank],
            (one - k).arg(),
            [orig.crank_joint_to_p(), cog2.crank_joint_to_p()],
        ),
        (
            ["B", "C"],
            [b, c],
            ["original.rocker", "cognate1.rocker"],
            [orig.rocker, cog1.rocker],
            k.arg(),
            [orig.rocker_joint_to_p(), cog1.rocker_joint_to_p()],
        ),
        (
            ["A", "B"],
            [a, b],
            ["cognate1.crank", "cognate2.rocker"],
            [cog1.crank, cog2.rocker],
            ((k - one) / k).arg(),
            [cog1.crank_joint_to_p(), cog2.rocker_joint_to_p()],
        ),
    ];
    let tips: Option<[[C64; 2]; 3]> = snap.and_then(|s| {
        if !matches!(s.status, SnapStatus::Ok | SnapStatus::Toggle) {
            return None;
        }
        let (d, e, p) = s.joints?;
        let pose = super::geometry::Pose {
            d,
            e,
            p,
            h: 0.0,
            s: 0.0,
        };
        let [_, (d1, e1), (d2, e2)] = map_pose(family, &pose);
        Some([[d, d2], [e, e1], [d1, e2]])
    });
    let p = snap.and_then(|s| s.joints.map(|j| j.2));
    specs
        .into_iter()
        .enumerate()
        .map(|(i, (names, pivots, from, cranks, phase, dyads))| {
            let snapshot = tips.zip(p).map(|(t, p)| {
                let [t1, t2] = t[i];
                let angles = [(t1 - pivots[0]).arg(), (t2 - pivots[1]).arg()];
                let residual = ((p - t1).norm() - dyads[0])
                    .abs()
                    .max(((p - t2).norm() - dyads[1]).abs());
                (angles, [t1, t2], p, residual)
            });
            FiveBar {
                names,
                pivots,
                from,
                cranks,
                phase: wrap_pi(phase),
                dyads,
                snapshot,
            }
        })
        .collect()
}

fn collect_warnings(
    input: &CognatesInput,
    family: &Family,
    mechs: &[MechOutput],
    out: &mut Vec<Notice>,
) {
    let rtol = input.options.grashof_rtol;
    for (i, m) in mechs.iter().enumerate() {
        let id = Some(i);
        let name = NAMES[i];
        if m.grashof.class == GrashofClass::ChangePoint {
            let folded: Vec<f64> = m.mech.folded_angles(rtol);
            out.push(Notice {
                kind: NoticeKind::ChangePoint,
                message: format!(
                    "{name} is a change-point linkage (s + l = p + q within grashof_rtol, margin {:e}): it can fold \
                     flat at the listed input angles, where both branches meet and the branch labels are ambiguous",
                    m.grashof.margin * input.scale
                ),
                mechanism: id,
                angles_rad: Some(folded),
            });
        }
        match m.grashof.special {
            Some(Special::Parallelogram) => out.push(notice(
                NoticeKind::Parallelogram,
                format!("{name} is a parallelogram (crank = rocker, coupler = ground): it can switch to the anti-parallelogram mode at the folded positions"),
                id,
            )),
            Some(Special::Rhombus) => out.push(notice(
                NoticeKind::Parallelogram,
                format!("{name} is a rhombus (all links equal): both a parallelogram and a deltoid"),
                id,
            )),
            Some(Special::DeltoidCrankGround) => out.push(notice(
                NoticeKind::Deltoid,
                format!("{name} is a deltoid with crank = ground and coupler = rocker: its crank tip reaches the output pivot"),
                id,
            )),
            Some(Special::DeltoidCrankCoupler) => out.push(notice(
                NoticeKind::Deltoid,
                format!("{name} is a deltoid with crank = coupler and rocker = ground: the coupler can fold onto the crank"),
                id,
            )),
            None => {}
        }
        if matches!(
            m.grashof.special,
            Some(Special::DeltoidCrankGround | Special::Rhombus)
        ) {
            let gamma = m.mech.ground_angle();
            out.push(Notice {
                kind: NoticeKind::InputLockedSegment,
                message: format!(
                    "{name}: at the listed input angle the crank tip sits on the output pivot; coupler and rocker can \
                     then turn about it with the input at rest, so that part of the curve cannot be driven by this \
                     mechanism's input (samples there are excluded or skipped)"
                ),
                mechanism: id,
                angles_rad: Some(vec![wrap_pi(gamma)]),
            });
        }
    }
    if input.collinear {
        out.push(notice(
            NoticeKind::CollinearCouplerTriangle,
            "the coupler point lies on the line through the coupler joints: C lies on the line AB and the cognates' \
             coupler triangles are collinear"
                .to_string(),
            None,
        ));
    }
    let k = family.mechs[0].k;
    let one = C64::new(1.0, 0.0);
    if k.norm() < NEAR_DEGENERATE_K {
        out.push(notice(
            NoticeKind::NearDegenerateCognate,
            format!("|k| = {:e} < 1e-3: P is very close to the crank joint; cognate 1 is {:e} times the original", k.norm(), k.norm()),
            Some(1),
        ));
    }
    if (one - k).norm() < NEAR_DEGENERATE_K {
        out.push(notice(
            NoticeKind::NearDegenerateCognate,
            format!(
                "|1 − k| = {:e} < 1e-3: P is very close to the rocker joint; cognate 2 is {:e} times the original",
                (one - k).norm(),
                (one - k).norm()
            ),
            Some(2),
        ));
    }
    let at_toggle = mechs[0]
        .snapshot
        .is_some_and(|s| s.status == SnapStatus::Toggle);
    if input.joints_at_toggle || at_toggle {
        out.push(notice(
            NoticeKind::SnapshotAtToggle,
            "the snapshot is at a toggle of the original (coupler and rocker collinear): both branches meet there, so \
             its branch label is ambiguous"
                .to_string(),
            Some(0),
        ));
    }
    let (lo, hi) = family
        .mechs
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), m| {
            (lo.min(m.min_length()), hi.max(m.scale()))
        });
    if hi > EXTREME_ASPECT * lo {
        out.push(notice(
            NoticeKind::ExtremeAspectRatio,
            format!(
                "the lengths of the three mechanisms span {:.3e} (> 1e6): results are exact to rounding but positions \
                 near toggles lose digits in proportion",
                hi / lo
            ),
            None,
        ));
    }
}
