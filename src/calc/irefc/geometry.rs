//! Shared geometry of the IREFC gear (spec `irefc_geometry.md`): derived radii and limits from the four
//! initial parameters (r2, Z2, χ, rb), per-angle quantities (pitch-point distance L, true contact angle α,
//! lever arms, exact profile curvature of both wheels), the load-sharing element set and optional profile
//! point sets.
//!
//! This is the ONE place where the geometry lives; [`super::stress`] and [`super::efficiency`] call it.
//!
//! # Conventions
//! * SI inside: lengths in metres, angles in radians.
//! * φ (paper φ2) is the element angle at the cage centre O, from ray O→P to ray O→O′; φ = 0 is the element in
//!   the cam root, φ = π the element at the cam tip. Loaded elements (driving direction) have φ ∈ [0, π].
//! * α is the TRUE contact angle `atan2(χ sin φ, 1 − χ cos φ)` ∈ [0, π] (never the paper's arcsin).
//! * Curvature κ_w of wheel w's profile at the contact point is signed: + convex (centre of curvature inside
//!   the wheel material), − concave. ρ_w = 1/κ_w (paper sign convention).
//! * Cage phase: element k sits at φ_k = 2π(p + k)/Z2 with the phase fraction p ∈ [0, 1) (phase angle
//!   p·2π/Z2); the loaded set is every k ≥ 0 with p + k ≤ Z2/2.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Smallest admitted number of rolling elements (Z2 = 2 gives Σsin²α = 0: division by zero).
pub const Z2_MIN: u32 = 3;
/// Largest admitted number of rolling elements (spec range).
pub const Z2_MAX: u32 = 1000;
/// Upper limit of the displacement coefficient χ (spec range; χ must also be > 1).
pub const CHI_MAX: f64 = 5.0;
/// Lower end of the force paper's χ range (assemblability) used for the `CHI_OUTSIDE_PAPER_RANGE` warning.
pub const CHI_PAPER_MIN: f64 = 1.25;
/// Upper end of the χ range swept in the force paper.
pub const CHI_PAPER_MAX: f64 = 1.67;
/// `NEAR_UNDERCUT` is raised when the sharpest convex profile radius is below this fraction of rb.
pub const NEAR_UNDERCUT_FRACTION: f64 = 0.25;

/// One of the two cycloid wheels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Wheel {
    /// Inner wheel on the eccentric, Z1 = Z2 − 1 lobes (contact point A).
    Cam,
    /// Outer wheel, Z3 = Z2 + 1 lobes (contact point B).
    Crown,
}

impl Wheel {
    /// Lower-case name used on the wire.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Cam => "cam",
            Self::Crown => "crown",
        }
    }
}

/// sin φ, cos φ and sin²(φ/2) of one angle, computed so that φ = π gives exactly (0, −1, 1) and φ = 0
/// exactly (0, 1, 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trig {
    /// sin φ.
    pub sin: f64,
    /// cos φ.
    pub cos: f64,
    /// sin²(φ/2) = (1 − cos φ)/2, computed without cancellation near φ = 0.
    pub half_sin2: f64,
}

impl Trig {
    /// Trigonometric values of any real φ \[rad\].
    ///
    /// φ is reduced to ψ = |φ| mod 2π folded into [0, π]; on (π/2, π] the functions are evaluated at
    /// π − ψ, which is exact (Sterbenz), so sin π = 0 and cos π = −1 exactly.
    #[must_use]
    pub fn of(phi: f64) -> Self {
        let mut psi = phi.abs() % TAU;
        let mut sign = if phi < 0.0 { -1.0 } else { 1.0 };
        if psi > PI {
            psi = TAU - psi;
            sign = -sign;
        }
        if psi > FRAC_PI_2 {
            // sin²(φ/2) = (1 − cos φ)/2 = (1 + cos q)/2: no cancellation for q ∈ [0, π/2).
            let q = PI - psi;
            let (s, c) = q.sin_cos();
            Self {
                sin: sign * s,
                cos: -c,
                half_sin2: 0.5 * (1.0 + c),
            }
        } else {
            // sin²(φ/2) = sin²φ / (2(1 + cos φ)): no cancellation near φ = 0.
            let (s, c) = psi.sin_cos();
            Self {
                sin: sign * s,
                cos: c,
                half_sin2: s * s / (2.0 * (1.0 + c)),
            }
        }
    }
}

