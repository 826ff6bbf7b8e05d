//! Closed form of one clamped-pinned elastica (spec 4.4, paper eqs. 12-15) with the branch fix of
//! spec 4.9-1: `(psi - theta1)` is reduced to `[0, 2 pi)` before halving.
//!
//! Used only by the assembly-mode search (4.6) and by tests; the parametrisation is singular for an
//! unloaded straight rod (`R -> 0`) and for `|k| -> 1`, so FK never uses it.

use std::f64::consts::{PI, TAU};

use crate::numerics::elliptic::{ellip_e_inc, ellip_f};

/// One closed-form rod solution (relative to the clamp point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastica {
    /// Tip position relative to the base `(x(phi2), y(phi2))` \[m\].
    pub tip: [f64; 2],
    /// Rod force `n = R (cos psi, sin psi)` \[N\] (force of the tip support on the rod).
    pub force: [f64; 2],
    /// Base moment `m(phi1)` [N m].
    pub base_moment: f64,
    /// Tip moment `m(phi2)` [N m] (zero up to round-off: pinned tip).
    pub tip_moment: f64,
    /// Load magnitude `R` \[N\].
    pub load: f64,
}

/// `c = cos(mod(psi - theta1, 2 pi) / 2)` (spec 4.4 with the required reduction).
#[must_use]
pub fn c_of(psi: f64, theta1: f64) -> f64 {
    ((psi - theta1).rem_euclid(TAU) / 2.0).cos()
}

/// The rod of stiffness `ei` and length `len` clamped at slope `theta1`, loaded at the tip in
/// direction `psi` with modulus `k` and buckling mode `q >= 1`; `None` if not admissible
/// (`|c| > |k|`, `k = 0`, `|k| >= 1`, or `F(phi2) <= F(phi1)`).
#[must_use]
pub fn elastica(ei: f64, len: f64, theta1: f64, psi: f64, k: f64, q: u32) -> Option<Elastica> {
    let c = c_of(psi, theta1);
    if k == 0.0 || k.is_nan() || k.abs() >= 1.0 || c.abs() > k.abs() || q == 0 {
        return None;
    }
    let m = k * k;
    let phi1 = (c / k).clamp(-1.0, 1.0).asin();
    let phi2 = (f64::from(q) - 0.5) * PI;
    let f1 = ellip_f(phi1, m);
    let f2 = ellip_f(phi2, m);
    if f2.is_nan() || f1.is_nan() || f2 <= f1 {
        return None;
    }
    let e1 = ellip_e_inc(phi1, m);
    let e2 = ellip_e_inc(phi2, m);
    let load = ei * (f2 - f1) * (f2 - f1) / (len * len);
    let lam = (ei / load).sqrt();
    let (sp, cp) = psi.sin_cos();
    let a = 2.0f64.mul_add(e2 - e1, -(f2 - f1));
    let b = phi2.cos() - phi1.cos();
    let x = (-lam * cp).mul_add(a, -2.0 * k * lam * sp * b);
    let y = (-lam * sp).mul_add(a, 2.0 * k * lam * cp * b);
    let amp = 2.0 * k * (load * ei).sqrt();
    Some(Elastica {
        tip: [x, y],
        force: [load * cp, load * sp],
        base_moment: amp * phi1.cos(),
        tip_moment: amp * phi2.cos(),
        load,
    })
}
