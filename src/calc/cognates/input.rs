//! Validation of a [`CognatesRequest`] into the domain input (spec §3, §4.1).
//!
//! Every offending field is collected with its JSON pointer and a message naming the quantity, the
//! value and the broken limit; the failure carries the spec's code of the first problem
//! (`NON_POSITIVE_LENGTH`, `COINCIDENT_PIVOTS`, `COUPLER_TRIANGLE_INVALID`, `COUPLER_POINT_AT_JOINT`,
//! else `INVALID_INPUT`).
//!
//! Internally the linkage is expressed in a normalised frame: origin at A and lengths divided by a
//! power of two close to the largest length L (an exact scaling), so every tolerance is absolute and
//! no square can overflow or underflow whatever the caller's unit.

use crate::calc::{CalcFailure, FieldIssue, ProblemClass};

use super::geometry::{C64, FourBar, Sign, cis, cross};
use super::wire::{
    AngleReference, CognatesRequest, CouplerPoint, CurveMode, Spacing, VerifyKind, WireSign,
};

pub use super::wire::MAX_MAGNITUDE;
use super::wire::{COORDINATE, GRASHOF_RTOL, LENGTH, NON_NEGATIVE_LENGTH, POINTS_PER_CIRCUIT};
use crate::calc::Range;
/// A ground length at or below this fraction of L is "coincident pivots" (spec §3: 1e-12).
pub const COINCIDENT_REL: f64 = 1e-12;
/// A link length below this fraction of L is numerically zero next to L (same bound as the pivots):
/// the cognate ratios |k| = d/b would exceed 1e12 and the position analysis would lose every digit.
pub const LENGTH_FLOOR_REL: f64 = 1e-12;
/// Slack of the coupler-triangle inequality, relative to max(b, d, e) (spec §3: 1e-12).
pub const TRIANGLE_SLACK_REL: f64 = 1e-12;
/// |k| or |1 − k| at or below this puts P on a coupler joint (spec §3: 1e-9).
pub const AT_JOINT_TOL: f64 = 1e-9;
/// P within this fraction of max(b, d, e) of the line DE is collinear (spec §7 warning).
pub const COLLINEAR_REL: f64 = 1e-12;
/// Smallest and largest `points_per_circuit` (spec §3; the bound is [`POINTS_PER_CIRCUIT`]).
pub const POINTS_PER_CIRCUIT_RANGE: (u64, u64) = (16, 100_000);

/// Snapshot request in the normalised frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnapshotSpec {
    /// Absolute input angle θ2 [rad], in (−π, π].
    pub theta: f64,
    /// Assembly branch t1.
    pub branch: Sign,
}

/// Validated options.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Return curves.
    pub curves: bool,
    /// Samples per circuit N.
    pub points_per_circuit: usize,
    /// Spacing.
    pub spacing: Spacing,
    /// Curve mode.
    pub curve_mode: CurveMode,
    /// Run the `sync` check.
    pub verify_sync: bool,
    /// Run the `implicit` check.
    pub verify_implicit: bool,
    /// Run the `hausdorff` check.
    pub verify_hausdorff: bool,
    /// Return geared five-bars.
    pub geared_fivebars: bool,
    /// Return metrics.
    pub metrics: bool,
    /// Grashof tolerance.
    pub grashof_rtol: f64,
}

impl Options {
    /// Whether any verification was requested.
    #[must_use]
    pub fn any_verify(&self) -> bool {
        self.verify_sync || self.verify_implicit || self.verify_hausdorff
    }
}