/// Everything the compute modules need at one element angle φ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnglePoint {
    /// Element angle φ \[rad\].
    pub phi: f64,
    /// s(φ) = L/r2 = sqrt(1 + χ² − 2χ cos φ) [–].
    pub s: f64,
    /// Pitch point to element centre distance L = r2·s \[m\] (force paper eq. 15).
    pub l: f64,
    /// sin α [–].
    pub sin_alpha: f64,
    /// cos α [–].
    pub cos_alpha: f64,
    /// True contact angle α ∈ [0, π] \[rad\].
    pub alpha: f64,
    /// Cam lever arm h_cam = r1·sin α \[m\] (force paper eq. 13).
    pub h_cam: f64,
    /// Crown lever arm h_crown = r3·sin α \[m\].
    pub h_crown: f64,
    /// Pitch point to cam contact A, LA = L − rb \[m\] (efficiency paper eq. 8).
    pub la: f64,
    /// Pitch point to crown contact B, LB = L + rb \[m\].
    pub lb: f64,
    /// D_cam(φ) = Z2 + χ² − (Z2+1)χ cos φ [–].
    pub d_cam: f64,
    /// D_crown(φ) = Z2 − χ² − (Z2−1)χ cos φ [–].
    pub d_crown: f64,
    /// Signed cam profile curvature κ_cam [1/m].
    pub kappa_cam: f64,
    /// Signed crown profile curvature κ_crown [1/m].
    pub kappa_crown: f64,
    /// Hertz curvature sum at the cam contact K_cam = κ_cam + 1/rb [1/m].
    pub k_cam: f64,
    /// Hertz curvature sum at the crown contact K_crown = κ_crown + 1/rb [1/m].
    pub k_crown: f64,
    /// Cusp margin at the cam, L³ − rb·r2²·D_cam scaled by 1/r2², i.e. r2·s³ − rb·D_cam \[m\]; must be > 0.
    pub margin_cam: f64,
    /// Cusp margin at the crown, r2·s³ − rb·D_crown \[m\]; must be > 0.
    pub margin_crown: f64,
}

impl AnglePoint {
    /// Signed curvature κ_w [1/m].
    #[must_use]
    pub const fn kappa(&self, w: Wheel) -> f64 {
        match w {
            Wheel::Cam => self.kappa_cam,
            Wheel::Crown => self.kappa_crown,
        }
    }

    /// Hertz curvature sum K_w [1/m].
    #[must_use]
    pub const fn curvature_sum(&self, w: Wheel) -> f64 {
        match w {
            Wheel::Cam => self.k_cam,
            Wheel::Crown => self.k_crown,
        }
    }

    /// Lever arm of wheel w, r_w·sin α \[m\].
    #[must_use]
    pub const fn lever_arm(&self, w: Wheel) -> f64 {
        match w {
            Wheel::Cam => self.h_cam,
            Wheel::Crown => self.h_crown,
        }
    }

    /// Signed profile radius ρ_w = 1/κ_w \[m\]; `None` at an inflection (κ = 0, ρ = ∞).
    #[must_use]
    pub fn rho(&self, w: Wheel) -> Option<f64> {
        let r = 1.0 / self.kappa(w);
        r.is_finite().then_some(r)
    }

    /// Cusp margin r2·s³ − rb·D_w \[m\] (> 0 away from a cusp).
    #[must_use]
    pub const fn margin(&self, w: Wheel) -> f64 {
        match w {
            Wheel::Cam => self.margin_cam,
            Wheel::Crown => self.margin_crown,
        }
    }
}

