//! Parametric IPMSM (spec §5.5 item 4): amplitude-invariant dq model with peak quantities,
//! torque T = 1.5 p [ψ_m i_q + (L_d − L_q) i_d i_q], steady-state voltage
//! v_d = R i_d − ω_e L_q i_q, v_q = R i_q + ω_e (ψ_m + L_d i_d), the torque envelope of §5.5.4,
//! MTPA / flux-weakening operating points and the loss split into DC copper, extra AC copper,
//! iron and mechanical loss.
//!
//! Paper ambiguity 4: the paper's eq. 6 (no 3/2 factor, rms flux) is the power-invariant form;
//! the amplitude-invariant form used here is equivalent. Sign convention: i_q has the sign of the
//! torque; i_d ≤ 0 (demagnetising); the rotor turns forward (ω_m ≥ 0).

// Plain products instead of `mul_add`: without FMA hardware in the target (the default x86-64
// baseline) `mul_add` is a libm call, ~10x slower in these per-interval loops, and plain
// arithmetic follows the rounding of the spec's reference implementation.

use std::f64::consts::{FRAC_PI_2, PI};

use super::ac_factor::{AcFactor, temp_factor};

/// Angles of the envelope's β grid (spec §5.5.4).
pub const N_BETA: usize = 721;
/// Golden-section iterations refining the envelope's best grid angle (spec §5.5.4).
pub const GOLDEN_ITERS: usize = 60;
/// Bisection iterations for the MTPA current, the flux-weakening root and the envelope angle.
pub const BISECT_ITERS: usize = 80;
/// Steps of the flux-weakening scan from the MTPA i_d down to −I_pk (spec §5.5 item 4c).
pub const FW_SCAN_STEPS: usize = 400;
/// Relative torque back-off of the first retry near the envelope (spec §5.5 item 4d).
pub const RETRY_BACKOFF: f64 = 1e-6;
/// Below this 2(A² + B²) the voltage constraint is degenerate (spec §8 item 6).
const QUAD_EPS: f64 = 1e-30;

/// How an operating point was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OpMode {
    /// Maximum torque per ampere, inside the voltage limit.
    Mtpa,
    /// Flux weakening on the constant-torque curve, on the voltage limit.
    FluxWeakening,
    /// Solved on the envelope's own (β, s*) parametrisation (spec §5.5 item 4d).
    Envelope,
}

impl OpMode {
    /// Wire name.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mtpa => "mtpa",
            Self::FluxWeakening => "fw",
            Self::Envelope => "envelope",
        }
    }
}

/// Currents of an operating point [A peak].
#[derive(Debug, Clone, Copy)]
pub struct Currents {
    /// d-axis current i_d (≤ 0).
    pub i_d: f64,
    /// q-axis current i_q (sign of the torque).
    pub i_q: f64,
    /// How it was found.
    pub mode: OpMode,
}

/// Losses at an operating point \[W\].
#[derive(Debug, Clone, Copy, Default)]
pub struct LossSplit {
    /// AC resistance factor k_AC at the electrical frequency.
    pub k_ac: f64,
    /// DC copper loss P_cu,DC = 1.5 R (i_d² + i_q²).
    pub cu_dc: f64,
    /// Copper loss with AC effect P_cu = k_AC P_cu,DC (the paper's P_copper,AC).
    pub cu: f64,
    /// Iron loss P_fe = (k_h ω_e + k_e ω_e²)|ψ|².
    pub iron: f64,
    /// Mechanical loss P_mech = c_fric ω_m + c_wind ω_m³.
    pub mech: f64,
    /// Total P_loss = P_cu + P_fe + P_mech.
    pub total: f64,
}

impl LossSplit {
    /// The extra AC copper loss (k_AC − 1) P_cu,DC.
    #[must_use]
    pub fn cu_ac_extra(&self) -> f64 {
        self.cu - self.cu_dc
    }
}

/// Envelope point: maximum torque at one speed and its current angle.
#[derive(Debug, Clone, Copy)]
pub struct EnvelopePoint {
    /// Maximum torque from the current and voltage limits, before caps [N·m].
    pub torque: f64,
    /// Current angle β from +q toward −d \[rad\].
    pub beta: f64,
    /// Current amplitude s* [A peak].
    pub current: f64,
}