/// The validated request.
#[derive(Debug, Clone, PartialEq)]
pub struct CognatesInput {
    /// Origin of the normalised frame (the caller's A).
    pub origin: C64,
    /// Length scale of the normalised frame (a power of two): caller = origin + scale·internal.
    pub scale: f64,
    /// The caller's A, echoed exactly.
    pub a_raw: [f64; 2],
    /// The caller's B (or A + l·(cos γ, sin γ)), echoed.
    pub b_raw: [f64; 2],
    /// The original mechanism in the normalised frame.
    pub mech: FourBar,
    /// Coupler side t2 (as given in the `{d, e, side}` form; else sign Im k, +1 when collinear).
    pub side: Sign,
    /// P on the line DE.
    pub collinear: bool,
    /// Snapshot, if requested.
    pub snapshot: Option<SnapshotSpec>,
    /// The `joints` configuration was at a toggle (cross product zero, branch set to +1).
    pub joints_at_toggle: bool,
    /// Options.
    pub options: Options,
}

/// Collects field issues with their spec codes.
#[derive(Default)]
struct Issues {
    list: Vec<(&'static str, FieldIssue)>,
}

impl Issues {
    fn push(&mut self, code: &'static str, pointer: impl Into<String>, detail: impl Into<String>) {
        self.list.push((
            code,
            FieldIssue {
                pointer: pointer.into(),
                detail: detail.into(),
            },
        ));
    }

    fn is_clean(&self) -> bool {
        self.list.is_empty()
    }

    /// A value of `range` (a length or coordinate bound of wire.rs); out of range below or
    /// non-finite is the spec's `NON_POSITIVE_LENGTH`, above the magnitude cap `INVALID_INPUT`.
    fn bounded(&mut self, pointer: &str, name: &str, x: f64, range: Range, what: &str) -> bool {
        if range.contains(x) {
            true
        } else if x.is_finite() && (x > range.hi || (x < range.lo && range.lo < 0.0)) {
            self.push(
                "INVALID_INPUT",
                pointer,
                format!("{name} must be {range}, got {x:e}"),
            );
            false
        } else {
            self.push(
                "NON_POSITIVE_LENGTH",
                pointer,
                format!("{name} must be a finite {what}, got {x}"),
            );
            false
        }
    }

    /// A positive, finite, bounded length.
    fn length(&mut self, pointer: &str, name: &str, x: f64) -> bool {
        self.bounded(pointer, name, x, LENGTH, "length > 0")
    }

    /// A non-negative, finite, bounded length.
    fn non_negative(&mut self, pointer: &str, name: &str, x: f64) -> bool {
        self.bounded(pointer, name, x, NON_NEGATIVE_LENGTH, "length ≥ 0")
    }

    /// A finite, bounded coordinate or signed length.
    fn coord(&mut self, pointer: &str, name: &str, x: f64) -> bool {
        self.bounded(pointer, name, x, COORDINATE, "number")
    }

    fn point(&mut self, pointer: &str, name: &str, p: [f64; 2]) -> bool {
        let x = self.coord(&format!("{pointer}/0"), &format!("{name}.x"), p[0]);
        let y = self.coord(&format!("{pointer}/1"), &format!("{name}.y"), p[1]);
        x && y
    }

    fn angle(&mut self, pointer: &str, name: &str, x: f64) -> bool {
        if x.is_finite() {
            true
        } else {
            self.push(
                "NON_POSITIVE_LENGTH",
                pointer,
                format!("{name} must be a finite angle, got {x}"),
            );
            false
        }
    }

