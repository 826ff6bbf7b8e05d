//! Closed-form four-bar geometry: Grashof/Barker classification (spec §4.2), feasible input range
//! and circuits (§4.3), position analysis for both assembly branches (§4.4), the Roberts–Chebyshev
//! construction (§4.5), the pose map (§4.6) and the coupler-curve sextic (§4.9).
//!
//! Conventions (spec §2): points are complex numbers `z = x + i·y`; angles in radians, CCW positive,
//! absolute angles from the +x axis, relative angles `φ` from the directed ground line
//! `input_pivot → output_pivot`. Branch `t = +1` puts the rocker joint E to the left of the directed
//! line `D → output_pivot`. The coupler point is `P = D + k·(E − D)` with the complex coupler ratio `k`.
//!
//! All functions are scale-invariant; tolerances are relative to the mechanism's own largest length
//! ([`FourBar::scale`]).

use std::f64::consts::PI;

/// A complex number used as a 2-D point or vector (`re` = x, `im` = y).
pub type C64 = nalgebra::Complex<f64>;

/// Relative distance below which the crank tip is taken to sit on the output pivot (spec §4.4 step 2):
/// the dyad direction is undefined there.
pub const SINGULAR_REL: f64 = 1e-12;
/// Relative slack on `h²` (in units of `(b + c)²`) that still counts as assemblable (spec §4.4 step 4):
/// absorbs the rounding of `s` at a toggle (relative error ~1e-16 in `s` gives ~1e-16 in `h²`).
pub const ASSEMBLY_SLACK_REL: f64 = 1e-12;
/// Dyad height `h/b` at or below which a pose is flagged as a toggle (spec §4.4 step 4).
pub const TOGGLE_REL: f64 = 1e-9;

/// `cross(u, v) = u_x v_y − u_y v_x` (positive when `v` is CCW from `u`).
#[must_use]
pub fn cross(u: C64, v: C64) -> f64 {
    u.re * v.im - u.im * v.re
}

/// Dot product of two plane vectors.
#[must_use]
pub fn dot(u: C64, v: C64) -> f64 {
    u.re * v.re + u.im * v.im
}

/// Modulus `|z|` by `sqrt(x² + y²)`: `hypot` guards against overflow that cannot occur in the
/// normalised frame (|z| ≲ 1e13 there) and costs 2–3× more in the sampling loops.
#[must_use]
pub fn mag(z: C64) -> f64 {
    z.norm_sqr().sqrt()
}

/// Unit vector at angle `theta` \[rad\].
#[must_use]
pub fn cis(theta: f64) -> C64 {
    let (s, c) = theta.sin_cos();
    C64::new(c, s)
}

pub use crate::numerics::angles::wrap_pi;

/// Assembly branch or coupler side: a sign, `+1` or `−1` (spec §2: `t1`, `t2`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sign {
    /// +1.
    Plus,
    /// −1.
    Minus,
}

impl Sign {
    /// +1.0 or −1.0.
    #[must_use]
    pub fn value(self) -> f64 {
        match self {
            Self::Plus => 1.0,
            Self::Minus => -1.0,
        }
    }

    /// +1 or −1 as an integer.
    #[must_use]
    pub fn as_i8(self) -> i8 {
        match self {
            Self::Plus => 1,
            Self::Minus => -1,
        }
    }

    /// The opposite sign.
    #[must_use]
    pub fn flip(self) -> Self {
        match self {
            Self::Plus => Self::Minus,
            Self::Minus => Self::Plus,
        }
    }

    /// Sign of `x`; `None` for zero (and NaN).
    #[must_use]
    pub fn of(x: f64) -> Option<Self> {
        if x > 0.0 {
            Some(Self::Plus)
        } else if x < 0.0 {
            Some(Self::Minus)
        } else {
            None
        }
    }
}

