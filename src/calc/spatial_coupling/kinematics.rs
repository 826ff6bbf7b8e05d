//! Closed-form kinematics of the RP1PR coupling at one input angle (spec §3.1–3.4, errata §3.6).
//!
//! Everything is written per unit a (lengths) and per unit ω1 (rates); the caller scales. Trig of
//! the input angle comes from its value in degrees ([`sin_cos_deg`]): exact at multiples of 90°,
//! reduced modulo 360° for any finite angle (spec §7.6).

use std::f64::consts::PI;

use crate::numerics::angles::{sin_cos_deg, wrap_2pi, wrap_pi};

/// A vector in ground coordinates.
pub type V3 = [f64; 3];

/// D is "zero to round-off" below this multiple of ε·max(|D(0)|, |D(90°)|): the rounding of D
/// itself and of the input angle's trig (|dD/dθ1| ≤ 2·max|D|) stays below it (spec §7.2).
pub const D_ZERO_ULPS: f64 = 64.0;

/// The coupling's constants (angles, trig, support-plane coefficients).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    /// sin α, cos α.
    pub sa: f64,
    /// cos α.
    pub ca: f64,
    /// sin 2α.
    pub s2a: f64,
    /// cos 2α.
    pub c2a: f64,
    /// sin β.
    pub sb: f64,
    /// cos β.
    pub cb: f64,
    /// D(0) = cos(α − β)·cos 2α.
    pub d0: f64,
    /// D(90°) = cos(α + β).
    pub d90: f64,
    /// cos(α − β).
    pub cm: f64,
    /// cos(α + β).
    pub cp: f64,
    /// Assembly mode σ = ±1.
    pub sigma: f64,
}

/// Core of one point (spec §3.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Core {
    /// sin θ1, cos θ1.
    pub s1: f64,
    /// cos θ1.
    pub c1: f64,
    /// sin θ2, cos θ2 (exact forms σ·(cos2α·c1, s1)/ρ).
    pub s2: f64,
    /// cos θ2.
    pub c2: f64,
    /// ρ = √(s1² + cos²2α·c1²).
    pub rho: f64,
    /// i12 = dθ2/dθ1.
    pub i12: f64,
    /// di12/dθ1 [1/rad].
    pub di12: f64,
}

/// Contact point per unit a and its derivative per unit θ1 (spec §3.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactKin {
    /// r_B / a.
    pub r: V3,
    /// (dr_B/dθ1) / a.
    pub dr: V3,
    /// D(θ1).
    pub d: f64,
}

/// Motion of B relative to one shaft, per unit a and per unit θ1 (spec §3.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelKin {
    /// x of B in the shaft frame / a.
    pub x: f64,
    /// z of B in the shaft frame / a.
    pub z: f64,
    /// dx/dθ1 / a.
    pub dx: f64,
    /// dz/dθ1 / a.
    pub dz: f64,
    /// Relative rotation of body 3 \[rad\], wrapped to (−π, π].
    pub theta: f64,
    /// Its rate per unit ω1.
    pub omega: f64,
}

/// The unit vectors of frames 1, 2, 3 in ground coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameKin {
    /// i1, j1, k1.
    pub f1: [V3; 3],
    /// i2, j2, k2.
    pub f2: [V3; 3],
    /// i3, j3, k3.
    pub f3: [V3; 3],
}

/// Dot product.
#[must_use]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
#[must_use]
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean norm.
#[must_use]
pub fn norm(a: V3) -> f64 {
    a[0].hypot(a[1]).hypot(a[2])
}

impl Coupling {
    /// The coupling for α, β \[deg\] and assembly mode σ (±1).
    #[must_use]
    pub fn new(alpha_deg: f64, beta_deg: f64, sigma: f64) -> Self {
        let (sa, ca) = sin_cos_deg(alpha_deg);
        let (s2a, c2a) = sin_cos_deg(2.0 * alpha_deg);
        let (sb, cb) = sin_cos_deg(beta_deg);
        let cm = sin_cos_deg(alpha_deg - beta_deg).1;
        let cp = sin_cos_deg(alpha_deg + beta_deg).1;
        Self {
            sa,
            ca,
            s2a,
            c2a,
            sb,
            cb,
            d0: cm * c2a,
            d90: cp,
            cm,
            cp,
            sigma,
        }
    }

    /// Support-plane validity (spec §7.2): B is finite at every θ1 iff D(0)·D(90°) > 0.
    #[must_use]
    pub fn plane_valid(&self) -> bool {
        // Signs, not the product (which can underflow to 0 for tiny valid D(0), D(90°)).
        (self.d0 > 0.0 && self.d90 > 0.0) || (self.d0 < 0.0 && self.d90 < 0.0)
    }

    /// max |D| over a revolution.
    #[must_use]
    pub fn d_max(&self) -> f64 {
        self.d0.abs().max(self.d90.abs())
    }

