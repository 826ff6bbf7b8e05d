//! One rod: the nondimensional planar Kirchhoff (optionally extensible) rod ODE integrated by
//! classical fixed-step RK4 together with its exact sensitivities (spec 4.1, paper eq. 8).
//!
//! Nondimensional variables: `sb = s/L`, `xb = x/L`, `mb = m L/EI`, `nb = n L^2/EI`. State
//! `z = (xb, yb, th, mb)`, unknowns `q = (mb0, nbx, nby)`, sensitivity `S = dz/dq` (4x3). The
//! sensitivities are integrated with the same RK4 stages as the state, so `S(1)` is the exact
//! derivative of the discrete map and Newton converges quadratically.

#![expect(
    clippy::excessive_precision,
    reason = "the fdlibm sine/cosine constants are kept digit for digit as published"
)]

/// Rod constants that enter the ODE.
#[derive(Debug, Clone, Copy)]
pub struct RodOde {
    /// Clamp angle `theta_c` \[rad\]: tangent direction at `s = 0`.
    pub theta_c: f64,
    /// Axial compliance `ca = EI/(EA L^2)` (0 for the paper's inextensible Kirchhoff rod).
    pub ca: f64,
}

/// State and sensitivities at the end of the rod.
#[derive(Debug, Clone, Copy, Default)]
pub struct RodEnd {
    /// `(xb, yb, th, mb)` at `sb = 1`.
    pub z: [f64; 4],
    /// `dz/dq` at `sb = 1`, rows `xb, yb, th, mb`, columns `mb0, nbx, nby`.
    pub s: [[f64; 3]; 4],
}

/// Hard cap on RK4 steps for one rod (the step rule of 4.1 grows with the load; a diverging Newton
/// iterate must not cost unbounded time: 65 536 steps keep `h sqrt|nb|` below 0.1 up to |nb| ~ 4e7).
pub const MAX_STEPS: usize = 65_536;