/// The hot-loop subset of [`AnglePoint`] for contact-stress scans.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kernel {
    /// sin α [–].
    pub sin_alpha: f64,
    /// K_cam = κ_cam + 1/rb [1/m].
    pub k_cam: f64,
    /// K_crown [1/m].
    pub k_crown: f64,
    /// min(cusp margins) \[m\]; ≤ 0 means the profile has a cusp at this angle.
    pub margin: f64,
}

/// A feasibility limit broken by a design (the design cannot be built).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Infeasibility {
    /// rb ≥ rb_undercut: the profile of `wheel` has a cusp/loop.
    Undercut {
        /// Wheel whose profile limits rb.
        wheel: Wheel,
        /// rb \[m\].
        rb: f64,
        /// rb_undercut \[m\].
        limit: f64,
    },
    /// rb ≥ χ·r2·sin(π/Z2): adjacent elements touch or overlap.
    ElementOverlap {
        /// rb \[m\].
        rb: f64,
        /// rb_overlap \[m\].
        limit: f64,
    },
}

impl Infeasibility {
    /// Stable code (`UNDERCUT`, `ELEMENT_OVERLAP`).
    #[must_use]
    pub const fn code(&self) -> &'static str {
        match self {
            Self::Undercut { .. } => "UNDERCUT",
            Self::ElementOverlap { .. } => "ELEMENT_OVERLAP",
        }
    }

    /// Human message with value and limit in mm.
    #[must_use]
    pub fn message(&self) -> String {
        match self {
            Self::Undercut { wheel, rb, limit } => format!(
                "rolling element radius rb = {} mm must be < rb_undercut = {} mm ({} profile forms a cusp)",
                rb * 1e3,
                limit * 1e3,
                wheel.name()
            ),
            Self::ElementOverlap { rb, limit } => format!(
                "rolling element radius rb = {} mm must be < rb_overlap = chi*r2*sin(pi/Z2) = {} mm (adjacent elements overlap)",
                rb * 1e3,
                limit * 1e3
            ),
        }
    }

    /// The broken limit \[m\].
    #[must_use]
    pub const fn limit(&self) -> f64 {
        match self {
            Self::Undercut { limit, .. } | Self::ElementOverlap { limit, .. } => *limit,
        }
    }
}

/// A non-fatal geometry warning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeometryWarning {
    /// χ outside the force paper's range [1.25, 1.67].
    ChiOutsidePaperRange,
    /// rb ≤ 2·r2/Z2 (lower bound of force-paper eq. 3).
    RbBelowPaperMin,
    /// rb ≥ r2(χ − 1): LA = L − rb ≤ 0 near φ = 0.
    ContactABeyondPitch,
    /// Sharpest convex profile radius < 0.25·rb.
    NearUndercut,
}

impl GeometryWarning {
    /// Stable code.
    #[must_use]
    pub const fn code(self) -> &'static str {
        match self {
            Self::ChiOutsidePaperRange => "CHI_OUTSIDE_PAPER_RANGE",
            Self::RbBelowPaperMin => "RB_BELOW_PAPER_MIN",
            Self::ContactABeyondPitch => "CONTACT_A_BEYOND_PITCH",
            Self::NearUndercut => "NEAR_UNDERCUT",
        }
    }
}

/// One point of a generated profile (all in the wheel's own frame, wheel centre at the origin) \[m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfilePoint {
    /// Rolling element centre O′.
    pub centre: [f64; 2],
    /// Pitch point P.
    pub pitch: [f64; 2],
    /// Contact point on the profile (A for the cam, B for the crown).
    pub contact: [f64; 2],
}

