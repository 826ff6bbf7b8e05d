//! The evaluation of single points and sweeps (spec §3.2–3.5); no wire types.

use crate::numerics::{Budget, par_map_while};

use super::error::SpatialCouplingError;
use super::input::{Groups, SpatialCouplingInput, Sweep};
use super::kinematics::{
    ContactKin, Coupling, D_ZERO_ULPS, FrameKin, RelKin, V3, about_centre, cross, dot, norm,
};

/// Points per unit of work between two budget checks.
pub const CHUNK: usize = 4096;

/// Contact point in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactOut {
    /// r_B \[m\].
    pub r: V3,
    /// v_B [m/s].
    pub v: V3,
    /// |v_B| [m/s].
    pub speed: f64,
    /// D(θ1).
    pub d: f64,
}

/// Motion relative to one shaft in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelOut {
    /// x \[m\].
    pub x: f64,
    /// z \[m\].
    pub z: f64,
    /// dx/dt [m/s].
    pub vx: f64,
    /// dz/dt [m/s].
    pub vz: f64,
    /// Relative rotation of body 3 \[deg\] (wrapped to [0°, 360°) for points, continuous for
    /// sweeps).
    pub theta_deg: f64,
    /// Its rate [rad/s].
    pub omega: f64,
}

/// Frames and the body-3 transforms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FramesOut {
    /// Unit vectors.
    pub frames: FrameKin,
    /// T13 (translation in m).
    pub t13: [[f64; 4]; 4],
    /// T23 (translation in m).
    pub t23: [[f64; 4]; 4],
}

/// A body-3 point in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body3Out {
    /// Ground frame position \[m\].
    pub r0: V3,
    /// Frame-1 position \[m\].
    pub r1: V3,
    /// Frame-2 position \[m\].
    pub r2: V3,
    /// Absolute velocity [m/s].
    pub v0: V3,
    /// Velocity relative to shaft 1, frame 1 [m/s].
    pub v1: V3,
    /// Velocity relative to shaft 2, frame 2 [m/s].
    pub v2: V3,
}

/// Closure residuals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckOut {
    /// (rB − A1)·j1, (rB − A2)·j2, n0·rB over max(a, |rB|), and j1·j2 (absolute values).
    pub closure: [f64; 4],
    /// Largest entry of |F3ᵀF3 − I|.
    pub orthonormality: f64,
}

/// The kinematics at one input angle, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct PointKin {
    /// θ1 \[deg\].
    pub theta1_deg: f64,
    /// θ2 \[deg\] (wrapped to [0°, 360°) for points, continuous for sweeps).
    pub theta2_deg: f64,
    /// i12.
    pub i12: f64,
    /// di12/dθ1 [1/rad].
    pub di12: f64,
    /// ω2 [rad/s].
    pub omega2: f64,
    /// ε2 [rad/s²].
    pub epsilon2: f64,
    /// Contact point (when asked).
    pub contact: Option<ContactOut>,
    /// Relative to shaft 1 (when asked).
    pub rel1: Option<RelOut>,
    /// Relative to shaft 2 (when asked).
    pub rel2: Option<RelOut>,
    /// Frames (when asked).
    pub frames: Option<FramesOut>,
    /// Body-3 points (when given).
    pub body3: Option<Vec<Body3Out>>,
    /// Closure check (when asked).
    pub check: Option<CheckOut>,
    /// |rB|/a (0 when B was not evaluated).
    pub radius_over_a: f64,
}

/// One requested input angle: its kinematics, or B at infinity there.
#[derive(Debug, Clone, PartialEq)]
pub enum PointResult {
    /// The kinematics.
    Ok(Box<PointKin>),
    /// D is zero to round-off: no finite contact point.
    AtInfinity {
        /// θ1 \[deg\].
        theta1_deg: f64,
        /// D(θ1).
        d: f64,
    },
}