/// A planar four-bar with a coupler point: the tuple `(O_in, O_out, a, b, c, k)` of spec §2 plus its
/// ground length. The cognates are ordinary four-bars of this type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourBar {
    /// Input (crank) ground pivot `O_in`.
    pub input_pivot: C64,
    /// Output (rocker) ground pivot `O_out`.
    pub output_pivot: C64,
    /// Ground length `g = |O_out − O_in|`, stored so that the cognates' ground lengths are the exact
    /// products `|k|·l`, `|1−k|·l` (keeps equalities such as `crank = ground` bit-exact).
    pub ground: f64,
    /// Crank `a = |D − O_in|`.
    pub crank: f64,
    /// Coupler `b = |E − D|`.
    pub coupler: f64,
    /// Rocker `c = |E − O_out|`.
    pub rocker: f64,
    /// Complex coupler ratio `k`: `P = D + k·(E − D)`.
    pub k: C64,
}

/// Outcome of the position analysis at one input angle and branch (spec §4.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solve {
    /// The linkage assembles.
    Pose(Pose),
    /// `h² < 0` beyond the slack: the coupler and rocker cannot reach (`s` outside `[|b−c|, b+c]`).
    NotAssemblable {
        /// Distance crank tip – output pivot.
        s: f64,
        /// Crank tip.
        d: C64,
    },
    /// The crank tip sits on the output pivot (`s ≈ 0`): the dyad direction is undefined.
    Singular {
        /// Crank tip.
        d: C64,
    },
}

/// One assembled configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Crank tip D.
    pub d: C64,
    /// Rocker tip E.
    pub e: C64,
    /// Coupler point P.
    pub p: C64,
    /// Height of E above the line D–O_out (`h ≥ 0`; 0 at a toggle).
    pub h: f64,
    /// Distance `s = |O_out − D|`.
    pub s: f64,
}

/// Grashof class (spec §4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GrashofClass {
    /// `s + l < p + q` (beyond the tolerance).
    Grashof,
    /// `s + l > p + q`.
    NonGrashof,
    /// `|s + l − (p + q)| ≤ rtol·l`.
    ChangePoint,
}

/// Four-bar type by input/output motion (spec §4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkageType {
    /// Grashof, ground shortest.
    DoubleCrank,
    /// Grashof, input shortest.
    CrankRocker,
    /// Grashof, coupler shortest.
    DoubleRocker,
    /// Grashof, output shortest.
    RockerCrank,
    /// Non-Grashof.
    TripleRocker,
    /// Change point (`s + l = p + q`).
    ChangePoint,
}

/// Role of a link in a four-bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkRole {
    /// Fixed link between the pivots.
    Ground,
    /// Crank (input link).
    Input,
    /// Coupler.
    Coupler,
    /// Rocker (output link).
    Output,
}

/// Special shapes (spec §4.2, §7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Special {
    /// `a = c`, `b = g`.
    Parallelogram,
    /// `a = g`, `b = c` (the crank tip can reach the output pivot).
    DeltoidCrankGround,
    /// `a = b`, `c = g` (the coupler can fold onto the crank).
    DeltoidCrankCoupler,
    /// All four links equal.
    Rhombus,
}

/// Grashof/Barker classification of one four-bar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grashof {
    /// Class.
    pub class: GrashofClass,
    /// Type.
    pub kind: LinkageType,
    /// Barker code (GCCC, GCRR, GRCR, GRRC, RRR1..RRR4); `None` for change points.
    pub barker: Option<&'static str>,
    /// Special shape, if any.
    pub special: Option<Special>,
    /// Signed margin `m = (s + l) − (p + q)`; negative = Grashof.
    pub margin: f64,
    /// `s + l`.
    pub s_plus_l: f64,
    /// `p + q`.
    pub p_plus_q: f64,
    /// Shortest link (first in the order ground, input, coupler, output on ties).
    pub shortest: LinkRole,
    /// Longest link (last in that order on ties).
    pub longest: LinkRole,
}

/// Feasible input range relative to the ground line (spec §4.3): `φ_min ≤ |φ| ≤ φ_max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputRange {
    /// `φ_min` \[rad\], 0 when the crank tip can pass the output pivot's near side.
    pub phi_min: f64,
    /// `φ_max` \[rad\], π when the crank can pass the far side.
    pub phi_max: f64,
}