/// A parametric IPMSM in SI units (hot resistance already applied).
#[derive(Debug, Clone)]
pub struct Ipmsm {
    /// Pole pairs p.
    pub p: f64,
    /// PM flux linkage ψ_m [Wb peak].
    pub psi: f64,
    /// L_d \[H\].
    pub ld: f64,
    /// L_q \[H\] (≥ L_d).
    pub lq: f64,
    /// Phase resistance at the winding temperature R(T_w) \[Ω\].
    pub r: f64,
    /// Winding temperature [°C] (for the Dowell skin depth).
    pub temp_c: f64,
    /// Peak current limit I_pk = √2 I_rms \[A\].
    pub i_pk: f64,
    /// Peak phase voltage limit V_max = utilisation·V_dc/√3 \[V\].
    pub v_max: f64,
    /// Maximum mechanical speed [rad/s].
    pub omega_max: f64,
    /// Torque cap [N·m] (∞ if none).
    pub t_cap: f64,
    /// Power cap \[W\] (∞ if none).
    pub p_cap: f64,
    /// AC factor model.
    pub ac: AcFactor,
    /// Hysteresis coefficient k_h.
    pub k_h: f64,
    /// Eddy coefficient k_e.
    pub k_e: f64,
    /// Friction torque c_fric [N·m].
    pub c_fric: f64,
    /// Windage coefficient c_wind.
    pub c_wind: f64,
    /// (sin β_k, cos β_k) of the envelope's β grid.
    trig: Vec<(f64, f64)>,
}

/// Parameters of [`Ipmsm::new`] as given on the wire (before temperature and stack scaling).
#[derive(Debug, Clone)]
pub struct IpmsmParams {
    /// Pole pairs.
    pub pole_pairs: f64,
    /// ψ_m [Wb peak].
    pub psi_m_wb: f64,
    /// L_d \[H\].
    pub ld_h: f64,
    /// L_q \[H\].
    pub lq_h: f64,
    /// R at 20 °C \[Ω\].
    pub r_20_ohm: f64,
    /// Winding temperature [°C].
    pub winding_temp_c: f64,
    /// Current limit [A rms].
    pub i_max_arms: f64,
    /// DC link voltage \[V\].
    pub v_dc: f64,
    /// Voltage utilisation.
    pub voltage_utilization: f64,
    /// Maximum speed \[rpm\].
    pub n_max_rpm: f64,
    /// Torque cap [N·m] (∞ if none).
    pub t_cap_nm: f64,
    /// Power cap \[W\] (∞ if none).
    pub p_cap_w: f64,
    /// AC factor.
    pub ac: AcFactor,
    /// k_h.
    pub k_h: f64,
    /// k_e.
    pub k_e: f64,
    /// c_fric [N·m].
    pub c_fric: f64,
    /// c_wind.
    pub c_wind: f64,
    /// Stack-length scale (1 = as given).
    pub stack_scale: f64,
}

/// ψ_m from a back-EMF measurement: ψ_m = V_peak_phase / (p · 2π·rpm/60).
#[must_use]
pub fn psi_from_back_emf(v_peak_phase: f64, at_rpm: f64, pole_pairs: f64) -> f64 {
    v_peak_phase / (pole_pairs * rpm_to_rad_s(at_rpm))
}

/// rpm → rad/s.
#[must_use]
pub fn rpm_to_rad_s(rpm: f64) -> f64 {
    rpm * PI / 30.0
}

/// rad/s → rpm.
#[must_use]
pub fn rad_s_to_rpm(w: f64) -> f64 {
    w * 30.0 / PI
}

/// Roots (low, high) of a s² + b s + c = 0 in the cancellation-free form (spec §8 item 6), or
/// `None` when the discriminant is negative. `a` must be > 0.
fn quadratic_roots(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let q = -0.5 * (b + b.signum() * sq);
    if q.abs() < f64::MIN_POSITIVE {
        let s = -b / (2.0 * a);
        return Some((s, s));
    }
    let (r1, r2) = (q / a, c / q);
    Some((r1.min(r2), r1.max(r2)))
}

/// (sin β, cos β) on the N_BETA-point grid of [0, π/2].
fn beta_grid() -> Vec<(f64, f64)> {
    let step = FRAC_PI_2 / (N_BETA - 1) as f64;
    (0..N_BETA).map(|k| (k as f64 * step).sin_cos()).collect()
}

