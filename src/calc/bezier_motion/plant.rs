//! The compliant drive of spec §3.1 and §3.3–3.5: derived quantities, the closed-form transition
//! matrix `e^{Ac t}` for every ξ ≥ 0, and the response matrix `H` with `x(T) = H·A` (integration
//! by parts when `r = 2N/rho_min ≤ 1`, composite Gauss–Legendre otherwise).

use super::law::{bernstein_all, bernstein_horner, binomial};
use crate::numerics::quadrature::gauss_legendre;

/// Below this `|qd·t²|` the transition matrix uses its power series (spec §3.4): no 0/0 at ξ = 1.
pub const SERIES_SWITCH: f64 = 1e-2;
/// Terms of the series branch (spec §3.4: k = 0..11; the truncation error is < 1e-2^12/24!).
const SERIES_TERMS: usize = 12;
/// Largest `rho_max = T·|p_fast|` for the Gauss–Legendre path (spec §2, §6).
pub const RHO_MAX_GL: f64 = 2e5;
/// `rho_max` per Gauss–Legendre panel (spec §3.5b).
pub const RHO_PER_PANEL: f64 = 24.0;

/// A compliant drive: `J_eq`, `k`, `c`, `z` and the derived `ωn`, `ξ` (spec §3.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plant {
    /// Equivalent inertia downstream of the joint `J_eq` [kg m²].
    pub j_eq: f64,
    /// Joint stiffness `k` [N m/rad].
    pub k: f64,
    /// Joint viscous damping `c` [N m s/rad].
    pub c: f64,
    /// Reducer ratio `z` (output/motor).
    pub z: f64,
    /// Natural frequency `ωn = sqrt(k/J_eq)` [rad/s].
    pub wn: f64,
    /// Damping ratio `ξ = c / (2 sqrt(k J_eq))`.
    pub xi: f64,
}

impl Plant {
    /// The plant with its derived quantities.
    #[must_use]
    pub fn new(j_eq: f64, k: f64, c: f64, z: f64) -> Self {
        let wn = k.sqrt() / j_eq.sqrt();
        let xi = c / (2.0 * k.sqrt() * j_eq.sqrt());
        Self {
            j_eq,
            k,
            c,
            z,
            wn,
            xi,
        }
    }

    /// The same drive with stiffness `k·f` (J_eq, c, z unchanged).
    #[must_use]
    pub fn with_stiffness_factor(&self, f: f64) -> Self {
        Self::new(self.j_eq, self.k * f, self.c, self.z)
    }

    /// `1 − ξ²`, formed as `(1 − ξ)(1 + ξ)` (exact sign and no cancellation near ξ = 1).
    fn one_minus_xi2(&self) -> f64 {
        (1.0 - self.xi) * (1.0 + self.xi)
    }

    /// Damped frequency `ωd` [rad/s] (only ξ < 1).
    #[must_use]
    pub fn omega_d(&self) -> Option<f64> {
        (self.xi < 1.0).then(|| self.wn * self.one_minus_xi2().sqrt())
    }

    /// `(|p_slow|, |p_fast|)` [rad/s]: both ωn for ξ ≤ 1; `ωn(ξ ∓ sqrt(ξ²−1))` for ξ > 1 (the slow
    /// one formed as `ωn / (ξ + sqrt(ξ²−1))`, free of cancellation).
    #[must_use]
    pub fn pole_magnitudes(&self) -> (f64, f64) {
        if self.xi <= 1.0 {
            (self.wn, self.wn)
        } else {
            let q = (self.xi - 1.0).sqrt() * (self.xi + 1.0).sqrt();
            (self.wn / (self.xi + q), self.wn * (self.xi + q))
        }
    }

    /// `(C̃, S̃)` of spec §3.4 at time `t ≥ 0`.
    fn cs(&self, t: f64) -> (f64, f64) {
        let sigma = -self.xi * self.wn;
        let qd = self.wn * self.wn * self.one_minus_xi2();
        let s = qd * t * t;
        if s.abs() < SERIES_SWITCH {
            // Cf = Σ (−s)^k/(2k)!, Sf = t Σ (−s)^k/(2k+1)!.
            let (mut cf, mut sf) = (0.0, 0.0);
            let (mut tc, mut ts) = (1.0, 1.0);
            for k in 0..SERIES_TERMS {
                cf += tc;
                sf += ts;
                let kk = k as f64;
                tc *= -s / ((2.0 * kk + 1.0) * (2.0 * kk + 2.0));
                ts *= -s / ((2.0 * kk + 2.0) * (2.0 * kk + 3.0));
            }
            let e = (sigma * t).exp();
            (e * cf, e * t * sf)
        } else if qd > 0.0 {
            let w = qd.sqrt();
            let e = (sigma * t).exp();
            let (sn, cs) = (w * t).sin_cos();
            (e * cs, e * sn / w)
        } else {
            let r = (-qd).sqrt();
            let (slow, fast) = self.pole_magnitudes();
            // σ + r = −|p_slow|, σ − r = −|p_fast|: both ≤ 0, formed without cancellation.
            let ea = (-slow * t).exp();
            let eb = (-fast * t).exp();
            ((ea + eb) / 2.0, (ea - eb) / (2.0 * r))
        }
    }