/// One closed circuit of the configuration space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Circuit {
    /// Full rotation of the input on a fixed branch (case 1 of §4.3), `φ ∈ [−π, π)`.
    Full(Sign),
    /// A limited interval `[lo, hi]` (rad, relative), branch +1 going up and −1 coming back.
    Limited {
        /// Lower end (a toggle).
        lo: f64,
        /// Upper end (a toggle).
        hi: f64,
    },
}

impl InputRange {
    /// Whether the input rotates fully.
    #[must_use]
    pub fn full_rotation(&self) -> bool {
        self.phi_min <= 0.0 && self.phi_max >= PI
    }

    /// Feasible intervals of `φ` \[rad\]; case 3 runs through π and may end above π.
    #[must_use]
    pub fn intervals(&self) -> Vec<(f64, f64)> {
        if self.full_rotation() {
            vec![(-PI, PI)]
        } else if self.phi_min <= 0.0 {
            vec![(-self.phi_max, self.phi_max)]
        } else if self.phi_max >= PI {
            vec![(self.phi_min, 2.0 * PI - self.phi_min)]
        } else {
            vec![(self.phi_min, self.phi_max), (-self.phi_max, -self.phi_min)]
        }
    }

    /// Toggle (dead-centre) input angles relative to the ground line \[rad\], wrapped to (−π, π].
    #[must_use]
    pub fn toggles(&self) -> Vec<f64> {
        if self.full_rotation() {
            Vec::new()
        } else {
            self.intervals()
                .into_iter()
                .flat_map(|(lo, hi)| [wrap_pi(lo), wrap_pi(hi)])
                .collect()
        }
    }

    /// The closed circuits (spec §4.3): two fixed-branch loops for full rotation, else one per interval.
    #[must_use]
    pub fn circuits(&self) -> Vec<Circuit> {
        if self.full_rotation() {
            vec![Circuit::Full(Sign::Plus), Circuit::Full(Sign::Minus)]
        } else {
            self.intervals()
                .into_iter()
                .map(|(lo, hi)| Circuit::Limited { lo, hi })
                .collect()
        }
    }

    /// Whether `phi` (relative, rad) lies in the feasible set.
    #[must_use]
    pub fn contains(&self, phi: f64) -> bool {
        let x = wrap_pi(phi).abs();
        x >= self.phi_min && x <= self.phi_max
    }
}

/// Angle at the vertex between sides `p` and `q` of a triangle whose third side is `x`, by the
/// half-angle formula `tan²(φ/2) = (x−p+q)(x+p−q) / ((p+q−x)(p+q+x))`: accurate near 0 and π
/// (where `acos` loses half the digits) and saturating to 0 when `x ≤ |p − q|` and to π when
/// `x ≥ p + q`.
#[must_use]
pub fn included_angle(p: f64, q: f64, x: f64) -> f64 {
    let num = (x - p + q) * (x + p - q);
    let den = (p + q - x) * (p + q + x);
    2.0 * num.max(0.0).sqrt().atan2(den.max(0.0).sqrt())
}

impl FourBar {
    /// Largest length of the mechanism (ground, links, both coupler-point distances): the scale of
    /// all relative tolerances.
    #[must_use]
    pub fn scale(&self) -> f64 {
        self.ground
            .max(self.crank)
            .max(self.coupler)
            .max(self.rocker)
            .max(self.crank_joint_to_p())
            .max(self.rocker_joint_to_p())
    }

    /// Smallest length of the mechanism (same set as [`FourBar::scale`]).
    #[must_use]
    pub fn min_length(&self) -> f64 {
        self.ground
            .min(self.crank)
            .min(self.coupler)
            .min(self.rocker)
            .min(self.crank_joint_to_p())
            .min(self.rocker_joint_to_p())
    }

    /// Direction of the ground line `arg(O_out − O_in)` \[rad\].
    #[must_use]
    pub fn ground_angle(&self) -> f64 {
        (self.output_pivot - self.input_pivot).arg()
    }

    /// `|P − D| = |k|·b` (paper `d`).
    #[must_use]
    pub fn crank_joint_to_p(&self) -> f64 {
        self.k.norm() * self.coupler
    }

    /// `|P − E| = |1 − k|·b` (paper `e`).
    #[must_use]
    pub fn rocker_joint_to_p(&self) -> f64 {
        (C64::new(1.0, 0.0) - self.k).norm() * self.coupler
    }

