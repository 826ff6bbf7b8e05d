//! The rules between fields of a [`CognatesRequest`] (spec §3, §4.1), turning it into the domain
//! input. Every per-field rule (lengths > 0 with the spec's `NON_POSITIVE_LENGTH`, coordinate
//! caps, option ranges, exactly one of `B`/`length`) is declared on the wire types and checked at
//! the door; what is left here is what JSON Schema cannot state, each rule with its own code
//! ([`CROSS_FIELD_RULES`]; the spec's `NON_POSITIVE_LENGTH`, `COINCIDENT_PIVOTS`,
//! `COUPLER_TRIANGLE_INVALID`, `COUPLER_POINT_AT_JOINT`).
//!
//! Internally the linkage is expressed in a normalised frame: origin at A and lengths divided by a
//! power of two close to the largest length L (an exact scaling), so every tolerance is absolute and
//! no square can overflow or underflow whatever the caller's unit.

use crate::calc::common;
use crate::calc::rules::rule;
use crate::calc::{CalcFailure, Validator};

use super::geometry::{C64, FourBar, Sign, cis, cross};
use super::wire::{AngleReference, CognatesRequest, CouplerPoint, GroundSpec, JointsSpec};

pub use super::wire::{MAX_MAGNITUDE, VerifyKind};

crate::calc::rules::cross_rules! {
    /// The rules between fields of `POST /v1/cognates`, as the document lists them.
    pub const CROSS_FIELD_RULES: &[CrossRule];
    invalid JOINTS_EXCLUSIVE ["/joints", "/ground", "/crank", "/coupler", "/rocker",
        "/coupler_point", "/input_angle_deg", "/branch"]
        "With `joints`, `ground`, `crank`, `coupler`, `rocker`, `coupler_point`, `input_angle_deg` \
         and `branch` are omitted (they are read from the drawn configuration).";
    invalid DIMENSIONS_REQUIRED ["/ground", "/crank", "/coupler", "/rocker", "/coupler_point",
        "/joints"]
        "Without `joints`, `ground`, `crank`, `coupler`, `rocker` and `coupler_point` are all given.";
    invalid GROUND_B_OR_LENGTH ["/ground/B", "/ground/length"]
        "Exactly one of `ground.B` and `ground.length` is given.";
    invalid GROUND_ANGLE_WITH_LENGTH ["/ground/angle_deg", "/ground/B"]
        "`ground.angle_deg` is given only with `ground.length` (not with `ground.B`).";
    invalid COINCIDENT_PIVOTS(super::error::COINCIDENT_PIVOTS) ["/ground/B", "/ground/length",
        "/joints/B"] "|B − A| > 1e-12·L, L the largest length of the linkage.";
    invalid LENGTH_FLOOR(super::error::NON_POSITIVE_LENGTH) ["/crank", "/coupler", "/rocker",
        "/joints/D", "/joints/E", "/joints"]
        "Crank, coupler and rocker are each ≥ 1e-12·L, L the largest length of the linkage (in \
         `joints` mode: the joints do not all coincide).";
    invalid COUPLER_TRIANGLE_INVALID(super::error::COUPLER_TRIANGLE_INVALID) ["/coupler_point",
        "/coupler"] "(b, d, e) satisfy the triangle inequality within 1e-12·max(b, d, e).";
    invalid COUPLER_POINT_AT_JOINT(super::error::COUPLER_POINT_AT_JOINT) ["/coupler_point",
        "/joints/P"]
        "P is off the coupler joints: |k| > 1e-9 and |1 − k| > 1e-9, k = (P − D)/(E − D).";
    /// The linkage assembles somewhere (found while computing).
    infeasible NOT_ASSEMBLABLE ["/ground", "/crank", "/coupler", "/rocker"]
        "The four-bar assembles for some input angle.";
    /// The curves fit the point limit (found while computing).
    too_large TOO_MANY_POINTS ["/options/points_per_circuit", "/options/curves", "/options/verify"]
        "The sampled points of every requested output stay within the service's point limit.";
    /// The work fits the time budget (found while computing).
    too_large DEADLINE_EXCEEDED ["/time_limit_ms", "/options"]
        "The requested outputs are computed within the request's time limit.";
    listed crate::calc::common::RESPONSE_TOO_LARGE_RULE;
}

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

/// How curves are traced: the request's curve mode.
pub use super::wire::CurveMode;

/// The request's options (their ranges are checked at the door).
pub use super::wire::CognatesOptions as Options;

impl Options {
    /// Whether the verification `kind` was requested.
    #[must_use]
    pub fn verifies(&self, kind: VerifyKind) -> bool {
        self.verify.contains(&kind)
    }

    /// Whether any verification was requested.
    #[must_use]
    pub fn any_verify(&self) -> bool {
        !self.verify.is_empty()
    }