    /// min|D| / max|D| over a revolution (D is a convex combination of D(0) and D(90°)).
    #[must_use]
    pub fn d_min_over_max(&self) -> f64 {
        let max = self.d_max();
        if !self.plane_valid() || max <= 0.0 {
            0.0
        } else {
            self.d0.abs().min(self.d90.abs()) / max
        }
    }

    /// Input angles in [0°, 360°) where D = 0 (none for a valid plane).
    #[must_use]
    pub fn d_roots_deg(&self) -> Vec<f64> {
        if self.plane_valid() {
            return Vec::new();
        }
        if self.d0 == 0.0 && self.d90 == 0.0 {
            // D ≡ 0: B is at infinity at every input angle; no isolated root.
            return Vec::new();
        }
        // D0 c1² + D90 s1² = 0 ⇔ tan²θ1 = −D0/D90: θ* = atan2(√|D0|, √|D90|) ∈ [0°, 90°].
        let t = self
            .d0
            .abs()
            .sqrt()
            .atan2(self.d90.abs().sqrt())
            .to_degrees();
        let mut roots = vec![t, 180.0 - t, 180.0 + t, 360.0 - t];
        for r in &mut roots {
            if *r >= 360.0 {
                *r -= 360.0;
            }
        }
        roots.sort_by(f64::total_cmp);
        roots.dedup_by(|a, b| (*a - *b).abs() <= 1e-12);
        roots
    }

    /// Whether |cos 2α| is within 1e-12 of 1 (homokinetic).
    #[must_use]
    pub fn homokinetic(&self) -> bool {
        (1.0 - self.c2a.abs()).abs() < 1e-12
    }

    /// Core at θ1 given in degrees.
    #[must_use]
    #[inline]
    pub fn core(&self, theta1_deg: f64) -> Core {
        let (s1, c1) = sin_cos_deg(theta1_deg);
        self.core_sc(s1, c1)
    }

    /// Core from sin θ1, cos θ1 (spec §3.2, with the cancellation-free denominator). θ2 itself
    /// is [`Coupling::theta2`] (an `atan2` that sweeps need only at the points they keep).
    #[must_use]
    #[inline]
    pub fn core_sc(&self, s1: f64, c1: f64) -> Core {
        let c = self.c2a;
        let den = s1 * s1 + c * c * c1 * c1;
        let rho = den.sqrt();
        let (y, x) = (self.sigma * c * c1, self.sigma * s1);
        let (s2, c2) = (y / rho, x / rho);
        let i12 = -c / den;
        let di12 = c * self.s2a * self.s2a * (2.0 * s1 * c1) / (den * den);
        Core {
            s1,
            c1,
            s2,
            c2,
            rho,
            i12,
            di12,
        }
    }

    /// θ2 = atan2(σ cos2α c1, σ s1) \[rad\], wrapped to [0, 2π).
    #[must_use]
    pub fn theta2(&self, core: &Core) -> f64 {
        let (y, x) = (self.sigma * self.c2a * core.c1, self.sigma * core.s1);
        wrap_2pi(y.atan2(x))
    }

    /// D(θ1).
    #[must_use]
    #[inline]
    pub fn d(&self, s1: f64, c1: f64) -> f64 {
        self.d0 * c1 * c1 + self.d90 * s1 * s1
    }

    /// Whether D is zero to round-off at this θ1 (B at infinity, spec §7.2).
    #[must_use]
    #[inline]
    pub fn d_is_zero(&self, d: f64) -> bool {
        d.abs() <= D_ZERO_ULPS * f64::EPSILON * self.d_max()
    }

    /// Contact point per unit a (branch-free closed form of spec §3.3), or `None` where D is zero
    /// to round-off.
    #[must_use]
    #[inline]
    pub fn contact(&self, s1: f64, c1: f64) -> Option<ContactKin> {
        let d = self.d(s1, c1);
        if self.d_is_zero(d) {
            return None;
        }
        let c = self.c2a;
        let (s2t, c2t) = (2.0 * s1 * c1, c1 * c1 - s1 * s1);
        let cmc = self.cm * c;
        let n = [
            cmc * c1 * c1 - self.cp * s1 * s1,
            c * s2t * self.sb,
            c * s2t * self.cb,
        ];
        let np = [
            -(cmc + self.cp) * s2t,
            2.0 * c * c2t * self.sb,
            2.0 * c * c2t * self.cb,
        ];
        let dp = (self.cp - cmc) * s2t;
        let r = [-n[0] / d, -n[1] / d, -n[2] / d];
        let dr = [
            -(np[0] * d - n[0] * dp) / (d * d),
            -(np[1] * d - n[1] * dp) / (d * d),
            -(np[2] * d - n[2] * dp) / (d * d),
        ];
        Some(ContactKin { r, dr, d })
    }