    /// Coupler side `t2 = sign Im k`; `None` when P is on the line DE.
    #[must_use]
    pub fn coupler_side(&self) -> Option<Sign> {
        Sign::of(self.k.im)
    }

    /// Grashof/Barker classification with relative tolerance `rtol` (spec §4.2).
    #[must_use]
    pub fn grashof(&self, rtol: f64) -> Grashof {
        let mut links = [
            (self.ground, LinkRole::Ground),
            (self.crank, LinkRole::Input),
            (self.coupler, LinkRole::Coupler),
            (self.rocker, LinkRole::Output),
        ];
        links.sort_by(|x, y| x.0.total_cmp(&y.0));
        let [s1, s2, s3, s4] = links.map(|l| l.0);
        let s_plus_l = s1 + s4;
        let p_plus_q = s2 + s3;
        let margin = s_plus_l - p_plus_q;
        let tol = rtol * s4;
        let shortest = links[0].1;
        let longest = links[3].1;
        let (class, kind, barker) = if margin.abs() <= tol {
            (GrashofClass::ChangePoint, LinkageType::ChangePoint, None)
        } else if margin < 0.0 {
            let (kind, code) = match shortest {
                LinkRole::Ground => (LinkageType::DoubleCrank, "GCCC"),
                LinkRole::Input => (LinkageType::CrankRocker, "GCRR"),
                LinkRole::Coupler => (LinkageType::DoubleRocker, "GRCR"),
                LinkRole::Output => (LinkageType::RockerCrank, "GRRC"),
            };
            (GrashofClass::Grashof, kind, Some(code))
        } else {
            let code = match longest {
                LinkRole::Ground => "RRR1",
                LinkRole::Input => "RRR2",
                LinkRole::Coupler => "RRR3",
                LinkRole::Output => "RRR4",
            };
            (
                GrashofClass::NonGrashof,
                LinkageType::TripleRocker,
                Some(code),
            )
        };
        let eq = |x: f64, y: f64| (x - y).abs() <= tol;
        let (g, a, b, c) = (self.ground, self.crank, self.coupler, self.rocker);
        let parallelogram = eq(a, c) && eq(b, g);
        let deltoid_ground = eq(a, g) && eq(b, c);
        let deltoid_coupler = eq(a, b) && eq(c, g);
        let special = if parallelogram && (deltoid_ground || deltoid_coupler) {
            Some(Special::Rhombus)
        } else if parallelogram {
            Some(Special::Parallelogram)
        } else if deltoid_ground {
            Some(Special::DeltoidCrankGround)
        } else if deltoid_coupler {
            Some(Special::DeltoidCrankCoupler)
        } else {
            None
        };
        Grashof {
            class,
            kind,
            barker,
            special,
            margin,
            s_plus_l,
            p_plus_q,
            shortest,
            longest,
        }
    }

    /// Whether some input angle assembles the linkage with a motion range of non-zero width: the
    /// longest of (g, a, b, c) must be shorter than the sum of the other three by more than
    /// `slack_rel·longest`.
    #[must_use]
    pub fn assemblable(&self, slack_rel: f64) -> bool {
        let l = [self.ground, self.crank, self.coupler, self.rocker];
        let longest = l.iter().copied().fold(0.0_f64, f64::max);
        let sum: f64 = l.iter().sum();
        longest < (sum - longest) - slack_rel * longest
    }

    /// Feasible input range (spec §4.3), by the half-angle formula of [`included_angle`].
    #[must_use]
    pub fn input_range(&self) -> InputRange {
        let (g, a, b, c) = (self.ground, self.crank, self.coupler, self.rocker);
        InputRange {
            phi_min: included_angle(a, g, (b - c).abs()),
            phi_max: included_angle(a, g, b + c),
        }
    }

    /// Crank tip at absolute input angle `theta` \[rad\].
    #[must_use]
    pub fn crank_tip(&self, theta: f64) -> C64 {
        self.input_pivot + cis(theta) * self.crank
    }