/// The IREFC gear geometry: the four initial parameters and every derived scalar (spec "Derived scalars").
///
/// Construct with [`Geometry::new_unchecked`] (no range check: the caller validated the inputs) and check
/// buildability with [`Geometry::infeasibilities`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Cage pitch circle radius r2 \[m\].
    pub r2: f64,
    /// Number of rolling elements Z2.
    pub z2: u32,
    /// Displacement coefficient χ (rc = χ·r2) [–].
    pub chi: f64,
    /// Rolling element radius rb \[m\].
    pub rb: f64,
    /// Z2 as f64.
    pub z2f: f64,
    /// Eccentricity of each mesh e = r2/Z2 \[m\] (force paper eq. 5).
    pub e: f64,
    /// Cam centre to crown centre 2e \[m\].
    pub e_total: f64,
    /// Cam pitch radius r1 = r2(1 − 1/Z2) \[m\].
    pub r1: f64,
    /// Crown pitch radius r3 = r2(1 + 1/Z2) \[m\].
    pub r3: f64,
    /// Element-centre circle radius rc = χ·r2 \[m\] (force paper eq. 4).
    pub rc: f64,
    /// Cam lobes Z1 = Z2 − 1.
    pub z1: u32,
    /// Crown lobes Z3 = Z2 + 1.
    pub z3: u32,
    /// Cam tip radius r2(χ + 1/Z2) − rb \[m\] (eq. 8).
    pub cam_tip: f64,
    /// Cam root radius r2(χ − 1/Z2) − rb \[m\] (eq. 9).
    pub cam_root: f64,
    /// Crown tip radius r2(χ − 1/Z2) + rb \[m\] (eq. 10).
    pub crown_tip: f64,
    /// Crown root radius r2(χ + 1/Z2) + rb \[m\] (eq. 11).
    pub crown_root: f64,
    /// Lower bound of force-paper eq. 3, 2·r2/Z2 \[m\].
    pub rb_min_paper: f64,
    /// Element overlap limit χ·r2·sin(π/Z2) \[m\] (upper bound of eq. 3).
    pub rb_overlap: f64,
    /// Smallest positive radius of the element-centre path relative to the cam, min ρt_cam \[m\].
    pub rho_t_min_cam: f64,
    /// Smallest positive ρt_crown \[m\]; `None` when the crown profile is concave everywhere (χ ≥ Z2).
    pub rho_t_min_crown: Option<f64>,
    /// Undercut limit rb_undercut = min(ρt_min_cam, ρt_min_crown) \[m\].
    pub rb_undercut: f64,
}

impl Geometry {
    /// Derived geometry without any range check.
    ///
    /// Requires (not checked) finite r2 > 0, Z2 ≥ 3, 1 < χ, rb > 0; [`super::stress`] and
    /// [`super::efficiency`] validate before calling. Infeasible designs (undercut, overlap) are allowed
    /// here; see [`Self::infeasibilities`].
    #[must_use]
    pub fn new_unchecked(r2: f64, z2: u32, chi: f64, rb: f64) -> Self {
        let z2f = f64::from(z2);
        let e = r2 / z2f;
        let r1 = r2 * (1.0 - 1.0 / z2f);
        let r3 = r2 * (1.0 + 1.0 / z2f);
        let rc = chi * r2;
        let rho_t_min_cam = min_positive_rho_t(r2, z2f, chi, Wheel::Cam);
        let rho_t_min_crown = min_positive_rho_t(r2, z2f, chi, Wheel::Crown);
        // The cam always has ρt_cam(π) = r2(χ+1)²/(χ+Z2) > 0, so its minimum exists.
        let rho_t_min_cam = rho_t_min_cam.unwrap_or(f64::INFINITY);
        let rb_undercut = rho_t_min_crown.map_or(rho_t_min_cam, |c| c.min(rho_t_min_cam));
        Self {
            r2,
            z2,
            chi,
            rb,
            z2f,
            e,
            e_total: 2.0 * e,
            r1,
            r3,
            rc,
            z1: z2.saturating_sub(1),
            z3: z2.saturating_add(1),
            cam_tip: r2.mul_add(chi + 1.0 / z2f, -rb),
            cam_root: r2.mul_add(chi - 1.0 / z2f, -rb),
            crown_tip: r2.mul_add(chi - 1.0 / z2f, rb),
            crown_root: r2.mul_add(chi + 1.0 / z2f, rb),
            rb_min_paper: 2.0 * r2 / z2f,
            rb_overlap: chi * r2 * (PI / z2f).sin(),
            rho_t_min_cam,
            rho_t_min_crown,
            rb_undercut,
        }
    }