    /// The transition matrix `e^{Ac t}` (spec §3.4), row-major.
    #[must_use]
    pub fn transition(&self, t: f64) -> [[f64; 2]; 2] {
        let (c, s) = self.cs(t);
        let xw = self.xi * self.wn;
        [[c + xw * s, s], [-self.wn * (self.wn * s), c - xw * s]]
    }

    /// Second column of `e^{Ac t}`: the response to a unit initial velocity.
    #[must_use]
    pub fn column2(&self, t: f64) -> [f64; 2] {
        let (c, s) = self.cs(t);
        [s, c - self.xi * self.wn * s]
    }

    /// Free response `x(t) = e^{Ac t} x0`.
    #[must_use]
    pub fn propagate(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let e = self.transition(t);
        [
            e[0][0] * x0[0] + e[0][1] * x0[1],
            e[1][0] * x0[0] + e[1][1] * x0[1],
        ]
    }

    /// Vibration energy `½ J_eq (ψ'² + ωn² ψ²)` \[J\] (paper Eq. 24), with `ωn ψ` formed first.
    #[must_use]
    pub fn energy(&self, x: [f64; 2]) -> f64 {
        let a = self.wn * x[0];
        0.5 * self.j_eq * (x[1] * x[1] + a * a)
    }

    /// Residual amplitude `R` \[rad\] of the free vibration from state `x` (ξ < 1, spec §3.6).
    #[must_use]
    pub fn amplitude(&self, x: [f64; 2]) -> Option<f64> {
        let wd = self.omega_d()?;
        let b = (x[1] + self.xi * self.wn * x[0]) / wd;
        Some(x[0].hypot(b))
    }
}

/// How `H` was computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndStateMethod {
    /// Integration by parts, closed form (spec §3.5a).
    ClosedFormIbp,
    /// Over-damped drive (ξ ≥ [`MODAL_XI`]) with r > 1: the two real modes separately, the fast one
    /// by integration by parts, the slow one by integration by parts when `2N ≤ T·|p_slow|`, else by
    /// Gauss–Legendre with the §3.5b rule on its own `T·|p_slow|` (`panels`, `nodes`; 0 when
    /// unused).
    Modal {
        /// Gauss–Legendre panels of the slow mode (0: integration by parts).
        panels: usize,
        /// Nodes per panel of the slow mode (0: integration by parts).
        nodes: usize,
    },
    /// Composite Gauss–Legendre on the Duhamel integral (spec §3.5b).
    GaussLegendre {
        /// Equal panels on [0, 1].
        panels: usize,
        /// Nodes per panel.
        nodes: usize,
    },
}

/// The response matrix: `x(T) = H·A` for acceleration ordinates `A_0..A_N` (spec §3.5).
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseMatrix {
    /// Row of ψ(T), one entry per `A_i` [rad per rad/s²].
    pub psi: Vec<f64>,
    /// Row of ψ'(T) [rad/s per rad/s²].
    pub dpsi: Vec<f64>,
    /// How it was computed.
    pub method: EndStateMethod,
    /// `r = 2N / rho_min`.
    pub ratio: f64,
}

impl ResponseMatrix {
    /// `x(T) = H·A`.
    #[must_use]
    pub fn apply(&self, a: &[f64]) -> [f64; 2] {
        let dot = |h: &[f64]| h.iter().zip(a).map(|(h, a)| h * a).sum::<f64>();
        [dot(&self.psi), dot(&self.dpsi)]
    }
}

/// `r = 2N / rho_min` (spec §3.5): IBP is exact to round-off for r ≤ 1.
#[must_use]
pub fn ibp_ratio(plant: &Plant, n: usize, t: f64) -> f64 {
    2.0 * n as f64 / (t * plant.pole_magnitudes().0)
}

/// Least damping ratio of the modal path: from ξ = 1.25 the fast pole is at least 4× the slow
/// one, so the two modes' contributions never cancel to more than a factor ~2.
pub const MODAL_XI: f64 = 1.25;