    /// Distance `s` at or below which the crank tip counts as sitting on the output pivot
    /// (`1e-12·L`, spec §4.4 step 2). Hot loops compute it once and call the `*_tol` solvers.
    #[must_use]
    pub fn singular_tol(&self) -> f64 {
        SINGULAR_REL * self.scale()
    }

    /// Closed-form position analysis (spec §4.4) at absolute input angle `theta` \[rad\] on branch `t`.
    /// With `clamp`, a negative `h²` is set to 0 (for inputs known to lie inside the feasible range,
    /// where only rounding can make it negative); otherwise beyond the slack it is `NotAssemblable`.
    #[must_use]
    pub fn solve(&self, theta: f64, t: Sign, clamp: bool) -> Solve {
        self.solve_tol(theta, t, clamp, self.singular_tol())
    }

    /// [`FourBar::solve`] with a precomputed [`FourBar::singular_tol`].
    #[must_use]
    pub fn solve_tol(&self, theta: f64, t: Sign, clamp: bool, s_min: f64) -> Solve {
        self.solve_dyad_tol(self.crank_tip(theta), t, clamp, s_min)
    }

    /// The dyad part of [`FourBar::solve`] for a given crank tip `d`.
    #[must_use]
    pub fn solve_dyad(&self, d: C64, t: Sign, clamp: bool) -> Solve {
        self.solve_dyad_tol(d, t, clamp, self.singular_tol())
    }

    /// [`FourBar::solve_dyad`] with a precomputed [`FourBar::singular_tol`].
    #[must_use]
    pub fn solve_dyad_tol(&self, d: C64, t: Sign, clamp: bool, s_min: f64) -> Solve {
        let w = self.output_pivot - d;
        let s = mag(w);
        if s <= s_min {
            return Solve::Singular { d };
        }
        let (b, c) = (self.coupler, self.rocker);
        // l1 = (b² + s² − c²)/(2s), with b² − c² factored to keep digits when b ≈ c.
        let l1 = ((b - c) * (b + c) + s * s) / (2.0 * s);
        // Factored form of b² − l1² (spec §4.4 step 4): no cancellation at the toggles.
        let h2 = (s + b + c) * (s + b - c) * (s - b + c) * (b + c - s) / (4.0 * s * s);
        if !clamp && h2 < -ASSEMBLY_SLACK_REL * (b + c) * (b + c) {
            return Solve::NotAssemblable { s, d };
        }
        let h = h2.max(0.0).sqrt();
        let u = w / s;
        let e = d + C64::new(l1, t.value() * h) * u;
        let p = d + self.k * (e - d);
        Solve::Pose(Pose { d, e, p, h, s })
    }

    /// Whether a pose is at a toggle (`h ≤ 1e-9·b`).
    #[must_use]
    pub fn is_toggle(&self, pose: &Pose) -> bool {
        pose.h <= TOGGLE_REL * self.coupler
    }

    /// Transmission angle of a pose \[rad\]: angle between `D − E` and `O_out − E`, folded into
    /// `[0, π/2]` (spec §4.4).
    #[must_use]
    pub fn transmission_angle(&self, d: C64, e: C64) -> f64 {
        let u = d - e;
        let v = self.output_pivot - e;
        let mu = cross(u, v).abs().atan2(dot(u, v));
        if mu > PI / 2.0 { PI - mu } else { mu }
    }

    /// Height of E above the line D–O_out and `s = |O_out − D|` for a given configuration.
    #[must_use]
    pub fn dyad_height(&self, d: C64, e: C64) -> (f64, f64) {
        let w = self.output_pivot - d;
        let s = mag(w);
        if s > 0.0 {
            (cross(w, e - d).abs() / s, s)
        } else {
            (mag(e - d), 0.0)
        }
    }

    /// Input angles (absolute, rad) at which the linkage folds flat (all joints on the ground line),
    /// i.e. the change-point configurations: `φ = 0` when `|g − a|` equals `b + c` or `|b − c|`,
    /// `φ = π` when `g + a` does, within `rtol·scale`.
    #[must_use]
    pub fn folded_angles(&self, rtol: f64) -> Vec<f64> {
        let (g, a, b, c) = (self.ground, self.crank, self.coupler, self.rocker);
        let tol = rtol * g.max(a).max(b).max(c);
        let hits = |s: f64| (s - (b + c)).abs() <= tol || (s - (b - c).abs()).abs() <= tol;
        let gamma = self.ground_angle();
        let mut out = Vec::new();
        if hits((g - a).abs()) {
            out.push(wrap_pi(gamma));
        }
        if hits(g + a) {
            out.push(wrap_pi(gamma + PI));
        }
        out
    }
}