/// Extremes over a sweep (spec §3.5), SI units and radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepSummary {
    /// Points.
    pub n: u64,
    /// [min, max] i12.
    pub i12: [f64; 2],
    /// [min, max] |i12|.
    pub i12_abs: [f64; 2],
    /// [min, max] continuous θ31 \[deg\].
    pub theta31: [f64; 2],
    /// [min, max] continuous θ32 \[deg\].
    pub theta32: [f64; 2],
    /// [min, max] |rB| \[m\].
    pub r_b: [f64; 2],
    /// [min, max] |vB| [m/s].
    pub v_b: [f64; 2],
    /// [min, max] x2B \[m\].
    pub x2: [f64; 2],
    /// [min, max] z2B \[m\].
    pub z2: [f64; 2],
    /// max |ω31| [rad/s].
    pub omega31: f64,
    /// max |ω32| [rad/s].
    pub omega32: f64,
    /// [min, max] |D|.
    pub d_abs: [f64; 2],
}

const EMPTY: [f64; 2] = [f64::INFINITY, f64::NEG_INFINITY];

impl Default for SweepSummary {
    fn default() -> Self {
        Self {
            n: 0,
            i12: EMPTY,
            i12_abs: EMPTY,
            theta31: EMPTY,
            theta32: EMPTY,
            r_b: EMPTY,
            v_b: EMPTY,
            x2: EMPTY,
            z2: EMPTY,
            omega31: 0.0,
            omega32: 0.0,
            d_abs: EMPTY,
        }
    }
}

fn widen(r: &mut [f64; 2], x: f64) {
    r[0] = r[0].min(x);
    r[1] = r[1].max(x);
}

fn join(r: &mut [f64; 2], o: [f64; 2]) {
    r[0] = r[0].min(o[0]);
    r[1] = r[1].max(o[1]);
}

impl SweepSummary {
    fn add(&mut self, p: &PointKin) {
        self.n += 1;
        widen(&mut self.i12, p.i12);
        widen(&mut self.i12_abs, p.i12.abs());
        if let Some(c) = &p.contact {
            widen(&mut self.r_b, norm(c.r));
            widen(&mut self.v_b, c.speed);
            widen(&mut self.d_abs, c.d.abs());
        }
        if let Some(r) = &p.rel1 {
            widen(&mut self.theta31, r.theta_deg);
            self.omega31 = self.omega31.max(r.omega.abs());
        }
        if let Some(r) = &p.rel2 {
            widen(&mut self.theta32, r.theta_deg);
            widen(&mut self.x2, r.x);
            widen(&mut self.z2, r.z);
            self.omega32 = self.omega32.max(r.omega.abs());
        }
    }

    fn merge(&mut self, o: &Self) {
        self.n += o.n;
        join(&mut self.i12, o.i12);
        join(&mut self.i12_abs, o.i12_abs);
        join(&mut self.theta31, o.theta31);
        join(&mut self.theta32, o.theta32);
        join(&mut self.r_b, o.r_b);
        join(&mut self.v_b, o.v_b);
        join(&mut self.x2, o.x2);
        join(&mut self.z2, o.z2);
        self.omega31 = self.omega31.max(o.omega31);
        self.omega32 = self.omega32.max(o.omega32);
        join(&mut self.d_abs, o.d_abs);
    }
}

/// Relative margin of the squared-norm pre-test of [`NormRange`]: far above the rounding of a
/// squared norm (3 ε) and of [`norm`] (two `hypot`s, under 2 ε), far below the change of |rB| or
/// |vB| between two sweep points.
const NORM_MARGIN: f64 = 1e-12;
/// Squared norms in this range carry no underflow or overflow: the pre-test's error bound holds.
const SAFE_SQUARE: std::ops::RangeInclusive<f64> = 1e-280..=1e280;
/// Candidates held per end of a [`NormRange`] before their norms are taken.
const CANDIDATES: usize = 16;

/// Vectors whose squared norm is within [`NORM_MARGIN`] of the smallest (or largest) so far.
#[derive(Clone, Copy)]
struct Candidates {
    len: usize,
    v: [(f64, V3); CANDIDATES],
}

impl Candidates {
    const EMPTY: Self = Self {
        len: 0,
        v: [(0.0, [0.0; 3]); CANDIDATES],
    };

    /// Keep only the candidates whose squared norm passes `keep`.
    #[inline]
    fn retain(&mut self, keep: impl Fn(f64) -> bool) {
        let mut n = 0;
        for i in 0..self.len {
            if keep(self.v[i].0) {
                self.v[n] = self.v[i];
                n += 1;
            }
        }
        self.len = n;
    }