/// Stride of the coarse pre-scan that looks for a binding torque/power cap.
const CAP_PRESCAN_STRIDE: usize = 16;

impl Ipmsm {
    /// Build from wire parameters: hot resistance R(T_w) = R_20 (1 + 0.00393 (T_w − 20)),
    /// I_pk = √2 I_rms, V_max = u·V_dc/√3, and the optional stack-length scaling of paper §3.2
    /// (ψ_m, L_d, L_q, k_h, k_e ×s; R slot part ×s, end part unchanged; the Dowell slot length ×s).
    #[must_use]
    pub fn new(p: &IpmsmParams) -> Self {
        let s = p.stack_scale;
        let r_hot = p.r_20_ohm * temp_factor(p.winding_temp_c);
        let mut ac = p.ac.clone();
        let r = match &mut ac {
            AcFactor::Dowell(d) if (s - 1.0).abs() > 0.0 => {
                let (ls, le) = (d.stack_length_m, d.end_length_m);
                let slot = r_hot * ls / (ls + le);
                let end = r_hot * le / (ls + le);
                d.stack_length_m *= s;
                slot * s + end
            }
            _ => r_hot,
        };
        Self {
            p: p.pole_pairs,
            psi: p.psi_m_wb * s,
            ld: p.ld_h * s,
            lq: p.lq_h * s,
            r,
            temp_c: p.winding_temp_c,
            i_pk: std::f64::consts::SQRT_2 * p.i_max_arms,
            v_max: p.voltage_utilization * p.v_dc / 3f64.sqrt(),
            omega_max: rpm_to_rad_s(p.n_max_rpm),
            t_cap: p.t_cap_nm,
            p_cap: p.p_cap_w,
            ac,
            k_h: p.k_h * s,
            k_e: p.k_e * s,
            c_fric: p.c_fric,
            c_wind: p.c_wind,
            trig: beta_grid(),
        }
    }

    /// Electromagnetic torque T = 1.5 p [ψ_m i_q + (L_d − L_q) i_d i_q] [N·m].
    #[must_use]
    pub fn torque(&self, i_d: f64, i_q: f64) -> f64 {
        1.5 * self.p * i_q * (self.psi + (self.ld - self.lq) * i_d)
    }

    /// Steady-state voltage amplitude |v| [V peak] at electrical speed `w_e`.
    #[must_use]
    pub fn voltage(&self, w_e: f64, i_d: f64, i_q: f64) -> f64 {
        let vd = self.r * i_d - w_e * self.lq * i_q;
        let vq = self.r * i_q + w_e * (self.psi + self.ld * i_d);
        vd.hypot(vq)
    }

    /// Squared voltage amplitude |v|² [V²] (comparisons against V_max² avoid a square root).
    fn voltage_sq(&self, w_e: f64, i_d: f64, i_q: f64) -> f64 {
        let vd = self.r * i_d - w_e * self.lq * i_q;
        let vq = self.r * i_q + w_e * (self.psi + self.ld * i_d);
        vd * vd + vq * vq
    }

    /// Largest current s* ≤ I_pk at angle β inside the voltage limit, for torque sign `sign`
    /// (i_d = −s sinβ, i_q = sign·s cosβ); `None` if the angle is infeasible (§5.5.4).
    fn s_star(&self, w_e: f64, sin_b: f64, cos_b: f64, sign: f64) -> Option<f64> {
        let a = -self.r * sin_b - sign * w_e * self.lq * cos_b;
        let b = sign * self.r * cos_b - w_e * self.ld * sin_b;
        let c = w_e * self.psi;
        let qa = a * a + b * b;
        let (s_lo, s_hi) = if 2.0 * qa < QUAD_EPS {
            // |v| = |C| independent of s.
            if c.abs() <= self.v_max {
                (f64::NEG_INFINITY, f64::INFINITY)
            } else {
                return None;
            }
        } else {
            quadratic_roots(qa, 2.0 * b * c, c * c - self.v_max * self.v_max)?
        };
        let s = s_hi.min(self.i_pk);
        (s >= s_lo.max(0.0) && s > 0.0).then_some(s)
    }