/// The three mechanisms of a Roberts–Chebyshev family (spec §4.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Family {
    /// Third ground pivot `C = A + k·(B − A)`.
    pub c: C64,
    /// `[original, cognate 1 (A, C), cognate 2 (C, B)]`.
    pub mechs: [FourBar; 3],
}

/// Roberts–Chebyshev construction (spec §4.5): cognate 1 = (A, C, |k|b, |k|a, |k|c, 1/k),
/// cognate 2 = (C, B, |1−k|a, |1−k|c, |1−k|b, k/(k−1)).
#[must_use]
pub fn cognates(orig: &FourBar) -> Family {
    let one = C64::new(1.0, 0.0);
    let k = orig.k;
    let (a_piv, b_piv) = (orig.input_pivot, orig.output_pivot);
    let c = a_piv + k * (b_piv - a_piv);
    let nk = k.norm();
    let n1k = (one - k).norm();
    let cog1 = FourBar {
        input_pivot: a_piv,
        output_pivot: c,
        ground: nk * orig.ground,
        crank: nk * orig.coupler,
        coupler: nk * orig.crank,
        rocker: nk * orig.rocker,
        k: k.inv(),
    };
    let cog2 = FourBar {
        input_pivot: c,
        output_pivot: b_piv,
        ground: n1k * orig.ground,
        crank: n1k * orig.crank,
        coupler: n1k * orig.rocker,
        rocker: n1k * orig.coupler,
        k: k / (k - one),
    };
    Family {
        c,
        mechs: [*orig, cog1, cog2],
    }
}

/// The same configuration in all three mechanisms (spec §4.6): crank and rocker tips
/// `[(D, E), (D1, E1), (D2, E2)]` for an original configuration `(D, E, P)`.
#[must_use]
pub fn map_pose(family: &Family, pose: &Pose) -> [(C64, C64); 3] {
    let one = C64::new(1.0, 0.0);
    let orig = &family.mechs[0];
    let (a_piv, b_piv) = (orig.input_pivot, orig.output_pivot);
    let k = orig.k;
    let d1 = a_piv + (pose.p - pose.d);
    let e1 = a_piv + k * (pose.e - a_piv);
    let d2 = family.c + (one - k) * (pose.d - a_piv);
    let e2 = b_piv + (pose.p - pose.e);
    [(pose.d, pose.e), (d1, e1), (d2, e2)]
}

/// Branch of cognate 1 in the configuration of an original pose (spec §4.6):
/// `sign cross(D − A, E − B)`; `None` at a cognate-1 toggle.
#[must_use]
pub fn cognate1_branch(orig: &FourBar, pose: &Pose) -> Option<Sign> {
    Sign::of(cross(pose.d - orig.input_pivot, pose.e - orig.output_pivot))
}

/// Value and gradient of a quantity in forward-mode differentiation over (x, y).
#[derive(Debug, Clone, Copy)]
struct Dual {
    v: f64,
    dx: f64,
    dy: f64,
}

impl Dual {
    fn c(v: f64) -> Self {
        Self {
            v,
            dx: 0.0,
            dy: 0.0,
        }
    }
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            dx: self.dx + o.dx,
            dy: self.dy + o.dy,
        }
    }
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            dx: self.dx - o.dx,
            dy: self.dy - o.dy,
        }
    }
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            dx: self.dx * o.v + self.v * o.dx,
            dy: self.dy * o.v + self.v * o.dy,
        }
    }
    fn scale(self, s: f64) -> Self {
        Self {
            v: self.v * s,
            dx: self.dx * s,
            dy: self.dy * s,
        }
    }
}