    /// Take the norms of the candidates into `range` and forget them.
    fn flush(&mut self, range: &mut [f64; 2]) {
        for &(_, x) in &self.v[..self.len] {
            widen(range, norm(x));
        }
        self.len = 0;
    }

    #[inline]
    fn push(&mut self, s: f64, x: V3, range: &mut [f64; 2]) {
        if self.len == CANDIDATES {
            self.flush(range);
        }
        self.v[self.len] = (s, x);
        self.len += 1;
    }
}

/// [min, max] of [`norm`] over a run of vectors, with `norm` (two `hypot` calls) taken only where
/// the squared norm comes within [`NORM_MARGIN`] of the extremes so far. The result is exactly
/// the extremes of `norm` over every vector: a vector whose squared norm exceeds the smallest
/// by more than the margin has a larger `norm` than that vector, whatever the rounding (and
/// likewise at the top); vectors outside [`SAFE_SQUARE`] (or not finite) have their norm taken.
struct NormRange {
    /// Extremes of the norms taken.
    range: [f64; 2],
    /// Smallest and largest squared norm seen (in [`SAFE_SQUARE`]).
    square: [f64; 2],
    lo: Candidates,
    hi: Candidates,
}

impl NormRange {
    const EMPTY: Self = Self {
        range: EMPTY,
        square: EMPTY,
        lo: Candidates::EMPTY,
        hi: Candidates::EMPTY,
    };

    #[inline]
    fn add(&mut self, x: V3) {
        let s = dot(x, x);
        if !SAFE_SQUARE.contains(&s) {
            widen(&mut self.range, norm(x));
            return;
        }
        if s <= self.square[0] * (1.0 + NORM_MARGIN) {
            if s < self.square[0] {
                self.square[0] = s;
                let cut = s * (1.0 + NORM_MARGIN);
                self.lo.retain(|c| c <= cut);
            }
            self.lo.push(s, x, &mut self.range);
        }
        if s >= self.square[1] * (1.0 - NORM_MARGIN) {
            if s > self.square[1] {
                self.square[1] = s;
                let cut = s * (1.0 - NORM_MARGIN);
                self.hi.retain(|c| c >= cut);
            }
            self.hi.push(s, x, &mut self.range);
        }
    }

    /// The extremes of the norms of every vector added.
    fn finish(mut self) -> [f64; 2] {
        self.lo.flush(&mut self.range);
        self.hi.flush(&mut self.range);
        self.range
    }
}

/// A chunk's summary, with |rB| and |vB| through their [`NormRange`]s.
struct SummaryAcc {
    summary: SweepSummary,
    r_b: NormRange,
    v_b: NormRange,
}

impl SummaryAcc {
    fn finish(self) -> SweepSummary {
        let mut s = self.summary;
        join(&mut s.r_b, self.r_b.finish());
        join(&mut s.v_b, self.v_b.finish());
        s
    }
}

/// Result of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepOut {
    /// Summary over every point.
    pub summary: SweepSummary,
    /// Kept points (when the series was asked), angles continuous with the first in [0, 2π).
    pub series: Option<Vec<PointKin>>,
}

/// Output of [`compute`].
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialCouplingOutput {
    /// The coupling's constants.
    pub coupling: Coupling,
    /// One result per requested input angle.
    pub points: Vec<PointResult>,
    /// The sweep, if one was requested.
    pub sweep: Option<SweepOut>,
    /// Largest |rB|/a over everything evaluated (0 when B was not evaluated).
    pub max_radius_over_a: f64,
    /// Points evaluated.
    pub evaluated: u64,
}

/// Which groups one evaluation computes.
#[derive(Debug, Clone, Copy)]
struct Need {
    groups: Groups,
    body3: bool,
    /// A sweep with a summary: contact and both relative motions are needed for the extremes.
    summary: bool,
}

impl Need {
    fn contact(&self) -> bool {
        let g = self.groups;
        self.summary
            || g.contact
            || g.relative_1
            || g.relative_2
            || g.frames
            || g.check
            || self.body3
    }
}

/// The evaluation context of one request.
struct Ctx<'a> {
    cpl: Coupling,
    a: f64,
    omega1: f64,
    body3: &'a [V3],
}