    /// Torque magnitude at angle β with the largest admissible current (0 if infeasible).
    fn torque_at_sc(&self, w_e: f64, sin_b: f64, cos_b: f64, sign: f64) -> (f64, f64) {
        match self.s_star(w_e, sin_b, cos_b, sign) {
            Some(s) => (
                1.5 * self.p * s * cos_b * (self.psi + (self.lq - self.ld) * s * sin_b),
                s,
            ),
            None => (0.0, 0.0),
        }
    }

    fn torque_at_beta(&self, w_e: f64, beta: f64, sign: f64) -> (f64, f64) {
        let (sin_b, cos_b) = beta.sin_cos();
        self.torque_at_sc(w_e, sin_b, cos_b, sign)
    }

    /// The MTPA point on the current circle s = I_pk: (torque, β). sinβ solves
    /// ∂T/∂β = 0, 2ΔL I sin²β + ψ sinβ − ΔL I = 0 (β = 0 for ΔL = 0).
    fn mtpa_at_current_limit(&self) -> (f64, f64) {
        let (dl, i) = (self.lq - self.ld, self.i_pk);
        // Cancellation-free root of 2ΔL I x² + ψ x − ΔL I = 0.
        let sin_b =
            2.0 * dl * i / (self.psi + (self.psi * self.psi + 8.0 * dl * dl * i * i).sqrt());
        let beta = sin_b.clamp(0.0, 1.0).asin();
        let cos_b = beta.cos();
        (1.5 * self.p * i * cos_b * (self.psi + dl * i * sin_b), beta)
    }

    /// Envelope from the current and voltage limits only (no caps, no n_max), §5.5.4:
    /// best of 721 angles, then 60 golden-section steps on the neighbouring bracket.
    ///
    /// Shortcut (exact): when the voltage limit admits the full current at the MTPA angle of the
    /// current circle, that point is the global maximum (T grows with s at every β ∈ [0, π/2]),
    /// which the scan would converge to.
    #[must_use]
    pub fn envelope_raw(&self, omega_m: f64, sign: f64) -> EnvelopePoint {
        let w_e = self.p * omega_m;
        let (t_m, beta_m) = self.mtpa_at_current_limit();
        let (sin_m, cos_m) = beta_m.sin_cos();
        if self
            .s_star(w_e, sin_m, cos_m, sign)
            .is_some_and(|s| s >= self.i_pk)
        {
            return EnvelopePoint {
                torque: t_m,
                beta: beta_m,
                current: self.i_pk,
            };
        }
        let step = FRAC_PI_2 / (N_BETA - 1) as f64;
        let mut best = EnvelopePoint {
            torque: 0.0,
            beta: 0.0,
            current: 0.0,
        };
        let mut best_k = 0usize;
        for (k, &(sin_b, cos_b)) in self.trig.iter().enumerate() {
            let (t, s) = self.torque_at_sc(w_e, sin_b, cos_b, sign);
            if t > best.torque {
                best = EnvelopePoint {
                    torque: t,
                    beta: k as f64 * step,
                    current: s,
                };
                best_k = k;
            }
        }
        if best.torque <= 0.0 {
            return best;
        }
        let lo_k = best_k.saturating_sub(1);
        let hi_k = (best_k + 1).min(N_BETA - 1);
        let (mut a, mut b) = (lo_k as f64 * step, hi_k as f64 * step);
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let mut c = b - g * (b - a);
        let mut d = a + g * (b - a);
        let mut fc = self.torque_at_beta(w_e, c, sign);
        let mut fd = self.torque_at_beta(w_e, d, sign);
        for _ in 0..GOLDEN_ITERS {
            if fc.0 > fd.0 {
                b = d;
                d = c;
                fd = fc;
                c = b - g * (b - a);
                fc = self.torque_at_beta(w_e, c, sign);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + g * (b - a);
                fd = self.torque_at_beta(w_e, d, sign);
            }
        }
        let (beta, (t, s)) = if fc.0 > fd.0 { (c, fc) } else { (d, fd) };
        if t > best.torque {
            best = EnvelopePoint {
                torque: t,
                beta,
                current: s,
            };
        }
        best
    }