    /// Sharpest convex cam profile radius min ρt_cam − rb \[m\] (negative once undercut).
    #[must_use]
    pub fn min_profile_radius_cam(&self) -> f64 {
        self.rho_t_min_cam - self.rb
    }

    /// Sharpest convex crown profile radius \[m\]; `None` if the crown profile is concave everywhere.
    #[must_use]
    pub fn min_profile_radius_crown(&self) -> Option<f64> {
        self.rho_t_min_crown.map(|r| r - self.rb)
    }

    /// Smallest convex profile radius of either wheel \[m\].
    #[must_use]
    pub fn min_profile_radius(&self) -> f64 {
        self.min_profile_radius_crown()
            .map_or(self.min_profile_radius_cam(), |c| {
                c.min(self.min_profile_radius_cam())
            })
    }

    /// Wheel that limits rb_undercut.
    #[must_use]
    pub fn undercut_wheel(&self) -> Wheel {
        match self.rho_t_min_crown {
            Some(c) if c < self.rho_t_min_cam => Wheel::Crown,
            _ => Wheel::Cam,
        }
    }

    /// Overall ratio, carrier input, crown fixed, cam output: (Z2 − 1)/2 (output turns opposite to input).
    #[must_use]
    pub fn ratio_cam_output(&self) -> f64 {
        (self.z2f - 1.0) / 2.0
    }

    /// Overall ratio, carrier input, cam rotation locked, crown output: (Z2 + 1)/2 (same direction).
    #[must_use]
    pub fn ratio_crown_output(&self) -> f64 {
        (self.z2f + 1.0) / 2.0
    }

    /// Broken buildability limits (undercut first, then overlap); empty when the design can be built.
    #[must_use]
    pub fn infeasibilities(&self) -> Vec<Infeasibility> {
        let mut out = Vec::new();
        if self.rb >= self.rb_undercut || !self.rb_undercut.is_finite() {
            out.push(Infeasibility::Undercut {
                wheel: self.undercut_wheel(),
                rb: self.rb,
                limit: self.rb_undercut,
            });
        }
        if self.rb >= self.rb_overlap {
            out.push(Infeasibility::ElementOverlap {
                rb: self.rb,
                limit: self.rb_overlap,
            });
        }
        out
    }

    /// Non-fatal warnings of the geometry (spec "Warnings").
    #[must_use]
    pub fn warnings(&self) -> Vec<GeometryWarning> {
        let mut w = Vec::new();
        if !(CHI_PAPER_MIN..=CHI_PAPER_MAX).contains(&self.chi) {
            w.push(GeometryWarning::ChiOutsidePaperRange);
        }
        if self.rb <= self.rb_min_paper {
            w.push(GeometryWarning::RbBelowPaperMin);
        }
        if self.rb >= self.r2 * (self.chi - 1.0) {
            w.push(GeometryWarning::ContactABeyondPitch);
        }
        if self.min_profile_radius() < NEAR_UNDERCUT_FRACTION * self.rb {
            w.push(GeometryWarning::NearUndercut);
        }
        w
    }

    /// s² = 1 + χ² − 2χ cos φ, computed as (χ−1)² + 4χ·sin²(φ/2) (no cancellation near φ = 0, χ ≈ 1).
    #[inline]
    #[must_use]
    pub fn s2(&self, t: &Trig) -> f64 {
        let cm1 = self.chi - 1.0;
        (4.0 * self.chi).mul_add(t.half_sin2, cm1 * cm1)
    }