impl Ctx<'_> {
    /// All requested groups at θ1 [deg]; `Err(D)` where B is at infinity. Angles are wrapped to
    /// [0°, 360°), or continuous along a sweep (`continuous`).
    fn eval(&self, theta1_deg: f64, need: Need, continuous: bool) -> Result<PointKin, f64> {
        let core = self.cpl.core(theta1_deg);
        let w = self.omega1;
        let mut p = PointKin {
            theta1_deg,
            theta2_deg: if continuous {
                self.cpl.theta2_continuous_deg(theta1_deg, &core)
            } else {
                wrap_360(self.cpl.theta2(&core).to_degrees())
            },
            i12: core.i12,
            di12: core.di12,
            omega2: core.i12 * w,
            epsilon2: core.di12 * w * w,
            contact: None,
            rel1: None,
            rel2: None,
            frames: None,
            body3: None,
            check: None,
            radius_over_a: 0.0,
        };
        let d = self.cpl.d(core.s1, core.c1);
        let Some(b) = self.cpl.contact(core.s1, core.c1) else {
            return Err(d);
        };
        if !need.contact() {
            return Ok(p);
        }
        let g = need.groups;
        let (a, w) = (self.a, self.omega1);
        let r = b.r.map(|x| a * x);
        let v = b.dr.map(|x| a * w * x);
        p.radius_over_a = norm(b.r);
        if g.contact || need.summary {
            p.contact = Some(ContactOut {
                r,
                v,
                speed: norm(v),
                d: b.d,
            });
        }
        let rel = |k: RelKin, centre: f64| RelOut {
            x: a * k.x,
            z: a * k.z,
            vx: a * w * k.dx,
            vz: a * w * k.dz,
            theta_deg: if continuous {
                about_centre(k.theta, centre).to_degrees()
            } else {
                wrap_360(k.theta.to_degrees())
            },
            omega: w * k.omega,
        };
        let r1 = rel(self.cpl.relative_1(&core, &b), self.cpl.theta31_centre());
        let r2 = rel(self.cpl.relative_2(&core, &b), self.cpl.theta32_centre());
        if g.relative_1 || need.summary {
            p.rel1 = Some(r1);
        }
        if g.relative_2 || need.summary {
            p.rel2 = Some(r2);
        }
        if g.frames || g.check || need.body3 {
            let f = self.cpl.frames(&core);
            if g.frames {
                p.frames = Some(FramesOut {
                    frames: f,
                    t13: transform(&f.f1, &f.f3, [r[0] - a, r[1], r[2]]),
                    t23: transform(&f.f2, &f.f3, [r[0] + a, r[1], r[2]]),
                });
            }
            if g.check {
                p.check = Some(self.check(&f, &b));
            }
            if need.body3 {
                p.body3 = Some(self.body3(&f, r, v, &r1, &r2));
            }
        }
        Ok(p)
    }

    /// The summary's quantities at θ1 \[deg\] added to `s` (a sweep point that is not kept): the
    /// same arithmetic as [`Ctx::eval`] with `continuous`, without θ2, the rates the summary does
    /// not read, or a [`PointKin`]. False where B is at infinity.
    #[inline]
    fn add_to_summary(&self, theta1_deg: f64, acc: &mut SummaryAcc) -> bool {
        let cpl = &self.cpl;
        let core = cpl.core(theta1_deg);
        let Some(b) = cpl.contact(core.s1, core.c1) else {
            return false;
        };
        let (a, w) = (self.a, self.omega1);
        acc.r_b.add(b.r.map(|x| a * x));
        acc.v_b.add(b.dr.map(|x| a * w * x));
        let s = &mut acc.summary;
        s.n += 1;
        widen(&mut s.i12, core.i12);
        widen(&mut s.i12_abs, core.i12.abs());
        widen(&mut s.d_abs, b.d.abs());
        let k1 = cpl.relative_1(&core, &b);
        widen(
            &mut s.theta31,
            about_centre(k1.theta, cpl.theta31_centre()).to_degrees(),
        );
        s.omega31 = s.omega31.max((w * k1.omega).abs());
        let k2 = cpl.relative_2(&core, &b);
        widen(
            &mut s.theta32,
            about_centre(k2.theta, cpl.theta32_centre()).to_degrees(),
        );
        widen(&mut s.x2, a * k2.x);
        widen(&mut s.z2, a * k2.z);
        s.omega32 = s.omega32.max((w * k2.omega).abs());
        true
    }

    fn check(&self, f: &FrameKin, b: &ContactKin) -> CheckOut {
        let (a, r) = (self.a, b.r.map(|x| self.a * x));
        let l = a.max(norm(r));
        let n0 = [0.0, -self.cpl.cb, self.cpl.sb];
        let closure = [
            dot([r[0] - a, r[1], r[2]], f.f1[1]).abs() / l,
            dot([r[0] + a, r[1], r[2]], f.f2[1]).abs() / l,
            dot(n0, r).abs() / l,
            dot(f.f1[1], f.f2[1]).abs(),
        ];
        let mut ortho: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { 1.0 } else { 0.0 };
                ortho = ortho.max((dot(f.f3[i], f.f3[j]) - want).abs());
            }
        }
        CheckOut {
            closure,
            orthonormality: ortho,
        }
    }

    fn body3(&self, f: &FrameKin, r: V3, v: V3, r1: &RelOut, r2: &RelOut) -> Vec<Body3Out> {
        let [i3, j3, k3] = f.f3;
        // Absolute angular velocity of body 3: shaft 1 about k1 plus body 3 about j1 ≡ i3.
        let w3 = add(scale(f.f1[2], self.omega1), scale(f.f1[1], r1.omega));
        let in_frame = |fr: &[V3; 3], x: V3| [dot(fr[0], x), dot(fr[1], x), dot(fr[2], x)];
        let a = self.a;
        self.body3
            .iter()
            .map(|p| {
                let q = add(add(scale(i3, p[0]), scale(j3, p[1])), scale(k3, p[2]));
                let r0 = add(r, q);
                let q1 = in_frame(&f.f1, q);
                let q2 = in_frame(&f.f2, q);
                Body3Out {
                    r0,
                    r1: in_frame(&f.f1, [r0[0] - a, r0[1], r0[2]]),
                    r2: in_frame(&f.f2, [r0[0] + a, r0[1], r0[2]]),
                    v0: add(v, cross(w3, q)),
                    // ω × q with ω along y of the shaft frame: (ω q_z, 0, −ω q_x).
                    v1: [r1.vx + r1.omega * q1[2], 0.0, r1.vz - r1.omega * q1[0]],
                    v2: [r2.vx + r2.omega * q2[2], 0.0, r2.vz - r2.omega * q2[0]],
                }
            })
            .collect()
    }
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Pose of body 3 in a shaft frame: rotation rows fᵣ·f3_c, translation fᵣ·(rB − A).
fn transform(shaft: &[V3; 3], body: &[V3; 3], rel: V3) -> [[f64; 4]; 4] {
    let mut t = [[0.0; 4]; 4];
    for (row, fr) in t.iter_mut().zip(shaft) {
        for (c, fb) in body.iter().enumerate() {
            row[c] = dot(*fr, *fb);
        }
        row[3] = dot(*fr, rel);
    }
    t[3][3] = 1.0;
    t
}