/// Whether the end state takes the modal path: r > 1, ξ ≥ [`MODAL_XI`], and Gauss–Legendre would
/// need more than two panels (below that it costs no more than the modal sums).
#[must_use]
pub fn modal_path(plant: &Plant, n: usize, t: f64) -> bool {
    ibp_ratio(plant, n, t) > 1.0
        && plant.xi >= MODAL_XI
        && t * plant.pole_magnitudes().1 > 2.0 * RHO_PER_PANEL
}

/// The production choice of spec §3.5: IBP for r ≤ 1, else Gauss–Legendre with the node rule
/// (the modal closed form for strongly over-damped drives, [`modal_path`]). `None` when the
/// Gauss–Legendre path would need `rho_max > RHO_MAX_GL` (the spec's admission limit, kept on the
/// modal path too).
#[must_use]
pub fn response_matrix(plant: &Plant, n: usize, t: f64) -> Option<ResponseMatrix> {
    let ratio = ibp_ratio(plant, n, t);
    if ratio <= 1.0 {
        return Some(response_ibp(plant, n, t));
    }
    let rho_max = t * plant.pole_magnitudes().1;
    if rho_max > RHO_MAX_GL {
        return None;
    }
    if modal_path(plant, n, t) {
        return Some(response_modal(plant, n, t));
    }
    let (panels, nodes) = gl_rule(n, rho_max);
    Some(response_gl(plant, n, t, panels, nodes))
}

/// `H` of an over-damped drive from its two real modes: with `ea = e^{−|p_slow| t}`,
/// `eb = e^{−|p_fast| t}` and `r = ωn √(ξ²−1)`, the second column of `e^{Ac t}` is
/// `(ea·[1, −|p_slow|] − eb·[1, −|p_fast|]) / (2r)`, so
/// `H[:, i] = −zT/(2r) · (I_slow(i)·[1, −|p_slow|] − I_fast(i)·[1, −|p_fast|])` with
/// `I(ρ, i) = ∫₀¹ e^{−ρ(1−λ)} B(N, i, λ) dλ`, each by [`mode_integrals`].
#[must_use]
pub fn response_modal(plant: &Plant, n: usize, t: f64) -> ResponseMatrix {
    let (slow, fast) = plant.pole_magnitudes();
    let r = plant.wn * (plant.xi - 1.0).sqrt() * (plant.xi + 1.0).sqrt();
    let (is, rule) = mode_integrals(n, t * slow);
    let (ifast, _) = mode_integrals(n, t * fast);
    let scale = -plant.z * t / (2.0 * r);
    let psi = is
        .iter()
        .zip(&ifast)
        .map(|(a, b)| scale * (a - b))
        .collect();
    let dpsi = is
        .iter()
        .zip(&ifast)
        .map(|(a, b)| scale * (fast * b - slow * a))
        .collect();
    let (panels, nodes) = rule.unwrap_or((0, 0));
    ResponseMatrix {
        psi,
        dpsi,
        method: EndStateMethod::Modal { panels, nodes },
        ratio: ibp_ratio(plant, n, t),
    }
}

/// `I(ρ, i) = ∫₀¹ e^{−ρ(1−λ)} B(N, i, λ) dλ`, i = 0..N, of one real mode: by integration by parts
/// `Σ_k (−1/ρ)^{k+1} [e^{−ρ} u^(k)(0) − u^(k)(1)]` when `2N ≤ ρ` (the terms fall like (N/ρ)^k, as
/// in spec §3.5a), else by composite Gauss–Legendre with the §3.5b rule on ρ (returned).
#[must_use]
pub fn mode_integrals(n: usize, rho: f64) -> (Vec<f64>, Option<(usize, usize)>) {
    let mut out = vec![0.0; n + 1];
    if 2.0 * n as f64 <= rho {
        let minv = -1.0 / rho;
        let mut g = (-rho).exp();
        let mut h = 1.0;
        let mut falling = 1.0;
        for k in 0..=n {
            g *= minv;
            h *= minv;
            if k > 0 {
                falling *= (n + 1 - k) as f64;
            }
            for jx in 0..=k {
                let sign = if (k - jx) % 2 == 0 { 1.0 } else { -1.0 };
                let coef = falling * sign * binomial(k, jx);
                out[jx] += coef * g;
                out[n - k + jx] -= coef * h;
            }
        }
        return (out, None);
    }
    let (panels, nodes) = gl_rule(n, rho);
    let (x, wq) = gauss_legendre(nodes);
    let pf = panels as f64;
    let mut b = vec![0.0; n + 1];
    for p in 0..panels {
        for (xl, wl) in x.iter().zip(&wq) {
            let lam = (p as f64 + xl) / pf;
            bernstein_all(n, lam, &mut b);
            let w = wl / pf * (-rho * (1.0 - lam)).exp();
            for (o, bi) in out.iter_mut().zip(&b) {
                *o += w * bi;
            }
        }
    }
    (out, Some((panels, nodes)))
}