    /// `Ok` when clean; else one failure with every issue so far, coded by the first.
    fn finish(&mut self) -> Result<(), CalcFailure> {
        let list = std::mem::take(&mut self.list);
        let Some((code, first)) = list.first() else {
            return Ok(());
        };
        let code = *code;
        let n = list.len();
        let detail = if n == 1 {
            format!("{} {}", first.pointer, first.detail)
        } else {
            format!("{n} fields failed validation")
        };
        Err(CalcFailure {
            class: ProblemClass::InvalidInput,
            code,
            detail,
            errors: list.into_iter().map(|(_, i)| i).collect(),
        })
    }
}

fn c64(p: [f64; 2]) -> C64 {
    C64::new(p[0], p[1])
}

/// Degrees to radians, wrapped to (−π, π]; angles beyond ±360° are reduced modulo 360° first (exact in
/// floating point), so 1e12° + 30° still means 30°.
fn deg_to_rad(deg: f64) -> f64 {
    let d = if deg.abs() <= 360.0 { deg } else { deg % 360.0 };
    super::geometry::wrap_pi(d.to_radians())
}

fn sign_of(w: WireSign) -> Sign {
    match w {
        WireSign::Plus => Sign::Plus,
        WireSign::Minus => Sign::Minus,
    }
}

/// A power of two within a factor √2 of `x > 0`: dividing by it is exact.
fn power_of_two_near(x: f64) -> f64 {
    // x is finite, positive and ≤ ~1e101 here, so log2 is in (−1100, 340) and the cast cannot wrap.
    let e = x.log2().round() as i32;
    2f64.powi(e)
}

/// The coupler data of the dimension mode before the frame is known.
struct CouplerData {
    k: C64,
    d: f64,
    e: f64,
    side: Option<Sign>,
}

/// Options validation (shared by both modes).
fn validate_options(req: &CognatesRequest, issues: &mut Issues) -> Options {
    let o = &req.options;
    let (lo, hi) = POINTS_PER_CIRCUIT_RANGE;
    // Counts up to 2^53 convert exactly; larger ones are far outside the range either way.
    let n = o.points_per_circuit as f64;
    if !POINTS_PER_CIRCUIT.contains(n) {
        issues.push(
            "INVALID_INPUT",
            "/options/points_per_circuit",
            format!(
                "points_per_circuit must be {POINTS_PER_CIRCUIT}, got {}",
                o.points_per_circuit
            ),
        );
    }
    if !GRASHOF_RTOL.contains(o.grashof_rtol) {
        issues.push(
            "INVALID_INPUT",
            "/options/grashof_rtol",
            format!(
                "grashof_rtol must be {GRASHOF_RTOL}, got {}",
                o.grashof_rtol
            ),
        );
    }
    Options {
        curves: o.curves,
        points_per_circuit: usize::try_from(o.points_per_circuit.clamp(lo, hi)).unwrap_or(360),
        spacing: o.spacing,
        curve_mode: o.curve_mode,
        verify_sync: o.verify.contains(&VerifyKind::Sync),
        verify_implicit: o.verify.contains(&VerifyKind::Implicit),
        verify_hausdorff: o.verify.contains(&VerifyKind::Hausdorff),
        geared_fivebars: o.geared_fivebars,
        metrics: o.metrics,
        grashof_rtol: o.grashof_rtol,
    }
}

impl TryFrom<CognatesRequest> for CognatesInput {
    type Error = CalcFailure;