/// Whether the support plane passes the validity test to round-off: D(0), D(90°) of one sign and
/// min|D|/max|D| above the level where D = 0 cannot be told from rounding.
#[must_use]
pub fn plane_usable(cpl: &Coupling) -> bool {
    cpl.plane_valid() && cpl.d_min_over_max() > D_ZERO_ULPS * f64::EPSILON
}

/// Evaluate the requested points and sweep.
///
/// # Errors
/// [`SpatialCouplingError::SupportPlaneInvalid`] for a sweep with an invalid support plane;
/// [`SpatialCouplingError::Deadline`] when the budget runs out.
pub fn compute(
    input: &SpatialCouplingInput,
    budget: &Budget,
) -> Result<SpatialCouplingOutput, SpatialCouplingError> {
    let cpl = Coupling::new(input.alpha_deg, input.beta_deg, input.sigma);
    if input.sweep.is_some() && !plane_usable(&cpl) {
        let roots = if cpl.plane_valid() {
            // Valid in exact arithmetic, but D reaches round-off level at 0° or 90°.
            if cpl.d0.abs() <= cpl.d90.abs() {
                vec![0.0, 180.0]
            } else {
                vec![90.0, 270.0]
            }
        } else {
            cpl.d_roots_deg()
        };
        return Err(SpatialCouplingError::SupportPlaneInvalid {
            d0: cpl.d0,
            d90: cpl.d90,
            min_over_max: cpl.d_min_over_max(),
            roots,
        });
    }
    let ctx = Ctx {
        cpl,
        a: input.a,
        omega1: input.omega1,
        body3: &input.body3,
    };
    let total = input.points.len() + input.sweep.map_or(0, |s| s.n_points);
    let total_u = total as u64;
    let need = Need {
        groups: input.groups,
        body3: !input.body3.is_empty(),
        summary: false,
    };
    let chunks = chunk_bounds(input.points.len());
    let done = par_map_while(budget.threads(), &chunks, |_, &(lo, hi)| {
        if budget.check(lo as u64).is_some() {
            return None;
        }
        budget.progress(lo as f64 / total.max(1) as f64, None);
        Some(
            input.points[lo..hi]
                .iter()
                .map(|&t| match ctx.eval(t, need, false) {
                    Ok(p) => PointResult::Ok(Box::new(p)),
                    Err(d) => PointResult::AtInfinity { theta1_deg: t, d },
                })
                .collect::<Vec<_>>(),
        )
    });
    let mut points = Vec::with_capacity(input.points.len());
    for (c, r) in chunks.iter().zip(done) {
        let Some(r) = r else {
            return Err(SpatialCouplingError::Deadline {
                points: c.0 as u64,
                total: total_u,
            });
        };
        points.extend(r);
    }
    let sweep = match input.sweep {
        Some(s) => Some(sweep(&ctx, input, s, points.len(), budget)?),
        None => None,
    };
    let mut max_radius: f64 = 0.0;
    for p in &points {
        if let PointResult::Ok(p) = p {
            max_radius = max_radius.max(p.radius_over_a);
        }
    }
    if let Some(s) = &sweep
        && s.summary.n > 0
        && s.summary.r_b[1].is_finite()
    {
        max_radius = max_radius.max(s.summary.r_b[1] / input.a);
    }
    Ok(SpatialCouplingOutput {
        coupling: cpl,
        points,
        sweep,
        max_radius_over_a: max_radius,
        evaluated: total_u,
    })
}