/// The λ-derivatives `u^(k)(0)` and `u^(k)(1)`, k = 0..N, of the acceleration law with ordinates
/// `A_0..A_N` (spec §3.5a): `N!/(N−k)! Δ^k A_0` and `N!/(N−k)! Δ^k A_{N−k}`. They depend on the law
/// only, so a stiffness sweep computes them once and each factor's end state in O(N).
#[derive(Debug, Clone, PartialEq)]
pub struct EndDerivatives {
    /// The acceleration ordinates.
    pub a: Vec<f64>,
    /// `u^(k)(0)`.
    pub at0: Vec<f64>,
    /// `u^(k)(1)`.
    pub at1: Vec<f64>,
}

impl EndDerivatives {
    /// The end derivatives of the law with acceleration ordinates `a`.
    #[must_use]
    pub fn new(a: &[f64]) -> Self {
        let n = a.len().saturating_sub(1);
        let mut d = a.to_vec();
        let (mut at0, mut at1) = (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        let mut falling = 1.0;
        for k in 0..=n {
            if k > 0 {
                falling *= (n + 1 - k) as f64;
                for i in 0..d.len() - 1 {
                    d[i] = d[i + 1] - d[i];
                }
                d.pop();
            }
            at0.push(falling * d.first().copied().unwrap_or(0.0));
            at1.push(falling * d.last().copied().unwrap_or(0.0));
        }
        Self {
            a: a.to_vec(),
            at0,
            at1,
        }
    }
}

/// `x(T)` of one law on `plant` without forming `H` (the stiffness sweep): on the IBP path spec
/// §3.5a applied to the law's [`EndDerivatives`] (O(N)), otherwise the Duhamel integral of the
/// production rule applied to `u(λ)` itself (O(N) per node) or, on the modal path, `H` and its
/// product. `None` where [`response_matrix`] is `None`.
#[must_use]
pub fn end_state(plant: &Plant, law: &EndDerivatives, t: f64) -> Option<[f64; 2]> {
    let n = law.a.len().saturating_sub(1);
    let ratio = ibp_ratio(plant, n, t);
    if ratio <= 1.0 {
        let w = plant.wn * t;
        let minv = [[-2.0 * plant.xi / w, -t / (w * w)], [1.0 / t, 0.0]];
        let mul = |v: [f64; 2]| {
            [
                minv[0][0] * v[0] + minv[0][1] * v[1],
                minv[1][0] * v[0] + minv[1][1] * v[1],
            ]
        };
        let mut g = plant.column2(t);
        let mut h = [0.0, 1.0];
        let mut x = [0.0, 0.0];
        for (d0, d1) in law.at0.iter().zip(&law.at1) {
            g = mul(g);
            h = mul(h);
            x[0] += g[0] * d0 - h[0] * d1;
            x[1] += g[1] * d0 - h[1] * d1;
        }
        let scale = -plant.z * t;
        return Some([scale * x[0], scale * x[1]]);
    }
    let rho_max = t * plant.pole_magnitudes().1;
    if rho_max > RHO_MAX_GL {
        return None;
    }
    if modal_path(plant, n, t) {
        return Some(response_modal(plant, n, t).apply(&law.a));
    }
    let (panels, nodes) = gl_rule(n, rho_max);
    let (x, wq) = gauss_legendre(nodes);
    let pf = panels as f64;
    let scale = -plant.z * t;
    let mut out = [0.0, 0.0];
    for p in 0..panels {
        for (xl, wl) in x.iter().zip(&wq) {
            let lam = (p as f64 + xl) / pf;
            let col = plant.column2(t * (1.0 - lam));
            let w = scale * wl / pf * bernstein_horner(&law.a, lam);
            out[0] += w * col[0];
            out[1] += w * col[1];
        }
    }
    Some(out)
}

/// The node rule of spec §3.5b: `P = max(1, ceil(rho_max/24))`,
/// `q = ceil(N/2 + 0.75·rho_max/P + 12)`.
#[must_use]
pub fn gl_rule(n: usize, rho_max: f64) -> (usize, usize) {
    let panels = (rho_max / RHO_PER_PANEL).ceil().max(1.0);
    let nodes = (n as f64 / 2.0 + 0.75 * rho_max / panels + 12.0).ceil();
    // Both are small positive whole numbers (rho_max ≤ 2e5 when called from the production path).
    (panels as usize, nodes as usize)
}

/// `H` by integration by parts (spec §3.5a):
/// `x(T) = −zT Σ_k M^{−(k+1)} [e^{Ac T} e2 u^(k)(0) − e2 u^(k)(1)]`, `M = T·Ac`.
#[must_use]
pub fn response_ibp(plant: &Plant, n: usize, t: f64) -> ResponseMatrix {
    let w = plant.wn * t;
    // M⁻¹ = [[−2ξ/W, −T/W²], [1/T, 0]] in the physical state [ψ, ψ'].
    let minv = [[-2.0 * plant.xi / w, -t / (w * w)], [1.0 / t, 0.0]];
    let mul = |v: [f64; 2]| {
        [
            minv[0][0] * v[0] + minv[0][1] * v[1],
            minv[1][0] * v[0] + minv[1][1] * v[1],
        ]
    };
    let mut g = plant.column2(t);
    let mut h = [0.0, 1.0];
    let scale = -plant.z * t;
    let mut psi = vec![0.0; n + 1];
    let mut dpsi = vec![0.0; n + 1];
    let mut falling = 1.0; // N!/(N−k)!
    for k in 0..=n {
        g = mul(g);
        h = mul(h);
        if k > 0 {
            falling *= (n + 1 - k) as f64;
        }
        for jx in 0..=k {
            let sign = if (k - jx) % 2 == 0 { 1.0 } else { -1.0 };
            let coef = scale * falling * sign * binomial(k, jx);
            // u^(k)(0) = N!/(N−k)! Σ_j (−1)^{k−j} C(k,j) A_j
            psi[jx] += coef * g[0];
            dpsi[jx] += coef * g[1];
            // u^(k)(1) = N!/(N−k)! Σ_j (−1)^{k−j} C(k,j) A_{N−k+j}
            psi[n - k + jx] -= coef * h[0];
            dpsi[n - k + jx] -= coef * h[1];
        }
    }
    ResponseMatrix {
        psi,
        dpsi,
        method: EndStateMethod::ClosedFormIbp,
        ratio: ibp_ratio(plant, n, t),
    }
}

/// `H` by composite Gauss–Legendre on `x(T) = −zT ∫₀¹ e^{Ac T(1−λ)} e2 u(λ) dλ` (spec §3.5b).
#[must_use]
pub fn response_gl(plant: &Plant, n: usize, t: f64, panels: usize, nodes: usize) -> ResponseMatrix {
    let (x, wq) = gauss_legendre(nodes);
    let panels = panels.max(1);
    let pf = panels as f64;
    let mut psi = vec![0.0; n + 1];
    let mut dpsi = vec![0.0; n + 1];
    let mut b = vec![0.0; n + 1];
    let scale = -plant.z * t;
    for p in 0..panels {
        for (xl, wl) in x.iter().zip(&wq) {
            let lam = (p as f64 + xl) / pf;
            let col = plant.column2(t * (1.0 - lam));
            bernstein_all(n, lam, &mut b);
            let w = scale * wl / pf;
            for i in 0..=n {
                psi[i] += w * col[0] * b[i];
                dpsi[i] += w * col[1] * b[i];
            }
        }
    }
    ResponseMatrix {
        psi,
        dpsi,
        method: EndStateMethod::GaussLegendre { panels, nodes },
        ratio: ibp_ratio(plant, n, t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transition_is_continuous_across_critical_damping() {
        let t = 0.3;
        let at = |xi: f64| Plant::new(1.0, 900.0, xi * 60.0, 1.0).transition(t);
        let c = at(1.0);
        for d in [1e-12, 1e-9, 1e-6] {
            for xi in [1.0 - d, 1.0 + d] {
                let e = at(xi);
                for r in 0..2 {
                    for k in 0..2 {
                        let scale = c[r][k].abs().max(1e-3);
                        assert!(
                            (e[r][k] - c[r][k]).abs() <= 200.0 * d * scale + 1e-15,
                            "xi={xi} [{r}][{k}] {} vs {}",
                            e[r][k],
                            c[r][k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn ibp_and_gl_agree_below_ratio_one() {
        let plant = Plant::new(2.81, 8000.0, 35.0, 0.05);
        let a = response_ibp(&plant, 6, 1.0);
        let b = response_gl(&plant, 6, 1.0, 4, 40);
        let m = a.psi.iter().map(|x| x.abs()).fold(0.0, f64::max);
        for i in 0..7 {
            assert!((a.psi[i] - b.psi[i]).abs() < 1e-12 * m.max(1e-30));
        }
    }
}
