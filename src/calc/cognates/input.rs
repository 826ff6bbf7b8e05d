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

use crate::calc::common;
use crate::calc::{CalcFailure, INVALID_INPUT, Range, Validator};

use super::error::{
    COINCIDENT_PIVOTS, COUPLER_POINT_AT_JOINT, COUPLER_TRIANGLE_INVALID, NON_POSITIVE_LENGTH,
};
use super::geometry::{C64, FourBar, Sign, cis, cross};
use super::sampling::Spacing;
use super::wire::{
    self, AngleReference, CognatesRequest, CouplerPoint, GroundSpec, JointsSpec, VerifyKind,
};

pub use super::wire::MAX_MAGNITUDE;
use super::wire::{COORDINATE, GRASHOF_RTOL, LENGTH, NON_NEGATIVE_LENGTH, POINTS_PER_CIRCUIT};
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

/// Snapshot request in the normalised frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnapshotSpec {
    /// Absolute input angle θ2 \[rad\], in (−π, π].
    pub theta: f64,
    /// Assembly branch t1.
    pub branch: Sign,
}

/// How coupler curves are traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurveMode {
    /// Closed circuits, switching branch at toggles (the whole curve).
    Circuits,
    /// Paper style: each mechanism's own input over its range on the branch of the snapshot.
    FixedBranch,
}

impl From<wire::CurveMode> for CurveMode {
    fn from(m: wire::CurveMode) -> Self {
        match m {
            wire::CurveMode::Circuits => Self::Circuits,
            wire::CurveMode::FixedBranch => Self::FixedBranch,
        }
    }
}