/// An angle \[deg\] wrapped to [0°, 360°), −0 written as 0.
#[must_use]
pub fn wrap_360(deg: f64) -> f64 {
    let d = deg.rem_euclid(360.0);
    // rem_euclid rounds up to exactly 360 for tiny negative inputs.
    if d >= 360.0 { 0.0 } else { d + 0.0 }
}

fn chunk_bounds(n: usize) -> Vec<(usize, usize)> {
    (0..n.div_ceil(CHUNK))
        .map(|i| (i * CHUNK, ((i + 1) * CHUNK).min(n)))
        .collect()
}

/// The sweep: every point evaluated for the summary, every `decimate`-th (and the last) kept.
fn sweep(
    ctx: &Ctx<'_>,
    input: &SpatialCouplingInput,
    s: Sweep,
    done_before: usize,
    budget: &Budget,
) -> Result<SweepOut, SpatialCouplingError> {
    let total = done_before + s.n_points;
    let need = Need {
        groups: input.groups,
        body3: !input.body3.is_empty(),
        summary: input.summary,
    };
    let keep = |k: usize| input.series && (k.is_multiple_of(input.decimate) || k + 1 == s.n_points);
    let chunks = chunk_bounds(s.n_points);
    let done = par_map_while(budget.threads(), &chunks, |_, &(lo, hi)| {
        if budget.check((done_before + lo) as u64).is_some() {
            return None;
        }
        budget.progress((done_before + lo) as f64 / total.max(1) as f64, None);
        let mut acc = SummaryAcc {
            summary: SweepSummary::default(),
            r_b: NormRange::EMPTY,
            v_b: NormRange::EMPTY,
        };
        let mut kept = Vec::new();
        for k in lo..hi {
            let t = s.theta1_deg(k);
            if !keep(k) {
                // Only the summary reads this point; without one, only its |rB| for the largest
                // radius of the answer (which the summary's extremes carry), when B is asked.
                if input.summary || input.groups.contact {
                    // The plane passed the validity test: B is finite at every θ1.
                    ctx.add_to_summary(t, &mut acc);
                }
                continue;
            }
            // The plane passed the validity test: B is finite at every θ1.
            let Ok(p) = ctx.eval(t, need, true) else {
                continue;
            };
            acc.summary.add(&p);
            // The summary needed B and both relative motions; the series carries only what was
            // asked.
            let g = input.groups;
            let mut p = p;
            if !g.contact {
                p.contact = None;
            }
            if !g.relative_1 {
                p.rel1 = None;
            }
            if !g.relative_2 {
                p.rel2 = None;
            }
            kept.push(p);
        }
        Some((acc.finish(), kept))
    });
    let mut summary = SweepSummary::default();
    let mut series = input.series.then(Vec::new);
    for (c, r) in chunks.iter().zip(done) {
        let Some((sm, kept)) = r else {
            return Err(SpatialCouplingError::Deadline {
                points: (done_before + c.0) as u64,
                total: total as u64,
            });
        };
        summary.merge(&sm);
        if let Some(v) = &mut series {
            v.extend(kept);
        }
    }
    if let Some(v) = &mut series {
        first_in_first_turn(v);
    }
    Ok(SweepOut { summary, series })
}