/// Coupler-curve sextic `F(P)` of a four-bar (spec §4.9 `implicit`) and its gradient: zero exactly
/// on the full coupler curve (all circuits) of this coupler side. Returns `(F, |∇F|)`.
#[must_use]
pub fn sextic(mech: &FourBar, p: C64) -> (f64, f64) {
    let one = C64::new(1.0, 0.0);
    let d = mech.crank_joint_to_p();
    let m = (mech.k - one) / mech.k * d;
    let (a, c) = (mech.crank, mech.rocker);
    let wa = p - mech.input_pivot;
    let wb = p - mech.output_pivot;
    let wax = Dual {
        v: wa.re,
        dx: 1.0,
        dy: 0.0,
    };
    let way = Dual {
        v: wa.im,
        dx: 0.0,
        dy: 1.0,
    };
    let wbx = Dual {
        v: wb.re,
        dx: 1.0,
        dy: 0.0,
    };
    let wby = Dual {
        v: wb.im,
        dx: 0.0,
        dy: 1.0,
    };
    // z = conj(w_B)·m: Re z = wbx·m.re + wby·m.im, Im z = wbx·m.im − wby·m.re.
    let re_z = wbx.scale(m.re).add(wby.scale(m.im));
    let im_z = wbx.scale(m.im).sub(wby.scale(m.re));
    let r1 = Dual::c(a * a - d * d).sub(wax.mul(wax)).sub(way.mul(way));
    let r2 = Dual::c(c * c - m.norm_sqr())
        .sub(wbx.mul(wbx))
        .sub(wby.mul(wby));
    let a11 = wax.scale(2.0 * d);
    let a12 = way.scale(2.0 * d);
    let a21 = re_z.scale(2.0);
    let a22 = im_z.scale(-2.0);
    let det = a11.mul(a22).sub(a12.mul(a21));
    let nc = r1.mul(a22).sub(a12.mul(r2));
    let ns = a11.mul(r2).sub(a21.mul(r1));
    let f = nc.mul(nc).add(ns.mul(ns)).sub(det.mul(det));
    (f.v, f.dx.hypot(f.dy))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> FourBar {
        let (b, d, e) = (1.23_f64, 0.92_f64, 1.56_f64);
        let l2 = (d * d + b * b - e * e) / (2.0 * b);
        let h2 = (d * d - l2 * l2).sqrt();
        FourBar {
            input_pivot: C64::new(0.0, 0.0),
            output_pivot: C64::new(3.1, 0.0),
            ground: 3.1,
            crank: 1.13,
            coupler: b,
            rocker: 1.04,
            k: C64::new(l2 / b, h2 / b),
        }
    }

    #[test]
    fn sextic_vanishes_on_the_curve_and_gradient_matches_finite_differences() {
        let m = paper();
        let Solve::Pose(pose) = m.solve(30f64.to_radians(), Sign::Plus, false) else {
            panic!("assembles")
        };
        let (f, g) = sextic(&m, pose.p);
        assert!(f.abs() / g < 1e-13, "F = {f}, |grad| = {g}");
        let q = C64::new(0.3, 0.7);
        let (f0, g0) = sextic(&m, q);
        let hstep = 1e-6;
        let fx = (sextic(&m, q + C64::new(hstep, 0.0)).0 - sextic(&m, q - C64::new(hstep, 0.0)).0)
            / (2.0 * hstep);
        let fy = (sextic(&m, q + C64::new(0.0, hstep)).0 - sextic(&m, q - C64::new(0.0, hstep)).0)
            / (2.0 * hstep);
        assert!(
            (fx.hypot(fy) - g0).abs() < 1e-6 * g0.max(1.0),
            "{fx} {fy} {g0} {f0}"
        );
    }

    #[test]
    fn included_angle_saturates() {
        assert!((included_angle(1.0, 1.0, 3.0) - PI).abs() < 1e-15);
        assert!(included_angle(3.0, 1.0, 1.0).abs() < 1e-15);
        assert!((included_angle(1.0, 1.0, 2f64.sqrt()) - PI / 2.0).abs() < 1e-15);
    }

    #[test]
    fn wrap_pi_range() {
        assert!((wrap_pi(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_pi(-PI) - PI).abs() < 1e-12);
        assert!(wrap_pi(0.1).abs() - 0.1 < 1e-15);
    }
}