    /// Frames 1, 2, 3 (spec §3.1 with erratum 5).
    #[must_use]
    pub fn frames(&self, core: &Core) -> FrameKin {
        let (sa, ca) = (self.sa, self.ca);
        let (s1, c1, s2, c2) = (core.s1, core.c1, core.s2, core.c2);
        let i1 = [c1, sa * s1, ca * s1];
        let j1 = [-s1, sa * c1, ca * c1];
        let k1 = [0.0, -ca, sa];
        let i2 = [c2, sa * s2, -ca * s2];
        let j2 = [-s2, sa * c2, -ca * c2];
        let k2 = [0.0, ca, sa];
        FrameKin {
            f1: [i1, j1, k1],
            f2: [i2, j2, k2],
            f3: [j1, j2, cross(j1, j2)],
        }
    }

    /// Motion relative to shaft 1 (spec §3.4): frame-rotation terms vanish because
    /// (rB − A1)·j1 = 0, so d/dθ1 of (rB − A1)·i1 is (drB/dθ1)·i1.
    #[must_use]
    #[inline]
    pub fn relative_1(&self, core: &Core, b: &ContactKin) -> RelKin {
        let (sa, ca, s1, c1) = (self.sa, self.ca, core.s1, core.c1);
        let i1 = [c1, sa * s1, ca * s1];
        let k1 = [0.0, -ca, sa];
        let p = [b.r[0] - 1.0, b.r[1], b.r[2]];
        let den = core.rho * core.rho;
        RelKin {
            x: dot(p, i1),
            z: dot(p, k1),
            dx: dot(b.dr, i1),
            dz: dot(b.dr, k1),
            // θ31 = atan2(k3·i1, k3·k1) = atan2(−σ sin2α s1, σ cos2α) (exact reduction).
            theta: (-self.sigma * self.s2a * s1).atan2(self.sigma * self.c2a),
            omega: -self.s2a * self.c2a * c1 / den,
        }
    }

    /// Motion relative to shaft 2 (spec §3.4).
    #[must_use]
    #[inline]
    pub fn relative_2(&self, core: &Core, b: &ContactKin) -> RelKin {
        let (sa, ca, s2, c2) = (self.sa, self.ca, core.s2, core.c2);
        let i2 = [c2, sa * s2, -ca * s2];
        let k2 = [0.0, ca, sa];
        let p = [b.r[0] + 1.0, b.r[1], b.r[2]];
        RelKin {
            x: dot(p, i2),
            z: dot(p, k2),
            dx: dot(b.dr, i2),
            dz: dot(b.dr, k2),
            // θ32 = atan2(k3·i2, k3·k2) = atan2(−sin2α c1, −σρ) (exact reduction).
            theta: (-self.s2a * core.c1).atan2(-self.sigma * core.rho),
            // dθ32/dθ1 of the angle above: −σ sin2α s1/ρ. The spec's §3.4 prints it without σ
            // ("ω32 does not depend on σ"): true of the vector ω32·j2 (j2 flips with σ), not of the
            // signed rate about j2 that goes with θ32.
            omega: -self.sigma * self.s2a * core.s1 / core.rho,
        }
    }

    /// Centre of the oscillation of θ31 (0 or π): its value at θ1 = 0.
    #[must_use]
    pub fn theta31_centre(&self) -> f64 {
        if self.sigma * self.c2a > 0.0 { 0.0 } else { PI }
    }

    /// Centre of the oscillation of θ32 (π for σ = +1, 0 for σ = −1): its value at θ1 = 90°.
    #[must_use]
    pub fn theta32_centre(&self) -> f64 {
        if self.sigma > 0.0 { PI } else { 0.0 }
    }

    /// θ2 \[deg\] continuous in θ1 \[deg\] over any number of revolutions (spec §3.5, §7.6): the
    /// output turns once per input revolution, in the −z2 sense for |α| < 45°.
    #[must_use]
    pub fn theta2_continuous_deg(&self, theta1_deg: f64, core: &Core) -> f64 {
        let k = (theta1_deg / 360.0).floor();
        // ψ = atan2(s1, |c| c1) lies in the quadrant of θ1: wrapped to [0, 2π) it is continuous
        // over each revolution [360k, 360(k + 1)).
        let psi = 360.0 * k + wrap_2pi(core.s1.atan2(self.c2a.abs() * core.c1)).to_degrees();
        let base = if self.c2a > 0.0 {
            90.0 - psi
        } else {
            psi - 90.0
        };
        if self.sigma > 0.0 { base } else { base + 180.0 }
    }
}

/// An oscillating angle \[rad\] placed continuously about its centre: exact because the swing
/// about the centre is at most 90° (2|α| or 180° − 2|α|).
#[must_use]
pub fn about_centre(theta: f64, centre: f64) -> f64 {
    centre + wrap_pi(theta - centre)
}