    /// D_cam(φ) = Z2 + χ² − (Z2+1)·χ·cos φ.
    #[inline]
    #[must_use]
    pub fn d_cam(&self, t: &Trig) -> f64 {
        (-(self.z2f + 1.0) * self.chi).mul_add(t.cos, self.chi.mul_add(self.chi, self.z2f))
    }

    /// D_crown(φ) = Z2 − χ² − (Z2−1)·χ·cos φ.
    #[inline]
    #[must_use]
    pub fn d_crown(&self, t: &Trig) -> f64 {
        (-(self.z2f - 1.0) * self.chi).mul_add(t.cos, (-self.chi).mul_add(self.chi, self.z2f))
    }

    /// D_w(φ).
    #[inline]
    #[must_use]
    pub fn d(&self, w: Wheel, t: &Trig) -> f64 {
        match w {
            Wheel::Cam => self.d_cam(t),
            Wheel::Crown => self.d_crown(t),
        }
    }

    /// sin α from precomputed trig values.
    #[inline]
    #[must_use]
    pub fn sin_alpha(&self, t: &Trig) -> f64 {
        self.chi * t.sin / self.s2(t).sqrt()
    }

    /// sin²α = χ² sin²φ / s².
    #[inline]
    #[must_use]
    pub fn sin2_alpha(&self, t: &Trig) -> f64 {
        let cs = self.chi * t.sin;
        cs * cs / self.s2(t)
    }

    /// Hot-loop quantities at φ: sin α, both Hertz curvature sums and the smaller cusp margin.
    ///
    /// K_w = κ_w + 1/rb is evaluated as r2·s³ / (rb·(r2·s³ − rb·D_w)), algebraically identical and free of
    /// cancellation; it is positive whenever the cusp margin r2·s³ − rb·D_w is.
    #[inline]
    #[must_use]
    pub fn kernel(&self, t: &Trig) -> Kernel {
        let s2 = self.s2(t);
        let s = s2.sqrt();
        let r2s3 = self.r2 * s2 * s;
        let m_cam = (-self.rb).mul_add(self.d_cam(t), r2s3);
        let m_crown = (-self.rb).mul_add(self.d_crown(t), r2s3);
        let q = r2s3 / self.rb;
        Kernel {
            sin_alpha: self.chi * t.sin / s,
            k_cam: q / m_cam,
            k_crown: q / m_crown,
            margin: m_cam.min(m_crown),
        }
    }

    /// All per-angle quantities at φ \[rad\] (spec "Per-angle functions").
    #[must_use]
    pub fn at(&self, phi: f64) -> AnglePoint {
        let t = Trig::of(phi);
        let s2 = self.s2(&t);
        let s = s2.sqrt();
        let l = self.r2 * s;
        let sin_alpha = self.chi * t.sin / s;
        // 1 − χ cos φ = (1 − χ) + 2χ sin²(φ/2)
        let num_cos = (2.0 * self.chi).mul_add(t.half_sin2, 1.0 - self.chi);
        let cos_alpha = num_cos / s;
        let alpha = (self.chi * t.sin).atan2(num_cos);
        let d_cam = self.d_cam(&t);
        let d_crown = self.d_crown(&t);
        let r2s3 = self.r2 * s2 * s;
        let margin_cam = (-self.rb).mul_add(d_cam, r2s3);
        let margin_crown = (-self.rb).mul_add(d_crown, r2s3);
        let q = r2s3 / self.rb;
        AnglePoint {
            phi,
            s,
            l,
            sin_alpha,
            cos_alpha,
            alpha,
            h_cam: self.r1 * sin_alpha,
            h_crown: self.r3 * sin_alpha,
            la: l - self.rb,
            lb: l + self.rb,
            d_cam,
            d_crown,
            kappa_cam: d_cam / margin_cam,
            kappa_crown: d_crown / margin_crown,
            k_cam: q / margin_cam,
            k_crown: q / margin_crown,
            margin_cam,
            margin_crown,
        }
    }