    fn try_from(req: CognatesRequest) -> Result<Self, Self::Error> {
        let mut issues = Issues::default();
        let options = validate_options(&req, &mut issues);
        if req.joints.is_some() {
            joints_mode(&req, options, issues)
        } else {
            dimension_mode(&req, options, issues)
        }
    }
}

fn joints_mode(
    req: &CognatesRequest,
    options: Options,
    mut issues: Issues,
) -> Result<CognatesInput, CalcFailure> {
    let Some(j) = req.joints else {
        unreachable!("joints_mode is called with joints present")
    };
    let conflicts = [
        ("/ground", req.ground.is_some()),
        ("/crank", req.crank.is_some()),
        ("/coupler", req.coupler.is_some()),
        ("/rocker", req.rocker.is_some()),
        ("/coupler_point", req.coupler_point.is_some()),
        ("/input_angle_deg", req.input_angle_deg.is_some()),
        ("/branch", req.branch.is_some()),
    ];
    for (ptr, present) in conflicts {
        if present {
            issues.push(
                "INVALID_INPUT",
                ptr,
                "must be omitted with `joints` (read from the drawn configuration)",
            );
        }
    }
    let ok = [("A", j.a), ("B", j.b), ("D", j.d), ("E", j.e), ("P", j.p)]
        .into_iter()
        .fold(true, |acc, (n, p)| {
            issues.point(&format!("/joints/{n}"), n, p) && acc
        });
    if !ok || !issues.is_clean() {
        issues.finish()?;
    }
    let (a, b, d, e, p) = (c64(j.a), c64(j.b), c64(j.d), c64(j.e), c64(j.p));
    let l = (b - a).norm();
    let crank = (d - a).norm();
    let coupler = (e - d).norm();
    let rocker = (e - b).norm();
    let big_l = l
        .max(crank)
        .max(coupler)
        .max(rocker)
        .max((p - d).norm())
        .max((p - e).norm());
    if !(big_l.is_finite() && big_l > 0.0) {
        issues.push("NON_POSITIVE_LENGTH", "/joints", "all joints coincide");
        issues.finish()?;
    }
    if l <= COINCIDENT_REL * big_l {
        issues.push(
            "COINCIDENT_PIVOTS",
            "/joints/B",
            format!("B coincides with A: |B − A| = {l:e} ≤ 1e-12·L (L = {big_l:e})"),
        );
    }
    for (ptr, name, len) in [
        ("/joints/D", "crank |D − A|", crank),
        ("/joints/E", "coupler |E − D|", coupler),
        ("/joints/E", "rocker |E − B|", rocker),
    ] {
        if len <= LENGTH_FLOOR_REL * big_l {
            issues.push(
                "NON_POSITIVE_LENGTH",
                ptr,
                format!("{name} = {len:e} is zero next to L = {big_l:e} (limit 1e-12·L)"),
            );
        }
    }
    if !issues.is_clean() {
        issues.finish()?;
    }
    let k = (p - d) / (e - d);
    let one = C64::new(1.0, 0.0);
    check_at_joint(&mut issues, "/joints/P", k, one);
    issues.finish()?;
    let scale = power_of_two_near(big_l);
    let n = |z: C64| (z - a) / scale;
    let mech = FourBar {
        input_pivot: C64::new(0.0, 0.0),
        output_pivot: n(b),
        ground: l / scale,
        crank: crank / scale,
        coupler: coupler / scale,
        rocker: rocker / scale,
        k,
    };
    let t = Sign::of(cross(b - d, e - d));
    let collinear = k.im.abs() * coupler <= COLLINEAR_REL * big_l;
    Ok(CognatesInput {
        origin: a,
        scale,
        a_raw: j.a,
        b_raw: j.b,
        mech,
        side: Sign::of(k.im).unwrap_or(Sign::Plus),
        collinear,
        snapshot: Some(SnapshotSpec {
            theta: (d - a).arg(),
            branch: t.unwrap_or(Sign::Plus),
        }),
        joints_at_toggle: t.is_none(),
        options,
    })
}

fn check_at_joint(issues: &mut Issues, ptr: &str, k: C64, one: C64) {
    if k.norm() <= AT_JOINT_TOL {
        issues.push(
            "COUPLER_POINT_AT_JOINT",
            ptr,
            format!(
                "P coincides with the crank joint D: |k| = {:e} ≤ 1e-9",
                k.norm()
            ),
        );
    } else if (one - k).norm() <= AT_JOINT_TOL {
        issues.push(
            "COUPLER_POINT_AT_JOINT",
            ptr,
            format!(
                "P coincides with the rocker joint E: |1 − k| = {:e} ≤ 1e-9",
                (one - k).norm()
            ),
        );
    }
}

fn dimension_mode(
    req: &CognatesRequest,
    options: Options,
    mut issues: Issues,
) -> Result<CognatesInput, CalcFailure> {
    // --- field checks ---
    let mut ground_ok = false;
    let mut a_raw = [0.0, 0.0];
    let mut b_raw = [0.0, 0.0];
    match &req.ground {
        None => issues.push(
            "INVALID_INPUT",
            "/ground",
            "ground is required (or give `joints`)",
        ),
        Some(g) => {
            a_raw = g.a.unwrap_or([0.0, 0.0]);
            let a_ok = issues.point("/ground/A", "A", a_raw);
            match (g.b, g.length) {
                (Some(_), Some(_)) => issues.push(
                    "INVALID_INPUT",
                    "/ground/length",
                    "give either B or length, not both",
                ),
                (None, None) => {
                    issues.push("INVALID_INPUT", "/ground/B", "B (or length) is required")
                }
                (Some(b), None) => {
                    if g.angle_deg.is_some() {
                        issues.push(
                            "INVALID_INPUT",
                            "/ground/angle_deg",
                            "angle_deg goes with length, not with B",
                        );
                    }
                    b_raw = b;
                    ground_ok = issues.point("/ground/B", "B", b) && a_ok;
                }
                (None, Some(l)) => {
                    let l_ok = issues.length("/ground/length", "ground length l", l);
                    let gamma = g.angle_deg.unwrap_or(0.0);
                    let g_ok = issues.angle("/ground/angle_deg", "ground angle", gamma);
                    if l_ok && g_ok && a_ok {
                        let b = c64(a_raw) + cis(deg_to_rad(gamma)) * l;
                        b_raw = [b.re, b.im];
                        ground_ok = true;
                    }
                }
            }
        }
    }
    let mut lens = [0.0; 3];
    let mut lens_ok = true;
    for (i, (ptr, name, v)) in [
        ("/crank", "crank a", req.crank),
        ("/coupler", "coupler b", req.coupler),
        ("/rocker", "rocker c", req.rocker),
    ]
    .into_iter()
    .enumerate()
    {
        match v {
            None => {
                issues.push(
                    "INVALID_INPUT",
                    ptr,
                    format!("{name} is required (or give `joints`)"),
                );
                lens_ok = false;
            }
            Some(x) => {
                lens_ok &= issues.length(ptr, name, x);
                lens[i] = x;
            }
        }
    }
    let cp_ok = match req.coupler_point {
        None => {
            issues.push(
                "INVALID_INPUT",
                "/coupler_point",
                "coupler_point is required (or give `joints`)",
            );
            false
        }
        Some(CouplerPoint::Triangle { d, e, .. }) => {
            let a = issues.non_negative("/coupler_point/d", "d", d);
            issues.non_negative("/coupler_point/e", "e", e) && a
        }
        Some(CouplerPoint::Frame { u, v }) => {
            let a = issues.coord("/coupler_point/u", "u", u);
            issues.coord("/coupler_point/v", "v", v) && a
        }
        Some(CouplerPoint::Polar { p, alpha_deg }) => {
            let a = issues.non_negative("/coupler_point/p", "p", p);
            issues.angle("/coupler_point/alpha_deg", "alpha_deg", alpha_deg) && a
        }
    };
    if let Some(x) = req.input_angle_deg {
        issues.angle("/input_angle_deg", "input_angle_deg", x);
    }
    if !(ground_ok && lens_ok && cp_ok && issues.is_clean()) {
        issues.finish()?;
    }
    let Some(cp) = req.coupler_point else {
        unreachable!("checked above")
    };
    let [crank, coupler, rocker] = lens;
    let a = c64(a_raw);
    let b = c64(b_raw);

    // --- coupler ratio k ---
    let one = C64::new(1.0, 0.0);
    let coupler_data = match cp {
        CouplerPoint::Triangle { d, e, side } => {
            let slack = TRIANGLE_SLACK_REL * coupler.max(d).max(e);
            let violated = [
                (d, coupler + e, "d > b + e"),
                (e, coupler + d, "e > b + d"),
                (coupler, d + e, "b > d + e"),
            ]
            .into_iter()
            .find(|(x, s, _)| *x > *s + slack);
            if let Some((_, _, what)) = violated {
                issues.push(
                    "COUPLER_TRIANGLE_INVALID",
                    "/coupler_point",
                    format!("coupler triangle (b, d, e) = ({coupler}, {d}, {e}) violates the triangle inequality: {what}"),
                );
                None
            } else {
                // Work with lengths scaled by max(b, d, e) so the squares cannot overflow.
                let m = coupler.max(d).max(e);
                let (bn, dn, en) = (coupler / m, d / m, e / m);
                let t = sign_of(side);
                let re = (dn * dn + (bn - en) * (bn + en)) / (2.0 * bn * bn);
                let heron = (dn + bn + en) * (-dn + bn + en) * (dn - bn + en) * (dn + bn - en);
                let im = t.value() * heron.max(0.0).sqrt() / (2.0 * bn * bn);
                Some(CouplerData {
                    k: C64::new(re, im),
                    d,
                    e,
                    side: Some(t),
                })
            }
        }
        CouplerPoint::Frame { u, v } => {
            let k = C64::new(u, v) / coupler;
            Some(CouplerData {
                k,
                d: u.hypot(v),
                e: (coupler - u).hypot(v),
                side: None,
            })
        }
        CouplerPoint::Polar { p, alpha_deg } => {
            let z = cis(deg_to_rad(alpha_deg)) * p;
            Some(CouplerData {
                k: z / coupler,
                d: p,
                e: (C64::new(coupler, 0.0) - z).norm(),
                side: None,
            })
        }
    };
    let l = (b - a).norm();
    let (d_len, e_len) = coupler_data.as_ref().map_or((0.0, 0.0), |c| (c.d, c.e));
    let big_l = l.max(crank).max(coupler).max(rocker).max(d_len).max(e_len);
    if l <= COINCIDENT_REL * big_l {
        issues.push(
            "COINCIDENT_PIVOTS",
            if req.ground.as_ref().is_some_and(|g| g.length.is_some()) {
                "/ground/length"
            } else {
                "/ground/B"
            },
            format!("ground pivots coincide: |B − A| = {l:e} ≤ 1e-12·L (L = {big_l:e})"),
        );
    }
    for (ptr, name, len) in [
        ("/crank", "crank a", crank),
        ("/coupler", "coupler b", coupler),
        ("/rocker", "rocker c", rocker),
    ] {
        if len < LENGTH_FLOOR_REL * big_l {
            issues.push(
                "NON_POSITIVE_LENGTH",
                ptr,
                format!("{name} = {len:e} is zero next to L = {big_l:e} (limit 1e-12·L)"),
            );
        }
    }
    if let Some(cd) = &coupler_data {
        check_at_joint(&mut issues, "/coupler_point", cd.k, one);
    }
    issues.finish()?;
    let Some(cd) = coupler_data else {
        unreachable!("issues would have been reported")
    };

    // --- normalised frame ---
    let scale = power_of_two_near(big_l);
    let ground = l / scale;
    let mech = FourBar {
        input_pivot: C64::new(0.0, 0.0),
        output_pivot: (b - a) / scale,
        ground,
        crank: crank / scale,
        coupler: coupler / scale,
        rocker: rocker / scale,
        k: cd.k,
    };
    let collinear = cd.k.im.abs() * coupler <= COLLINEAR_REL * coupler.max(cd.d).max(cd.e);
    let side = cd
        .side
        .unwrap_or_else(|| Sign::of(cd.k.im).unwrap_or(Sign::Plus));
    let snapshot = req.input_angle_deg.map(|deg| {
        let rel = deg_to_rad(deg);
        let theta = match req.angle_reference {
            AngleReference::Global => rel,
            AngleReference::Ground => rel + mech.ground_angle(),
        };
        SnapshotSpec {
            theta: super::geometry::wrap_pi(theta),
            branch: req.branch.map_or(Sign::Plus, sign_of),
        }
    });
    Ok(CognatesInput {
        origin: a,
        scale,
        a_raw,
        b_raw,
        mech,
        side,
        collinear,
        snapshot,
        joints_at_toggle: false,
        options,
    })
}