/// Shift each continuous angle of the series by whole turns so its first value is in
/// [0°, 360°) (spec §3.5).
fn first_in_first_turn(v: &mut [PointKin]) {
    let Some(first) = v.first() else {
        return;
    };
    let turns = |x: f64| 360.0 * (x / 360.0).floor();
    let o2 = turns(first.theta2_deg);
    let o31 = first.rel1.map_or(0.0, |r| turns(r.theta_deg));
    let o32 = first.rel2.map_or(0.0, |r| turns(r.theta_deg));
    // Beyond ~1e307° the shift itself can overflow; such angles (flagged `LARGE_ANGLE`) carry no
    // revolution information anyway and are wrapped to [0°, 360°) instead.
    let shift = |x: f64, o: f64| {
        let y = x - o;
        if y.is_finite() { y } else { wrap_360(x) }
    };
    for p in v.iter_mut() {
        p.theta2_deg = shift(p.theta2_deg, o2);
        if let Some(r) = &mut p.rel1 {
            r.theta_deg = shift(r.theta_deg, o31);
        }
        if let Some(r) = &mut p.rel2 {
            r.theta_deg = shift(r.theta_deg, o32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`NormRange`] gives exactly the extremes of `norm` taken at every vector: smooth runs,
    /// constant norms (every vector a candidate), ties within rounding, tiny and huge vectors.
    #[test]
    fn norm_range_is_exact() {
        let mut runs: Vec<Vec<V3>> = Vec::new();
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut rnd = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for scale in [1.0, 1e-150, 1e145, 3.7e-3] {
            runs.push(
                (0..5000)
                    .map(|_| [rnd(), rnd(), rnd()].map(|c| c * scale))
                    .collect(),
            );
            runs.push(
                (0..5000)
                    .map(|k| {
                        let t = k as f64 * 1e-3;
                        [t.cos() * scale, t.sin() * scale, 0.5 * scale]
                    })
                    .collect(),
            );
            // Norms equal up to rounding: every vector stays a candidate.
            runs.push(
                (0..5000)
                    .map(|k| {
                        let t = k as f64 * 0.37;
                        [t.cos() * scale, t.sin() * scale, 0.0]
                    })
                    .collect(),
            );
        }
        runs.push(vec![
            [0.0; 3],
            [f64::NAN, 1.0, 0.0],
            [f64::INFINITY, 0.0, 0.0],
            [1.0, 2.0, 3.0],
        ]);
        for run in &runs {
            let mut want = EMPTY;
            let mut r = NormRange::EMPTY;
            for &v in run {
                widen(&mut want, norm(v));
                r.add(v);
            }
            let got = r.finish();
            assert_eq!(
                got.map(f64::to_bits),
                want.map(f64::to_bits),
                "{got:?} {want:?}"
            );
        }
    }
}