/// Arguments beyond this use `f64::sin_cos` (the two-part Cody-Waite reduction below is exact
/// to ~1 ulp for `|k| < 2^20`, i.e. `|x| < 1.6e6`; 1e5 leaves a wide margin).
const FAST_TRIG_RANGE: f64 = 1.0e5;
/// Rounds to the nearest integer by the 1.5 * 2^52 trick (valid for |v| < 2^51).
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;
/// First 33 bits of pi/2 (so `k * PIO2_1` is exact for |k| < 2^20).
const PIO2_1: f64 = 1.570_796_326_734_125_614_17;
/// `pi/2 - PIO2_1`.
const PIO2_1T: f64 = 6.077_100_506_506_192_249_32e-11;
// fdlibm kernel coefficients on [-pi/4, pi/4] (error < 1 ulp).
const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;
const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `(sin x, cos x)` inlined: the RK4 stages evaluate 4 of these per step and glibc's `sincos`
/// call dominated the FK cost (half of all time in sweeps). Accurate to ~2 ulp.
#[inline(always)]
#[must_use]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.is_nan() || x.abs() >= FAST_TRIG_RANGE {
        return x.sin_cos();
    }
    let k = (x * std::f64::consts::FRAC_2_PI + ROUND_MAGIC) - ROUND_MAGIC;
    let r = (x - k * PIO2_1) - k * PIO2_1T;
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let c = 1.0 - 0.5 * z + z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    // |k| < 1e5 * 2/pi: the cast is exact.
    match (k as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Number of RK4 steps the rule of spec 4.1 asks for at `q`:
/// `base * max(1, sqrt(max(|nb|, mb0^2) / 4))` (RK4 error scales as `(h sqrt|nb|)^4`).
#[must_use]
pub fn steps_for(base: usize, q: &[f64; 3]) -> usize {
    let nb = q[1].hypot(q[2]);
    let load = nb.max(q[0] * q[0]);
    let factor = (load / 4.0).sqrt().max(1.0);
    let want = (base as f64) * factor;
    if want.is_finite() && want < MAX_STEPS as f64 {
        // Provably in range: 0 < want < MAX_STEPS.
        (want.ceil() as usize).max(base)
    } else {
        MAX_STEPS.max(base)
    }
}

#[inline]
fn deriv_state(z: &[f64; 4], nbx: f64, nby: f64, ca: f64) -> [f64; 4] {
    let (s, c) = sin_cos(z[2]);
    let e = ca * (nbx * c + nby * s) + 1.0;
    let w = nbx * s - nby * c;
    [e * c, e * s, z[3], e * w]
}

#[inline]
fn deriv_full(
    z: &[f64; 4],
    sm: &[[f64; 3]; 4],
    nbx: f64,
    nby: f64,
    ca: f64,
) -> ([f64; 4], [[f64; 3]; 4]) {
    let (s, c) = sin_cos(z[2]);
    let e = ca * (nbx * c + nby * s) + 1.0;
    let w = nbx * s - nby * c;
    let et = -ca * w;
    let dz = [e * c, e * s, z[3], e * w];
    let a02 = et * c - e * s;
    let a12 = et * s + e * c;
    let a32 = et * w + e * (nbx * c + nby * s);
    let b0 = [0.0, ca * c * c, ca * s * c];
    let b1 = [0.0, ca * c * s, ca * s * s];
    let b3 = [0.0, ca * c * w + e * s, ca * s * w - e * c];
    let mut ds = [[0.0; 3]; 4];
    for k in 0..3 {
        let s2 = sm[2][k];
        ds[0][k] = a02 * s2 + b0[k];
        ds[1][k] = a12 * s2 + b1[k];
        ds[2][k] = sm[3][k];
        ds[3][k] = a32 * s2 + b3[k];
    }
    (dz, ds)
}

#[inline]
fn axpy4(z: &[f64; 4], a: f64, d: &[f64; 4]) -> [f64; 4] {
    [
        z[0] + a * d[0],
        z[1] + a * d[1],
        z[2] + a * d[2],
        z[3] + a * d[3],
    ]
}

#[inline]
fn axpy43(z: &[[f64; 3]; 4], a: f64, d: &[[f64; 3]; 4]) -> [[f64; 3]; 4] {
    let mut r = *z;
    for (ri, di) in r.iter_mut().zip(d) {
        for (x, y) in ri.iter_mut().zip(di) {
            *x += a * *y;
        }
    }
    r
}

/// Initial state for unknowns `q`.
#[inline]
fn initial(ode: &RodOde, q: &[f64; 3]) -> [f64; 4] {
    [0.0, 0.0, ode.theta_c, q[0]]
}

/// One classical RK4 step of the state only.
#[inline]
fn step_state(z: &[f64; 4], h: f64, nbx: f64, nby: f64, ca: f64) -> [f64; 4] {
    let k1 = deriv_state(z, nbx, nby, ca);
    let k2 = deriv_state(&axpy4(z, 0.5 * h, &k1), nbx, nby, ca);
    let k3 = deriv_state(&axpy4(z, 0.5 * h, &k2), nbx, nby, ca);
    let k4 = deriv_state(&axpy4(z, h, &k3), nbx, nby, ca);
    let mut out = *z;
    for i in 0..4 {
        out[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
    }
    out
}

/// Integrate the state and its sensitivities over `sb in [0, 1]` with `steps` RK4 steps.
#[must_use]
pub fn shoot(ode: &RodOde, q: &[f64; 3], steps: usize) -> RodEnd {
    let (nbx, nby, ca) = (q[1], q[2], ode.ca);
    let n = steps.max(1);
    let h = 1.0 / n as f64;
    let mut z = initial(ode, q);
    let mut sm = [[0.0; 3]; 4];
    sm[3][0] = 1.0;
    for _ in 0..n {
        let (k1, l1) = deriv_full(&z, &sm, nbx, nby, ca);
        let (k2, l2) = deriv_full(
            &axpy4(&z, 0.5 * h, &k1),
            &axpy43(&sm, 0.5 * h, &l1),
            nbx,
            nby,
            ca,
        );
        let (k3, l3) = deriv_full(
            &axpy4(&z, 0.5 * h, &k2),
            &axpy43(&sm, 0.5 * h, &l2),
            nbx,
            nby,
            ca,
        );
        let (k4, l4) = deriv_full(&axpy4(&z, h, &k3), &axpy43(&sm, h, &l3), nbx, nby, ca);
        for i in 0..4 {
            z[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
            for k in 0..3 {
                sm[i][k] += h / 6.0 * (l1[i][k] + 2.0 * (l2[i][k] + l3[i][k]) + l4[i][k]);
            }
        }
    }
    RodEnd { z, s: sm }
}

/// Integrate the state only (no sensitivities) and return the end state.
#[must_use]
pub fn shoot_plain(ode: &RodOde, q: &[f64; 3], steps: usize) -> [f64; 4] {
    let n = steps.max(1);
    let h = 1.0 / n as f64;
    let mut z = initial(ode, q);
    for _ in 0..n {
        z = step_state(&z, h, q[1], q[2], ode.ca);
    }
    z
}

/// The RK4 node values of one rod (for shapes, stresses, energies and the stability test).
#[derive(Debug, Clone)]
pub struct RodTrace {
    /// `steps + 1` states `(xb, yb, th, mb)` at `sb = k/steps`.
    pub nodes: Vec<[f64; 4]>,
    /// Nondimensional force `(nbx, nby)`.
    pub nb: [f64; 2],
    /// Axial compliance used.
    pub ca: f64,
    /// Nondimensional bending energy `int_0^1 mb^2/2 dsb` (Simpson on the RK4 nodes with
    /// Hermite mid-points; physical energy = value * EI / L).
    pub bending_energy: f64,
}

/// Integrate and keep every RK4 node.
#[must_use]
pub fn trace(ode: &RodOde, q: &[f64; 3], steps: usize) -> RodTrace {
    let n = steps.max(1);
    let h = 1.0 / n as f64;
    let mut z = initial(ode, q);
    let mut nodes = Vec::with_capacity(n + 1);
    nodes.push(z);
    for _ in 0..n {
        z = step_state(&z, h, q[1], q[2], ode.ca);
        nodes.push(z);
    }
    let mut t = RodTrace {
        nodes,
        nb: [q[1], q[2]],
        ca: ode.ca,
        bending_energy: 0.0,
    };
    // Simpson per step: mb at the step mid-point from the cubic Hermite interpolant
    // (fourth-order accurate, like the RK4 nodes themselves).
    let mut energy = 0.0;
    for k in 0..n {
        let m0 = t.nodes[k][3];
        let m1 = t.nodes[k + 1][3];
        let mm = t.eval(k, 0.5)[3];
        energy += h / 6.0 * (m0 * m0 + 4.0 * mm * mm + m1 * m1) * 0.5;
    }
    t.bending_energy = energy;
    t
}

impl RodTrace {
    /// Number of RK4 steps.
    #[must_use]
    pub fn steps(&self) -> usize {
        self.nodes.len().saturating_sub(1)
    }

    /// ODE right-hand side at a node state.
    fn rhs(&self, z: &[f64; 4]) -> [f64; 4] {
        deriv_state(z, self.nb[0], self.nb[1], self.ca)
    }

    /// Cubic Hermite interpolation inside step `k` at local fraction `u in [0, 1]`.
    fn eval(&self, k: usize, u: f64) -> [f64; 4] {
        let n = self.steps().max(1);
        let h = 1.0 / n as f64;
        let z0 = self.nodes[k];
        let z1 = self.nodes[(k + 1).min(self.nodes.len() - 1)];
        let d0 = self.rhs(&z0);
        let d1 = self.rhs(&z1);
        let u2 = u * u;
        let u3 = u2 * u;
        let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
        let h10 = u3 - 2.0 * u2 + u;
        let h01 = -2.0 * u3 + 3.0 * u2;
        let h11 = u3 - u2;
        let mut out = [0.0; 4];
        for i in 0..4 {
            out[i] = h00 * z0[i] + h * h10 * d0[i] + h01 * z1[i] + h * h11 * d1[i];
        }
        out
    }

    /// State at arc-length fraction `sb in [0, 1]` (cubic Hermite between RK4 nodes).
    #[must_use]
    pub fn at(&self, sb: f64) -> [f64; 4] {
        let n = self.steps().max(1);
        let x = sb.clamp(0.0, 1.0) * n as f64;
        let k = (x.floor() as usize).min(n - 1); // x in [0, n]: the cast cannot wrap
        self.eval(k, x - k as f64)
    }

    /// Largest `|mb|` over the RK4 nodes.
    #[must_use]
    pub fn max_abs_mb(&self) -> f64 {
        self.nodes.iter().fold(0.0, |a, z| a.max(z[3].abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_sin_cos_matches_libm() {
        let mut x = -40.0f64;
        while x < 40.0 {
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 4e-16 && (c - x.cos()).abs() < 4e-16,
                "{x}"
            );
            x += 0.000_731;
        }
        let (s, c) = sin_cos(1e7);
        assert!((s - 1e7f64.sin()).abs() < 1e-15 && (c - 1e7f64.cos()).abs() < 1e-15);
    }
}