impl From<wire::Spacing> for Spacing {
    fn from(s: wire::Spacing) -> Self {
        match s {
            wire::Spacing::Auto => Self::Auto,
            wire::Spacing::Uniform => Self::Uniform,
        }
    }
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

/// Check `x` against `range` (a length or coordinate bound of wire.rs): below the range, or not
/// finite, is the spec's `NON_POSITIVE_LENGTH`; above the magnitude cap (or below a negative lower
/// end) `INVALID_INPUT`.
fn bounded(v: &mut Validator, pointer: &str, name: &str, x: f64, range: Range) -> bool {
    let beyond_cap = x.is_finite() && (x > range.hi || (x < range.lo && range.lo < 0.0));
    let code = if beyond_cap {
        INVALID_INPUT
    } else {
        NON_POSITIVE_LENGTH
    };
    v.range_code(code, pointer, name, x, range)
}

/// A check of one named value at a pointer (`v, pointer, name, value`); true when it passes.
type Check = fn(&mut Validator, &str, &str, f64) -> bool;

/// A distance that may be zero ([`NON_NEGATIVE_LENGTH`]).
fn non_negative(v: &mut Validator, pointer: &str, name: &str, x: f64) -> bool {
    bounded(v, pointer, name, x, NON_NEGATIVE_LENGTH)
}

/// A coordinate or signed length ([`COORDINATE`]).
fn coordinate(v: &mut Validator, pointer: &str, name: &str, x: f64) -> bool {
    bounded(v, pointer, name, x, COORDINATE)
}

/// A point `[x, y]` of coordinates at `pointer` (`/0`, `/1`).
fn point(v: &mut Validator, pointer: &str, name: &str, p: [f64; 2]) -> bool {
    let x = coordinate(v, &format!("{pointer}/0"), &format!("{name}.x"), p[0]);
    let y = coordinate(v, &format!("{pointer}/1"), &format!("{name}.y"), p[1]);
    x && y
}

/// A finite angle in degrees (any value: it is reduced modulo 360°).
fn angle(v: &mut Validator, pointer: &str, name: &str, x: f64) -> bool {
    v.range_code(NON_POSITIVE_LENGTH, pointer, name, x, Range::FINITE)
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

fn sign_of(w: common::Sign) -> Sign {
    match w {
        common::Sign::Plus => Sign::Plus,
        common::Sign::Minus => Sign::Minus,
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
fn validate_options(req: &CognatesRequest, v: &mut Validator) -> Options {
    let o = &req.options;
    // The ends of POINTS_PER_CIRCUIT are whole numbers far below 2^53: the conversions are exact.
    let (lo, hi) = (POINTS_PER_CIRCUIT.lo as u64, POINTS_PER_CIRCUIT.hi as u64);
    v.uint(
        "/options/points_per_circuit",
        "points_per_circuit",
        o.points_per_circuit,
        POINTS_PER_CIRCUIT,
    );
    v.range(
        "/options/grashof_rtol",
        "grashof_rtol",
        o.grashof_rtol,
        GRASHOF_RTOL,
    );
    Options {
        curves: o.curves,
        points_per_circuit: usize::try_from(o.points_per_circuit.clamp(lo, hi)).unwrap_or(360),
        spacing: o.spacing.into(),
        curve_mode: o.curve_mode.into(),
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
        let mut v = Validator::new();
        let _ = crate::calc::common::time_limit(&mut v, req.time_limit_ms);
        let options = validate_options(&req, &mut v);
        if let Some(j) = req.joints {
            joints_mode(&req, &j, options, v)
        } else {
            dimension_mode(&req, options, v)
        }
    }
}

/// The fields that must be absent with `joints` (read from the drawn configuration).
fn conflicts_with_joints(req: &CognatesRequest) -> [(&'static str, bool); 7] {
    [
        ("/ground", req.ground.is_some()),
        ("/crank", req.crank.is_some()),
        ("/coupler", req.coupler.is_some()),
        ("/rocker", req.rocker.is_some()),
        ("/coupler_point", req.coupler_point.is_some()),
        ("/input_angle_deg", req.input_angle_deg.is_some()),
        ("/branch", req.branch.is_some()),
    ]
}

fn joints_mode(
    req: &CognatesRequest,
    j: &JointsSpec,
    options: Options,
    mut v: Validator,
) -> Result<CognatesInput, CalcFailure> {
    for (ptr, present) in conflicts_with_joints(req) {
        if present {
            v.push(
                ptr,
                "must be omitted with `joints` (read from the drawn configuration)",
            );
        }
    }
    for (n, p) in [("A", j.a), ("B", j.b), ("D", j.d), ("E", j.e), ("P", j.p)] {
        point(&mut v, &format!("/joints/{n}"), n, p);
    }
    v.checkpoint()?;
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
        v.push_code(NON_POSITIVE_LENGTH, "/joints", "all joints coincide");
        v.checkpoint()?;
    }
    if l <= COINCIDENT_REL * big_l {
        v.push_code(
            COINCIDENT_PIVOTS,
            "/joints/B",
            format!("B coincides with A: |B − A| = {l:e} ≤ 1e-12·L (L = {big_l:e})"),
        );
    }
    length_floor(
        &mut v,
        big_l,
        [
            ("/joints/D", "crank |D − A|", crank),
            ("/joints/E", "coupler |E − D|", coupler),
            ("/joints/E", "rocker |E − B|", rocker),
        ],
        |len, floor| len <= floor,
    );
    v.checkpoint()?;
    let k = (p - d) / (e - d);
    check_at_joint(&mut v, "/joints/P", k);
    v.finish()?;
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

/// `NON_POSITIVE_LENGTH` for each link `(pointer, name, length)` that is zero next to the largest
/// length L (`too_short(length, 1e-12·L)`).
fn length_floor(
    v: &mut Validator,
    big_l: f64,
    links: [(&str, &str, f64); 3],
    too_short: fn(f64, f64) -> bool,
) {
    let floor = LENGTH_FLOOR_REL * big_l;
    for (ptr, name, len) in links {
        if too_short(len, floor) {
            v.push_code(
                NON_POSITIVE_LENGTH,
                ptr,
                format!("{name} = {len:e} is zero next to L = {big_l:e} (limit 1e-12·L)"),
            );
        }
    }
}

/// `COUPLER_POINT_AT_JOINT` when P (coupler ratio `k`) sits on the crank joint D or the rocker
/// joint E.
fn check_at_joint(v: &mut Validator, ptr: &str, k: C64) {
    let one = C64::new(1.0, 0.0);
    if k.norm() <= AT_JOINT_TOL {
        v.push_code(
            COUPLER_POINT_AT_JOINT,
            ptr,
            format!(
                "P coincides with the crank joint D: |k| = {:e} ≤ 1e-9",
                k.norm()
            ),
        );
    } else if (one - k).norm() <= AT_JOINT_TOL {
        v.push_code(
            COUPLER_POINT_AT_JOINT,
            ptr,
            format!(
                "P coincides with the rocker joint E: |1 − k| = {:e} ≤ 1e-9",
                (one - k).norm()
            ),
        );
    }
}

/// The ground pivots (A, B) of the dimension mode: B given, or A + l·(cos γ, sin γ).
fn check_ground(v: &mut Validator, ground: Option<&GroundSpec>) -> Option<([f64; 2], [f64; 2])> {
    let Some(g) = ground else {
        v.push("/ground", "ground is required (or give `joints`)");
        return None;
    };
    let a_raw = g.a.unwrap_or([0.0, 0.0]);
    let a_ok = point(v, "/ground/A", "A", a_raw);
    match (g.b, g.length) {
        (Some(_), Some(_)) => {
            v.push("/ground/length", "give either B or length, not both");
            None
        }
        (None, None) => {
            v.push("/ground/B", "B (or length) is required");
            None
        }
        (Some(b), None) => {
            if g.angle_deg.is_some() {
                v.push(
                    "/ground/angle_deg",
                    "angle_deg goes with length, not with B",
                );
            }
            (point(v, "/ground/B", "B", b) && a_ok).then_some((a_raw, b))
        }
        (None, Some(l)) => {
            let l_ok = bounded(v, "/ground/length", "ground length l", l, LENGTH);
            let gamma = g.angle_deg.unwrap_or(0.0);
            let g_ok = angle(v, "/ground/angle_deg", "ground angle", gamma);
            (l_ok && g_ok && a_ok).then(|| {
                let b = c64(a_raw) + cis(deg_to_rad(gamma)) * l;
                (a_raw, [b.re, b.im])
            })
        }
    }
}

/// The link lengths (a, b, c), each required and a [`LENGTH`].
fn check_links(v: &mut Validator, req: &CognatesRequest) -> Option<[f64; 3]> {
    let mut lens = [0.0; 3];
    let mut ok = true;
    for (slot, (ptr, name, given)) in lens.iter_mut().zip([
        ("/crank", "crank a", req.crank),
        ("/coupler", "coupler b", req.coupler),
        ("/rocker", "rocker c", req.rocker),
    ]) {
        match given {
            None => {
                v.push(ptr, format!("{name} is required (or give `joints`)"));
                ok = false;
            }
            Some(x) => {
                ok &= bounded(v, ptr, name, x, LENGTH);
                *slot = x;
            }
        }
    }
    ok.then_some(lens)
}

/// The coupler point in any of its three forms.
fn check_coupler_point(v: &mut Validator, cp: Option<CouplerPoint>) -> Option<CouplerPoint> {
    let Some(cp) = cp else {
        v.push(
            "/coupler_point",
            "coupler_point is required (or give `joints`)",
        );
        return None;
    };
    let fields: [(&str, f64, Check); 2] = match cp {
        CouplerPoint::Triangle { d, e, .. } => [("d", d, non_negative), ("e", e, non_negative)],
        CouplerPoint::Frame { u, v: w } => [("u", u, coordinate), ("v", w, coordinate)],
        CouplerPoint::Polar { p, alpha_deg } => {
            [("p", p, non_negative), ("alpha_deg", alpha_deg, angle)]
        }
    };
    let mut ok = true;
    for (name, x, check) in fields {
        ok &= check(v, &format!("/coupler_point/{name}"), name, x);
    }
    ok.then_some(cp)
}

/// The coupler ratio k = (P − D)/(E − D) and the distances d = |P − D|, e = |P − E| of a valid
/// coupler point (`COUPLER_TRIANGLE_INVALID` when the triangle (b, d, e) cannot close).
fn coupler_data(v: &mut Validator, cp: CouplerPoint, coupler: f64) -> Option<CouplerData> {
    match cp {
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
                v.push_code(
                    COUPLER_TRIANGLE_INVALID,
                    "/coupler_point",
                    format!("coupler triangle (b, d, e) = ({coupler}, {d}, {e}) violates the triangle inequality: {what}"),
                );
                return None;
            }
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
        CouplerPoint::Frame { u, v: w } => Some(CouplerData {
            k: C64::new(u, w) / coupler,
            d: u.hypot(w),
            e: (coupler - u).hypot(w),
            side: None,
        }),
        CouplerPoint::Polar { p, alpha_deg } => {
            let z = cis(deg_to_rad(alpha_deg)) * p;
            Some(CouplerData {
                k: z / coupler,
                d: p,
                e: (C64::new(coupler, 0.0) - z).norm(),
                side: None,
            })
        }
    }
}

fn dimension_mode(
    req: &CognatesRequest,
    options: Options,
    mut v: Validator,
) -> Result<CognatesInput, CalcFailure> {
    let pivots = check_ground(&mut v, req.ground.as_ref());
    let lens = check_links(&mut v, req);
    let cp = check_coupler_point(&mut v, req.coupler_point);
    if let Some(x) = req.input_angle_deg {
        angle(&mut v, "/input_angle_deg", "input_angle_deg", x);
    }
    v.checkpoint()?;
    let (Some((a_raw, b_raw)), Some([crank, coupler, rocker]), Some(cp)) = (pivots, lens, cp)
    else {
        unreachable!("every missing part recorded a problem and `checkpoint` returned it")
    };
    let a = c64(a_raw);
    let b = c64(b_raw);
    let ratio = coupler_data(&mut v, cp, coupler);
    let l = (b - a).norm();
    let (d_len, e_len) = ratio.as_ref().map_or((0.0, 0.0), |c| (c.d, c.e));
    let big_l = l.max(crank).max(coupler).max(rocker).max(d_len).max(e_len);
    if l <= COINCIDENT_REL * big_l {
        v.push_code(
            COINCIDENT_PIVOTS,
            if req.ground.as_ref().is_some_and(|g| g.length.is_some()) {
                "/ground/length"
            } else {
                "/ground/B"
            },
            format!("ground pivots coincide: |B − A| = {l:e} ≤ 1e-12·L (L = {big_l:e})"),
        );
    }
    length_floor(
        &mut v,
        big_l,
        [
            ("/crank", "crank a", crank),
            ("/coupler", "coupler b", coupler),
            ("/rocker", "rocker c", rocker),
        ],
        |len, floor| len < floor,
    );
    if let Some(cd) = &ratio {
        check_at_joint(&mut v, "/coupler_point", cd.k);
    }
    v.finish()?;
    let Some(cd) = ratio else {
        unreachable!("a missing coupler ratio recorded a problem and `finish` returned it")
    };
    Ok(normalised(
        req,
        options,
        a_raw,
        b_raw,
        [crank, coupler, rocker],
        &cd,
    ))
}

/// The validated dimension-mode linkage in its normalised frame (origin A, lengths divided by a
/// power of two near L).
fn normalised(
    req: &CognatesRequest,
    options: Options,
    a_raw: [f64; 2],
    b_raw: [f64; 2],
    [crank, coupler, rocker]: [f64; 3],
    cd: &CouplerData,
) -> CognatesInput {
    let (a, b) = (c64(a_raw), c64(b_raw));
    let l = (b - a).norm();
    let big_l = l.max(crank).max(coupler).max(rocker).max(cd.d).max(cd.e);
    let scale = power_of_two_near(big_l);
    let mech = FourBar {
        input_pivot: C64::new(0.0, 0.0),
        output_pivot: (b - a) / scale,
        ground: l / scale,
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
    CognatesInput {
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
    }
}