    /// Envelope T_max(ω_m) with caps: min(T_raw, t_cap, p_cap/ω_m); 0 above n_max.
    ///
    /// Exact shortcut: once any grid angle reaches the binding cap, T_max is the cap (a coarse
    /// pre-scan finds such an angle for most speeds of a capped motor).
    #[must_use]
    pub fn t_max(&self, omega_m: f64) -> f64 {
        if omega_m > self.omega_max {
            return 0.0;
        }
        let cap_p = if omega_m > 0.0 {
            self.p_cap / omega_m
        } else {
            f64::INFINITY
        };
        let cap = self.t_cap.min(cap_p);
        if cap.is_finite() {
            let w_e = self.p * omega_m;
            let reaches = |k: usize| {
                let (sin_b, cos_b) = self.trig[k];
                self.torque_at_sc(w_e, sin_b, cos_b, 1.0).0 >= cap
            };
            if (0..N_BETA).step_by(CAP_PRESCAN_STRIDE).any(reaches) {
                return cap;
            }
        }
        self.envelope_raw(omega_m, 1.0).torque.min(cap)
    }

    /// MTPA d-current for a q-current, i_d = −2ΔL i_q² / (ψ + √(ψ² + 4ΔL² i_q²)): the
    /// cancellation-free form of ψ/(2ΔL) − √(ψ²/(4ΔL²) + i_q²), exact 0 for ΔL = 0 (§8 item 5).
    #[must_use]
    pub fn mtpa_id(&self, i_q: f64) -> f64 {
        let dl = self.lq - self.ld;
        let root = (self.psi * self.psi + 4.0 * dl * dl * i_q * i_q).sqrt();
        -2.0 * dl * i_q * i_q / (self.psi + root)
    }