    /// Pitch point to element centre distance L(φ) = r2·s(φ) \[m\].
    #[must_use]
    pub fn l(&self, phi: f64) -> f64 {
        self.r2 * self.s2(&Trig::of(phi)).sqrt()
    }

    /// Signed radius of curvature of the element-centre path relative to wheel w, ρt_w = L³/(r2²·D_w) \[m\]
    /// (infinite where D_w = 0).
    #[must_use]
    pub fn rho_t(&self, w: Wheel, phi: f64) -> f64 {
        let t = Trig::of(phi);
        let s2 = self.s2(&t);
        self.r2 * s2 * s2.sqrt() / self.d(w, &t)
    }

    /// Element angles of the loaded set for cage phase fraction `p` ∈ [0, 1) (phase angle p·2π/Z2):
    /// pairs (k, φ_k) with φ_k = 2π(p + k)/Z2 ∈ [0, π]; the last one is exactly π when p + k = Z2/2.
    pub fn loaded_elements(&self, p: f64) -> impl Iterator<Item = (u32, f64)> + '_ {
        let half = 0.5 * self.z2f;
        (0..=self.z2 / 2).map_while(move |k| {
            let pos = p + f64::from(k);
            if pos > half {
                None
            } else {
                let phi = if 2.0 * pos >= self.z2f {
                    PI
                } else {
                    TAU * pos / self.z2f
                };
                Some((k, phi))
            }
        })
    }

    /// Σ sin²α over the loaded elements at cage phase fraction p ∈ [0, 1) (spec "Load sharing set").
    #[must_use]
    pub fn sum_sin2(&self, p: f64) -> f64 {
        self.loaded_elements(p)
            .map(|(_, phi)| self.sin2_alpha(&Trig::of(phi)))
            .sum()
    }

    /// Cage phase fraction p ∈ [0, 1) that puts an element at φ (the phase-exact load sharing).
    #[must_use]
    pub fn phase_fraction_at(&self, phi: f64) -> f64 {
        let x = phi * self.z2f / TAU;
        let p = x - x.floor();
        if (0.0..1.0).contains(&p) { p } else { 0.0 }
    }

    /// One profile point of wheel w at curve parameter t \[rad\] (spec "profile point sets"), in the wheel's
    /// frame \[m\].
    #[must_use]
    pub fn profile_point(&self, w: Wheel, t: f64) -> ProfilePoint {
        let zt = self.z2f * t;
        let (st, ct) = t.sin_cos();
        match w {
            Wheel::Cam => {
                let (sz, cz) = zt.sin_cos();
                let centre = [
                    self.e.mul_add(cz, -self.rc * ct),
                    self.e.mul_add(sz, -self.rc * st),
                ];
                let pitch = [-self.r1 * cz, -self.r1 * sz];
                let contact = offset(centre, pitch, -self.rb);
                ProfilePoint {
                    centre,
                    pitch,
                    contact,
                }
            }
            Wheel::Crown => {
                let (sz, cz) = (-zt).sin_cos();
                let centre = [
                    self.e.mul_add(cz, self.rc * ct),
                    self.e.mul_add(sz, self.rc * st),
                ];
                let pitch = [self.r3 * cz, self.r3 * sz];
                let contact = offset(centre, pitch, self.rb);
                ProfilePoint {
                    centre,
                    pitch,
                    contact,
                }
            }
        }
    }

    /// `n` profile points of wheel w at t = 2πi/n, i = 0..n−1 \[m\].
    #[must_use]
    pub fn profile(&self, w: Wheel, n: usize) -> Vec<[f64; 2]> {
        // n ≤ PROFILE_POINTS_MAX (validated), so the usize → f64 conversions are exact.
        let nf = n as f64;
        (0..n)
            .map(|i| {
                let t = TAU * (i as f64) / nf;
                self.profile_point(w, t).contact
            })
            .collect()
    }
}

/// `centre + d·(centre − pitch)/|centre − pitch|`.
fn offset(centre: [f64; 2], pitch: [f64; 2], d: f64) -> [f64; 2] {
    let dx = centre[0] - pitch[0];
    let dy = centre[1] - pitch[1];
    let n = dx.hypot(dy);
    [d.mul_add(dx / n, centre[0]), d.mul_add(dy / n, centre[1])]
}