    /// Samples per circuit N (in `POINTS_PER_CIRCUIT` at the door: the conversion is exact).
    #[must_use]
    pub fn points(&self) -> usize {
        usize::try_from(self.points_per_circuit).unwrap_or(usize::MAX)
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

impl TryFrom<CognatesRequest> for CognatesInput {
    type Error = CalcFailure;

    fn try_from(req: CognatesRequest) -> Result<Self, Self::Error> {
        let v = Validator::new();
        let options = req.options.clone();
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
            rule!(v, JOINTS_EXCLUSIVE, ptr;
                "must be omitted with `joints` (read from the drawn configuration)");
        }
    }
    // Every coordinate is within ±1e100 (the door).
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
        rule!(v, LENGTH_FLOOR, "/joints"; "all joints coincide");
        v.checkpoint()?;
    }
    if l <= COINCIDENT_REL * big_l {
        rule!(v, COINCIDENT_PIVOTS, "/joints/B";
            "B coincides with A: |B − A| = {l:e} ≤ 1e-12·L (L = {big_l:e})");
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
            rule!(v, LENGTH_FLOOR, ptr;
                "{name} = {len:e} is zero next to L = {big_l:e} (limit 1e-12·L)");
        }
    }
}

/// `COUPLER_POINT_AT_JOINT` when P (coupler ratio `k`) sits on the crank joint D or the rocker
/// joint E.
fn check_at_joint(v: &mut Validator, ptr: &str, k: C64) {
    let one = C64::new(1.0, 0.0);
    if k.norm() <= AT_JOINT_TOL {
        rule!(v, COUPLER_POINT_AT_JOINT, ptr;
            "P coincides with the crank joint D: |k| = {:e} ≤ 1e-9", k.norm());
    } else if (one - k).norm() <= AT_JOINT_TOL {
        rule!(v, COUPLER_POINT_AT_JOINT, ptr;
            "P coincides with the rocker joint E: |1 − k| = {:e} ≤ 1e-9", (one - k).norm());
    }
}

/// The ground pivots (A, B) of the dimension mode: B given, or A + l·(cos γ, sin γ) (the
/// coordinate caps and l > 0 are checked at the door).
fn check_ground(v: &mut Validator, ground: Option<&GroundSpec>) -> Option<([f64; 2], [f64; 2])> {
    let Some(g) = ground else {
        rule!(v, DIMENSIONS_REQUIRED, "/ground"; "ground is required (or give `joints`)");
        return None;
    };
    let a_raw = g.a.unwrap_or([0.0, 0.0]);
    match (g.b, g.length) {
        (Some(_), Some(_)) => {
            rule!(v, GROUND_B_OR_LENGTH, "/ground/length"; "give either B or length, not both");
            None
        }
        (None, None) => {
            rule!(v, GROUND_B_OR_LENGTH, "/ground/B"; "B (or length) is required");
            None
        }
        (Some(b), None) => {
            if g.angle_deg.is_some() {
                rule!(v, GROUND_ANGLE_WITH_LENGTH, "/ground/angle_deg";
                    "angle_deg goes with length, not with B");
            }
            Some((a_raw, b))
        }
        (None, Some(l)) => {
            let gamma = g.angle_deg.unwrap_or(0.0);
            let b = c64(a_raw) + cis(deg_to_rad(gamma)) * l;
            Some((a_raw, [b.re, b.im]))
        }
    }
}

/// The link lengths (a, b, c), each required (their ranges are checked at the door).
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
                rule!(v, DIMENSIONS_REQUIRED, ptr; "{name} is required (or give `joints`)");
                ok = false;
            }
            Some(x) => *slot = x,
        }
    }
    ok.then_some(lens)
}

/// The coupler point in any of its three forms (its ranges are checked at the door).
fn check_coupler_point(v: &mut Validator, cp: Option<CouplerPoint>) -> Option<CouplerPoint> {
    if cp.is_none() {
        rule!(v, DIMENSIONS_REQUIRED, "/coupler_point";
            "coupler_point is required (or give `joints`)");
    }
    cp
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
                rule!(v, COUPLER_TRIANGLE_INVALID, "/coupler_point";
                    "coupler triangle (b, d, e) = ({coupler}, {d}, {e}) violates the triangle inequality: {what}");
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
    v.checkpoint()?;
    let (Some((a_raw, b_raw)), Some([crank, coupler, rocker]), Some(cp)) = (pivots, lens, cp)
    else {
        return Err(crate::calc::rules::door_skipped("/ground"));
    };
    let a = c64(a_raw);
    let b = c64(b_raw);
    let ratio = coupler_data(&mut v, cp, coupler);
    let l = (b - a).norm();
    let (d_len, e_len) = ratio.as_ref().map_or((0.0, 0.0), |c| (c.d, c.e));
    let big_l = l.max(crank).max(coupler).max(rocker).max(d_len).max(e_len);
    if l <= COINCIDENT_REL * big_l {
        let by_length = req.ground.as_ref().is_some_and(|g| g.length.is_some());
        let at = if by_length {
            "/ground/length"
        } else {
            "/ground/B"
        };
        rule!(v, COINCIDENT_PIVOTS, at;
            "ground pivots coincide: |B − A| = {l:e} ≤ 1e-12·L (L = {big_l:e})");
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
        return Err(crate::calc::rules::door_skipped("/coupler_point"));
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