    /// Steps a-c of §5.5 item 4 for torque `t` (any sign) at ω_m; `None` if infeasible.
    #[must_use]
    pub fn solve_currents(&self, omega_m: f64, t: f64) -> Option<Currents> {
        let sign = if t < 0.0 { -1.0 } else { 1.0 };
        let ta = t.abs();
        let w_e = self.p * omega_m;
        let v2 = self.v_max * self.v_max;
        // a. MTPA current by bisection on i_q.
        let t_mtpa = |iq: f64| self.torque(self.mtpa_id(iq), iq);
        if t_mtpa(self.i_pk) < ta {
            return None;
        }
        let (mut lo, mut hi) = (0.0, self.i_pk);
        for _ in 0..BISECT_ITERS {
            let mid = 0.5 * (lo + hi);
            if t_mtpa(mid) < ta {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let iq_m = hi;
        let id_m = self.mtpa_id(iq_m);
        // b. Inside the voltage limit?
        if self.voltage_sq(w_e, id_m, sign * iq_m) <= v2 {
            return Some(Currents {
                i_d: id_m,
                i_q: sign * iq_m,
                mode: OpMode::Mtpa,
            });
        }
        // c. Flux weakening along the constant-torque curve.
        let iq_of = |id: f64| ta / (1.5 * self.p * (self.psi + (self.ld - self.lq) * id));
        let step = (-self.i_pk - id_m) / FW_SCAN_STEPS as f64;
        let mut prev = id_m;
        for k in 1..=FW_SCAN_STEPS {
            let id = id_m + step * k as f64;
            let iq = iq_of(id);
            if id * id + iq * iq > self.i_pk * self.i_pk {
                return None;
            }
            if self.voltage_sq(w_e, id, sign * iq) <= v2 {
                let (mut bad, mut good) = (prev, id);
                for _ in 0..BISECT_ITERS {
                    let mid = 0.5 * (bad + good);
                    if self.voltage_sq(w_e, mid, sign * iq_of(mid)) <= v2 {
                        good = mid;
                    } else {
                        bad = mid;
                    }
                }
                return Some(Currents {
                    i_d: good,
                    i_q: sign * iq_of(good),
                    mode: OpMode::FluxWeakening,
                });
            }
            prev = id;
        }
        None
    }

    /// Step d of §5.5 item 4: solve T(β, s*(β)) = |t| by bisection in β between the MTPA angle
    /// and the envelope's maximising angle, then take the smallest current meeting |t| there.
    fn solve_on_envelope(&self, omega_m: f64, t: f64) -> Option<Currents> {
        let sign = if t < 0.0 { -1.0 } else { 1.0 };
        let ta = t.abs();
        let w_e = self.p * omega_m;
        let env = self.envelope_raw(omega_m, sign);
        if env.torque < ta {
            return None;
        }
        // MTPA angle for |t| (ignoring the voltage limit).
        let (mut lo, mut hi) = (0.0, self.i_pk);
        for _ in 0..BISECT_ITERS {
            let mid = 0.5 * (lo + hi);
            if self.torque(self.mtpa_id(mid), mid) < ta {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let beta_mtpa = (-self.mtpa_id(hi)).atan2(hi);
        let (mut b_low, mut b_ok) = (beta_mtpa, env.beta);
        if self.torque_at_beta(w_e, b_low, sign).0 >= ta {
            b_ok = b_low;
        } else {
            for _ in 0..BISECT_ITERS {
                let mid = 0.5 * (b_low + b_ok);
                if self.torque_at_beta(w_e, mid, sign).0 >= ta {
                    b_ok = mid;
                } else {
                    b_low = mid;
                }
            }
        }
        let (sin_b, cos_b) = b_ok.sin_cos();
        let s_max = self.s_star(w_e, sin_b, cos_b, sign)?;
        if cos_b <= 0.0 {
            return None;
        }
        // T(β, s) = 1.5 p cosβ (ψ s + ΔL sinβ s²): smallest s ≥ 0 with T = |t|.
        let c = ta / (1.5 * self.p * cos_b);
        let k = (self.lq - self.ld) * sin_b;
        let s = (2.0 * c / (self.psi + (self.psi * self.psi + 4.0 * k * c).sqrt())).min(s_max);
        let (i_d, i_q) = (-s * sin_b, sign * s * cos_b);
        (s.is_finite()).then_some(Currents {
            i_d,
            i_q,
            mode: OpMode::Envelope,
        })
    }

    /// Operating point for torque `t` at ω_m with the retries of §5.5 item 4d; `t_max` is the
    /// capped envelope at ω_m. `None` only if every method fails (caller counts it).
    #[must_use]
    pub fn operating_point(&self, omega_m: f64, t: f64, t_max: f64) -> Option<Currents> {
        if let Some(c) = self.solve_currents(omega_m, t) {
            return Some(c);
        }
        if let Some(c) = self.solve_currents(omega_m, t * (1.0 - RETRY_BACKOFF)) {
            return Some(c);
        }
        if t.abs() <= t_max {
            self.solve_on_envelope(omega_m, t)
        } else {
            None
        }
    }

    /// Currents of the envelope point itself (the fallback when no operating point is found).
    #[must_use]
    pub fn envelope_currents(&self, omega_m: f64, sign: f64) -> Currents {
        let env = self.envelope_raw(omega_m, sign);
        let (sin_b, cos_b) = env.beta.sin_cos();
        Currents {
            i_d: -env.current * sin_b,
            i_q: sign * env.current * cos_b,
            mode: OpMode::Envelope,
        }
    }

    /// Losses at currents (i_d, i_q) and speed ω_m ≥ 0.
    #[must_use]
    pub fn losses(&self, omega_m: f64, i_d: f64, i_q: f64) -> LossSplit {
        let w = omega_m.abs();
        let w_e = self.p * w;
        let k_ac = self.ac.k_ac(w_e / (2.0 * PI), self.temp_c);
        let cu_dc = 1.5 * self.r * (i_d * i_d + i_q * i_q);
        let cu = k_ac * cu_dc;
        let fd = self.psi + self.ld * i_d;
        let fq = self.lq * i_q;
        let iron = (self.k_h * w_e + self.k_e * w_e * w_e) * (fd * fd + fq * fq);
        let mech = self.c_fric * w + self.c_wind * w * w * w;
        LossSplit {
            k_ac,
            cu_dc,
            cu,
            iron,
            mech,
            total: cu + iron + mech,
        }
    }

    /// Operating point and losses at (ω_m, t), `t` already clamped to ±`t_max`. Returns the
    /// losses, the currents and whether the envelope fallback had to be used.
    #[must_use]
    pub fn evaluate(&self, omega_m: f64, t: f64, t_max: f64) -> (LossSplit, Currents, bool) {
        match self.operating_point(omega_m, t, t_max) {
            Some(c) => (self.losses(omega_m, c.i_d, c.i_q), c, false),
            None => {
                let c = self.envelope_currents(omega_m, if t < 0.0 { -1.0 } else { 1.0 });
                (self.losses(omega_m, c.i_d, c.i_q), c, true)
            }
        }
    }
}