/// ρt_w as a function of c = cos φ: r2·(1 + χ² − 2χc)^{3/2} / D_w(c).
// Written as in the spec for traceability; evaluated three times per geometry, not in a hot loop.
fn rho_t_of_cos(r2: f64, z2: f64, chi: f64, w: Wheel, c: f64) -> f64 {
    let q = (1.0 + chi * chi - 2.0 * chi * c).max(0.0);
    let d = match w {
        Wheel::Cam => (z2 + chi * chi) - (z2 + 1.0) * chi * c,
        Wheel::Crown => (z2 - chi * chi) - (z2 - 1.0) * chi * c,
    };
    r2 * q * q.sqrt() / d
}

/// Smallest positive ρt_w over φ ∈ [0, π] in closed form (spec "Undercut limit").
///
/// ρt_w(c) has exactly one stationary point c* on its D_w > 0 interval, a minimum, and tends to +∞ where
/// D_w → 0⁺; so the minimum over the positive part is the least of the values at c = ±1 (where D_w > 0) and
/// at c* (when it lies in [−1, 1] with D_w(c*) > 0). The spec lists c = −1 and c*; c = 1 also counts when
/// χ > Z2 (then the cam root is convex). `None` if ρt_w ≤ 0 everywhere.
// Written as in the spec for traceability (closed forms of c*); not in a hot loop.
fn min_positive_rho_t(r2: f64, z2: f64, chi: f64, w: Wheel) -> Option<f64> {
    let c_star = match w {
        Wheel::Cam => (2.0 * z2 - 1.0 - (z2 - 2.0) * chi * chi) / ((z2 + 1.0) * chi),
        Wheel::Crown => (2.0 * z2 + 1.0 - (z2 + 2.0) * chi * chi) / ((z2 - 1.0) * chi),
    };
    let mut best: Option<f64> = None;
    let mut consider = |c: f64| {
        let v = rho_t_of_cos(r2, z2, chi, w, c);
        if v > 0.0 && v.is_finite() {
            best = Some(best.map_or(v, |b| b.min(v)));
        }
    };
    consider(-1.0);
    consider(1.0);
    if (-1.0..=1.0).contains(&c_star) {
        consider(c_star);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trig_exact_at_ends() {
        let t = Trig::of(PI);
        assert!(t.sin.abs() < f64::MIN_POSITIVE);
        assert!((t.cos + 1.0).abs() < f64::MIN_POSITIVE);
        let t0 = Trig::of(0.0);
        assert!(t0.sin.abs() < f64::MIN_POSITIVE && t0.half_sin2.abs() < f64::MIN_POSITIVE);
        for phi in [-3.0, -1.0, 0.3, 1.7, 2.9, 4.0, 7.5] {
            let t = Trig::of(phi);
            assert!((t.sin - phi.sin()).abs() < 1e-15, "{phi}");
            assert!((t.cos - phi.cos()).abs() < 1e-15, "{phi}");
            assert!(
                (t.half_sin2 - (1.0 - phi.cos()) / 2.0).abs() < 1e-15,
                "{phi}"
            );
        }
    }

    #[test]
    fn loaded_set_phase_zero() {
        let g = Geometry::new_unchecked(0.02, 26, 1.4, 0.002);
        let v: Vec<_> = g.loaded_elements(0.0).collect();
        assert_eq!(v.len(), 14);
        assert!((v[13].1 - PI).abs() < f64::MIN_POSITIVE);
        let g7 = Geometry::new_unchecked(0.02, 7, 1.4, 0.002);
        assert_eq!(g7.loaded_elements(0.0).count(), 4);
        assert_eq!(g7.loaded_elements(0.5).count(), 4);
        assert_eq!(g7.loaded_elements(0.6).count(), 3);
    }
}
