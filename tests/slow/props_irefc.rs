//! Invariants of the IREFC specs as property tests (`irefc_geometry.md` "Property tests",
//! `irefc_stress.md` and `irefc_efficiency.md` "Property tests"). Case counts are modest for debug runs;
//! `PROPTEST_CASES` raises them.

// Tests compare against closed forms written as in the specs; mul_add would obscure them.
#![allow(clippy::suboptimal_flops)]

use std::f64::consts::{PI, TAU};

use mechcalc::calc::irefc::geometry::{Geometry, Trig, Wheel};
use mechcalc::calc::irefc::stress::compute::{Stresser, element_forces};
use mechcalc::calc::irefc::stress::input::LoadSharing;
use mechcalc::calc::irefc::stress::wire::StressSingleResponse;
use mechcalc::calc::irefc::{
    IrefcEfficiencyRequest, IrefcEfficiencyResponse, IrefcStressRequest, IrefcStressResponse,
    run_efficiency, run_stress,
};
use mechcalc::numerics::Budget;
use proptest::prelude::*;
use serde_json::{Value, json};

/// 48 cases per property by default; `PROPTEST_CASES` overrides it for bigger runs.
fn config() -> ProptestConfig {
    ProptestConfig {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|c| c.parse().ok())
            .unwrap_or(48),
        ..ProptestConfig::default()
    }
}

/// A buildable design [SI]: rb a fraction of min(rb_overlap, rb_undercut).
fn design() -> impl Strategy<Value = Geometry> {
    (3u32..=80, 1.02f64..3.0, 1.0f64..200.0, 0.05f64..0.95).prop_map(|(z2, chi, r2_mm, frac)| {
        let g = Geometry::new_unchecked(r2_mm / 1e3, z2, chi, 1e-3);
        let rb = frac * g.rb_overlap.min(g.rb_undercut);
        Geometry::new_unchecked(g.r2, z2, chi, rb)
    })
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

fn single(v: Value) -> StressSingleResponse {
    let req: IrefcStressRequest = serde_json::from_value(v).expect("decodes");
    match run_stress(req, &Budget::unlimited()).expect("computes") {
        IrefcStressResponse::Single(r) => *r,
        IrefcStressResponse::Sweep(_) => panic!("single expected"),
    }
}

fn stress_req(g: &Geometry, torque: f64) -> Value {
    json!({"r2_mm": g.r2 * 1e3, "Z2": g.z2, "chi": g.chi, "rb_mm": g.rb * 1e3, "torque_Nm": torque,
           "step_deg": 1, "refine": true})
}

fn eff(v: Value) -> IrefcEfficiencyResponse {
    let req: IrefcEfficiencyRequest = serde_json::from_value(v).expect("decodes");
    run_efficiency(req, &Budget::unlimited()).expect("computes")
}

fn eff_req(g: &Geometry, model: &str, mu_mm: f64, fs: f64) -> Value {
    json!({"r2_mm": g.r2 * 1e3, "Z2": g.z2, "chi": g.chi, "rb_mm": g.rb * 1e3, "power_W": 1500,
           "speed_rpm": 1500, "rolling_friction_mm": mu_mm, "sliding_friction": fs, "model": model})
}

/// Bobillier form of the paper's eqs 19–20 as the spec resolves it (test oracle only): l_MP.
fn l_mp_bobillier(g: &Geometry, w: Wheel, phi: f64) -> f64 {
    let a = g.at(phi);
    let l_o2c = g.r2 / (phi.sin() * a.alpha.tan() - phi.cos());
    let tan_beta = match w {
        Wheel::Cam => l_o2c * phi.sin() / (l_o2c * phi.cos() + g.e),
        Wheel::Crown => l_o2c * phi.sin() / (l_o2c * phi.cos() - g.e),
    };
    let r_w = match w {
        Wheel::Cam => g.r1,
        Wheel::Crown => g.r3,
    };
    r_w / (a.sin_alpha / tan_beta + a.cos_alpha)
}

/// Euler–Savary form: 1/l_MP = 1/L − k_w·L/(r2(1 − χ cos φ)).
fn inv_l_mp_euler_savary(g: &Geometry, w: Wheel, phi: f64) -> f64 {
    let l = g.l(phi);
    let k = match w {
        Wheel::Cam => 1.0 / g.r2 - 1.0 / g.r1,
        Wheel::Crown => 1.0 / g.r2 - 1.0 / g.r3,
    };
    1.0 / l - k * l / (g.r2 * (1.0 - g.chi * phi.cos()))
}

/// 1/l_MP from the closed form: l_MP = L − ρt_cam (cam), l_MP = L + ρt_crown (crown). Computed through the
/// path curvature κt = r2²D/L³ so it stays finite at D = 0: 1/l_MP = κt/(L·κt − 1) (cam),
/// κt/(L·κt + 1) (crown).
fn inv_l_mp_closed(g: &Geometry, w: Wheel, phi: f64) -> f64 {
    let t = Trig::of(phi);
    let l = g.l(phi);
    let kt = g.r2 * g.r2 * g.d(w, &t) / (l * l * l);
    match w {
        Wheel::Cam => kt / (l * kt - 1.0),
        Wheel::Crown => kt / (l * kt + 1.0),
    }
}

proptest! {
    #![proptest_config(config())]

    /// r2 − r1 = r3 − r2 = e; L(0) = r2(χ−1), L(π) = r2(χ+1); α(0) = π, α(π) = 0, α = π/2 at cos φ = 1/χ.
    #[test]
    fn geometry_end_values(g in design()) {
        prop_assert!(rel(g.r2 - g.r1, g.e) < 1e-12);
        prop_assert!(rel(g.r3 - g.r2, g.e) < 1e-12);
        prop_assert!(rel(g.l(0.0), g.r2 * (g.chi - 1.0)) < 1e-12);
        prop_assert!(rel(g.l(PI), g.r2 * (g.chi + 1.0)) < 1e-15);
        prop_assert!((g.at(0.0).alpha - PI).abs() < 1e-15);
        prop_assert!(g.at(PI).alpha.abs() < 1e-15);
        prop_assert!((g.at((1.0 / g.chi).acos()).alpha - PI / 2.0).abs() < 1e-12);
    }

    /// Closed-form end values of ρt (irefc_geometry "Closed-form end values").
    #[test]
    fn rho_t_end_values(g in design()) {
        let (r2, c, z) = (g.r2, g.chi, g.z2f);
        prop_assert!(rel(g.rho_t(Wheel::Cam, 0.0), r2 * (c - 1.0).powi(2) / (c - z)) < 1e-10);
        prop_assert!(rel(g.rho_t(Wheel::Cam, PI), r2 * (c + 1.0).powi(2) / (c + z)) < 1e-12);
        prop_assert!(rel(g.rho_t(Wheel::Crown, 0.0), -r2 * (c - 1.0).powi(2) / (c + z)) < 1e-10);
        prop_assert!(rel(g.rho_t(Wheel::Crown, PI), r2 * (c + 1.0).powi(2) / (z - c)) < 1e-12);
    }

    /// Bobillier = Euler–Savary = closed form (1e-10) for 1/l_MP, scaled by 1/L, away from the Bobillier
    /// construction's own singular points (tan α = ∞, l_O2C = ∞ or 0).
    #[test]
    fn curvature_three_forms_agree(g in design(), phi in 0.01f64..3.13) {
        let a = g.at(phi);
        prop_assume!(a.cos_alpha.abs() > 1e-3);
        prop_assume!((phi.sin() * a.alpha.tan() - phi.cos()).abs() > 1e-3);
        for w in [Wheel::Cam, Wheel::Crown] {
            let closed = inv_l_mp_closed(&g, w, phi);
            let es = inv_l_mp_euler_savary(&g, w, phi);
            let bob = 1.0 / l_mp_bobillier(&g, w, phi);
            let scale = 1.0 / a.l + closed.abs();
            prop_assert!((es - closed).abs() <= 1e-10 * scale, "{w:?} ES {es} closed {closed}");
            prop_assert!((bob - closed).abs() <= 1e-10 * scale, "{w:?} Bobillier {bob} closed {closed}");
        }
    }

    /// κ_w is continuous across D_w = 0 (inflection): κ ≈ 0 there, no jump, ρ reported as None only when
    /// κ is exactly 0.
    #[test]
    fn curvature_continuous_at_inflection(g in design()) {
        for (w, num, den) in [
            (Wheel::Cam, g.z2f + g.chi * g.chi, (g.z2f + 1.0) * g.chi),
            (Wheel::Crown, g.z2f - g.chi * g.chi, (g.z2f - 1.0) * g.chi),
        ] {
            let c0 = num / den;
            if !(-0.999..=0.999).contains(&c0) {
                continue;
            }
            let phi0 = c0.acos();
            let scale = 1.0 / g.r2;
            let k0 = g.at(phi0).kappa(w);
            prop_assert!(k0.abs() < 1e-9 * scale, "{w:?}: kappa at D = 0 is {k0}");
            // No jump: the difference across D = 0 halves with the distance (linear, not a step).
            let jump = |d: f64| g.at(phi0 + d).kappa(w) - g.at(phi0 - d).kappa(w);
            let (j1, j2) = (jump(1e-7), jump(2e-7));
            prop_assert!(j1.is_finite() && j2.is_finite());
            prop_assert!((j1 - 0.5 * j2).abs() <= 1e-3 * j2.abs() + 1e-9 * scale, "{w:?}: jumps {j1}, {j2}");
        }
    }

    /// Undercut closed form = dense scan of ρt over [0, π] (1e-7), the scan polished by golden section.
    #[test]
    fn undercut_closed_form_matches_scan(z2 in 3u32..=80, chi in 1.02f64..3.0) {
        let g = Geometry::new_unchecked(0.02, z2, chi, 1e-4);
        for (w, want) in [(Wheel::Cam, Some(g.rho_t_min_cam)), (Wheel::Crown, g.rho_t_min_crown)] {
            let n = 20_000;
            let rho = |phi: f64| g.rho_t(w, phi);
            let mut best: Option<(usize, f64)> = None;
            for j in 0..=n {
                let v = rho(PI * j as f64 / n as f64);
                if v > 0.0 && best.is_none_or(|(_, b)| v < b) {
                    best = Some((j, v));
                }
            }
            match (best, want) {
                (None, None) => {}
                (Some((j, _)), Some(want)) => {
                    // Golden-section polish on the bracket around the grid minimum (positive part only).
                    let (mut a, mut b) = (PI * j.saturating_sub(1) as f64 / n as f64, PI * (j + 1).min(n) as f64 / n as f64);
                    let f = |x: f64| { let v = rho(x); if v > 0.0 { v } else { f64::INFINITY } };
                    for _ in 0..200 {
                        let m1 = a + 0.381_966 * (b - a);
                        let m2 = b - 0.381_966 * (b - a);
                        if f(m1) < f(m2) { b = m2 } else { a = m1 }
                    }
                    let scan = f(0.5 * (a + b)).min(f(0.0)).min(f(PI)).min(best.map_or(f64::INFINITY, |x| x.1));
                    prop_assert!(rel(scan, want) < 1e-7, "{w:?}: scan {scan} closed {want}");
                }
                (s, w2) => prop_assert!(false, "{w:?}: scan {s:?} vs closed {w2:?}"),
            }
        }
    }

    /// Profile point sets: |contact − O′| = rb, contact, O′ and P collinear (1e-12), |O′ − P| = L(φ(t)) with
    /// φ = (Z2 ∓ 1)·t folded into [0, π].
    #[test]
    fn profile_points_consistent(g in design(), t in 0.0f64..TAU) {
        for (w, m) in [(Wheel::Cam, g.z2f - 1.0), (Wheel::Crown, g.z2f + 1.0)] {
            let p = g.profile_point(w, t);
            let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
            prop_assert!((d(p.contact, p.centre) - g.rb).abs() <= 1e-12 * g.r2);
            let (u, v) = ([p.centre[0] - p.pitch[0], p.centre[1] - p.pitch[1]], [p.contact[0] - p.pitch[0], p.contact[1] - p.pitch[1]]);
            prop_assert!((u[0] * v[1] - u[1] * v[0]).abs() <= 1e-12 * g.r2 * g.r2 * 10.0);
            let phi = (m * t).rem_euclid(TAU);
            let phi = if phi > PI { TAU - phi } else { phi };
            prop_assert!(rel(d(p.centre, p.pitch), g.l(phi)) < 1e-9);
        }
    }

    /// L and κ are even in φ, sin α is odd.
    #[test]
    fn parity(g in design(), phi in 0.0f64..PI) {
        let (a, b) = (g.at(phi), g.at(-phi));
        prop_assert!(rel(a.l, b.l) < 1e-15);
        prop_assert!((a.kappa_cam - b.kappa_cam).abs() <= 1e-12 * a.kappa_cam.abs().max(1.0 / g.r2));
        prop_assert!((a.kappa_crown - b.kappa_crown).abs() <= 1e-12 * a.kappa_crown.abs().max(1.0 / g.r2));
        prop_assert!((a.sin_alpha + b.sin_alpha).abs() <= 1e-15);
    }

    /// Phase average of Σ sin²α is Z2/4 (∫₀^π sin²α dφ = π/2 for every χ > 1); 2000 midpoint samples, 1e-9.
    #[test]
    fn sum_sin2_phase_average(z2 in 3u32..=60, chi in 1.05f64..3.0) {
        let g = Geometry::new_unchecked(0.02, z2, chi, 1e-4);
        let n = 2000;
        let mean = (0..n).map(|i| g.sum_sin2((i as f64 + 0.5) / n as f64)).sum::<f64>() / n as f64;
        prop_assert!(rel(mean, g.z2f / 4.0) < 1e-9, "mean {mean} vs {}", g.z2f / 4.0);
    }

    /// Force balance Σ F_k·h_k = T_cam (1e-12), F_k ≥ 0, F_0 = 0, F = 0 at φ = π; for any cage phase.
    #[test]
    fn force_balance(g in design(), t in 0.0f64..1e5, p in 0.0f64..1.0) {
        let f = element_forces(&g, t, p);
        let m: f64 = f.elements.iter().map(|e| e.f * e.h).sum();
        prop_assert!((m - t).abs() <= 1e-12 * t.max(1e-300));
        prop_assert!(f.elements.iter().all(|e| e.f >= 0.0));
        let f0 = element_forces(&g, t, 0.0);
        prop_assert!(f0.elements[0].f.abs() < f64::MIN_POSITIVE);
        if g.z2 % 2 == 0 {
            prop_assert!(f0.elements.last().map_or(0.0, |e| e.f).abs() < f64::MIN_POSITIVE);
        }
    }

    /// Hertz: σ equals the textbook line-contact peak pressure p0 = sqrt(P′E*/(πR′)), P′ = F/lb,
    /// 1/R′ = 1/ρ_w + 1/rb (Johnson §4.2), and for equal materials the paper's eq. 18 (1e-12).
    #[test]
    fn hertz_matches_textbook_and_eq18(g in design(), phi in 0.02f64..3.12, lb_over_rb in 0.5f64..5.0) {
        let t_cam = 100.0;
        let (e, nu) = (210e9, 0.3f64);
        let e_star = 1.0 / (2.0 * (1.0 - nu * nu) / e);
        let lb = lb_over_rb * g.rb;
        let f = element_forces(&g, t_cam, 0.0);
        let st = Stresser::new(&g, t_cam, f.fmax, e_star, lb, LoadSharing::PaperPhase0);
        let (s, a) = st.state_at(phi);
        for (w, s2) in [(Wheel::Cam, s.s2_cam), (Wheel::Crown, s.s2_crown)] {
            let Some(rho1) = a.rho(w) else { continue };
            prop_assume!(rho1.abs() < 1e6 * g.r2);
            let rho2 = g.rb;
            let inv_r = 1.0 / rho1 + 1.0 / rho2;
            let p0 = (s.f / lb * e_star * inv_r / PI).sqrt();
            let h = a.h_cam;
            let eq18 = (t_cam * h * e * (rho1 + rho2) / (2.0 * PI * lb * rho1 * rho2 * (1.0 - nu * nu) * f.sum_h2)).sqrt();
            prop_assert!(rel(s2.sqrt(), p0) < 1e-9, "{w:?}: {} vs {p0}", s2.sqrt());
            prop_assert!(rel(s2.sqrt(), eq18) < 1e-9, "{w:?}: {} vs {eq18}", s2.sqrt());
        }
    }

    /// F ∝ T, σ ∝ √T, σ ∝ 1/√lb; scaling r2, rb, lb by s and T by s³ leaves σ and φ2 of the maximum unchanged.
    #[test]
    fn scaling_laws(g in design(), t in 1.0f64..1e4, s in 0.1f64..10.0) {
        let base = single(json!({"r2_mm": g.r2 * 1e3, "Z2": g.z2, "chi": g.chi, "rb_mm": g.rb * 1e3,
            "torque_Nm": t, "lb_mm": g.rb * 2e3, "step_deg": 1}));
        let t4 = single(json!({"r2_mm": g.r2 * 1e3, "Z2": g.z2, "chi": g.chi, "rb_mm": g.rb * 1e3,
            "torque_Nm": 4.0 * t, "lb_mm": g.rb * 2e3, "step_deg": 1}));
        let lb4 = single(json!({"r2_mm": g.r2 * 1e3, "Z2": g.z2, "chi": g.chi, "rb_mm": g.rb * 1e3,
            "torque_Nm": t, "lb_mm": g.rb * 8e3, "step_deg": 1}));
        let sc = single(json!({"r2_mm": s * g.r2 * 1e3, "Z2": g.z2, "chi": g.chi, "rb_mm": s * g.rb * 1e3,
            "torque_Nm": t * s * s * s, "lb_mm": s * g.rb * 2e3, "step_deg": 1}));
        prop_assert!(rel(t4.fmax_n, 4.0 * base.fmax_n) < 1e-12);
        for (a, b4, l4, c) in [
            (&base.max.cam, &t4.max.cam, &lb4.max.cam, &sc.max.cam),
            (&base.max.crown, &t4.max.crown, &lb4.max.crown, &sc.max.crown),
        ] {
            prop_assert!(rel(b4.sigma_mpa, 2.0 * a.sigma_mpa) < 1e-12);
            prop_assert!(rel(l4.sigma_mpa, 0.5 * a.sigma_mpa) < 1e-12);
            prop_assert!(rel(c.sigma_mpa, a.sigma_mpa) < 1e-10, "{} vs {}", c.sigma_mpa, a.sigma_mpa);
            // The maximum's location is conditioned like sqrt(eps): on a flat maximum the round-off
            // of the scaled design moves the refined argmax by up to ~3e-7 rad (found: Z2 = 14,
            // chi = 2.557, s = 0.1: 1.8e-5 deg) while sigma passes the 1e-10 check. 1e-3 deg still tells a
            // different bump or a wrongly scaled angle (grid step 1 deg).
            let (pa, pc) = (a.phi2_deg.unwrap_or(-1.0), c.phi2_deg.unwrap_or(-2.0));
            prop_assert!((pa - pc).abs() < 1e-3, "phi2 {pa} vs {pc}");
        }
    }

    /// Swapping wheel and roller materials leaves σ unchanged; crown output with T equals cam output with
    /// T·(Z2−1)/(Z2+1).
    #[test]
    fn materials_symmetric_and_output_link(g in design(), e1 in 1e4f64..1e6, e2 in 1e4f64..1e6, n1 in 0.0f64..0.49, n2 in 0.0f64..0.49) {
        let mut a = stress_req(&g, 50.0);
        a["wheel_material"] = json!({"E_MPa": e1, "nu": n1});
        a["roller_material"] = json!({"E_MPa": e2, "nu": n2});
        let mut b = stress_req(&g, 50.0);
        b["wheel_material"] = json!({"E_MPa": e2, "nu": n2});
        b["roller_material"] = json!({"E_MPa": e1, "nu": n1});
        let (ra, rb) = (single(a), single(b));
        prop_assert!(rel(ra.max.cam.sigma_mpa, rb.max.cam.sigma_mpa) < 1e-12);
        prop_assert!(rel(ra.max.crown.sigma_mpa, rb.max.crown.sigma_mpa) < 1e-12);

        let mut c = stress_req(&g, 50.0);
        c["output_link"] = json!("crown");
        let d = stress_req(&g, 50.0 * (g.z2f - 1.0) / (g.z2f + 1.0));
        let (rc, rd) = (single(c), single(d));
        prop_assert!(rel(rc.t_cam_nm, rd.t_cam_nm) < 1e-15);
        prop_assert!(rel(rc.max.cam.sigma_mpa, rd.max.cam.sigma_mpa) < 1e-15);
        prop_assert!(rel(rc.max.crown.sigma_mpa, rd.max.crown.sigma_mpa) < 1e-15);
        prop_assert!(rel(rc.t_in_nm, rd.t_in_nm) < 1e-14);
    }

    /// Grid vs refine: the refined maximum is ≥ the grid maximum and equals the maximum found with a fine
    /// grid (0.05° + refine) to 1e-9, in both load-sharing modes. In "paper_phase0" (one bump per wheel) it
    /// also lies within one step of the grid maximum; in "phase_exact" the curve can have several bumps
    /// and a coarse grid may rank them wrongly (regression: Z2 = 9, step 2.93°), so only the value is
    /// compared there.
    #[test]
    fn refine_never_worse(g in design(), step in 0.3f64..5.0, exact in any::<bool>()) {
        let mode = if exact { "phase_exact" } else { "paper_phase0" };
        let mut a = stress_req(&g, 80.0);
        a["step_deg"] = json!(step);
        a["load_sharing"] = json!(mode);
        a["refine"] = json!(false);
        let mut b = a.clone();
        b["refine"] = json!(true);
        let mut c = b.clone();
        c["step_deg"] = json!(0.05);
        let (ra, rb, rc) = (single(a), single(b), single(c));
        let n = (180.0 / step).round();
        let h = 180.0 / n;
        for (x, y, z) in [
            (&ra.max.cam, &rb.max.cam, &rc.max.cam),
            (&ra.max.crown, &rb.max.crown, &rc.max.crown),
        ] {
            prop_assert!(y.sigma_mpa >= x.sigma_mpa);
            prop_assert!(rel(y.sigma_mpa, z.sigma_mpa) < 1e-9, "{} vs fine {}", y.sigma_mpa, z.sigma_mpa);
            if !exact {
                let (px, py) = (x.phi2_deg.unwrap_or(0.0), y.phi2_deg.unwrap_or(0.0));
                prop_assert!((px - py).abs() <= h * (1.0 + 1e-9), "{px} vs {py}, step {h}");
            }
        }
    }

    /// Efficiency: NS = NSA + NSB; R = 0 → NS = 0; paper Vs = 4ω1(L − Z2·rb)/(Z2(Z2²−1)); Vs changes sign
    /// where L = Z2·rb in every model; Vs_paper/vs_rigid = −2/(Z2+1); "paper_abs" ≥ "paper_table".
    #[test]
    fn efficiency_kinematics(g in design(), mu in 0.0f64..2.0, fs in 0.0f64..0.5) {
        let pt = eff(eff_req(&g, "paper_table", mu, fs));
        let pa = eff(eff_req(&g, "paper_abs", mu, fs));
        let rb = eff(eff_req(&g, "rigid_body", mu, fs));
        let w1 = pt.omega1_rad_s;
        let z = g.z2f;
        let (et, ea, er) = (pt.elements.expect("on"), pa.elements.expect("on"), rb.elements.expect("on"));
        for ((t, a), r) in et.iter().zip(&ea).zip(&er) {
            for e in [t, a, r] {
                prop_assert!((e.ns_w - (e.nsa_w + e.nsb_w)).abs() <= 1e-12 * e.ns_w.abs().max(1e-300));
                if e.r_n.abs() < f64::MIN_POSITIVE { prop_assert!(e.ns_w.abs() < f64::MIN_POSITIVE); }
            }
            let l = t.l_mm / 1e3;
            let closed = 4.0 * w1 * (l - z * g.rb) / (z * (z * z - 1.0));
            // 1e-15 absolute at the spec's scale; in general relative to the terms V12, V23 that cancel.
            let scale = 2.0 * w1 * (l + g.rb) / (z * (z - 1.0));
            prop_assert!((t.vs_m_s - closed).abs() <= 1e-14 * scale);
            let d = l - z * g.rb;
            if d.abs() > 1e-9 * g.r2 {
                prop_assert_eq!(t.vs_m_s > 0.0, d > 0.0);
                prop_assert_eq!(r.vs_m_s > 0.0, d < 0.0);
                // Both speeds are ∝ d and carry the absolute error checked above (1e-14 · scale):
                // relative to |Vs| that is 1e-14 (l + rb)(Z2 + 1)/(2|d|) each, which dominates near
                // the sign change (found: Z2 = 43, seed 13, close to L = Z2 rb).
                let cond = 1e-14 * (l + g.rb) * (z + 1.0) / d.abs();
                prop_assert!(rel(t.vs_m_s / r.vs_m_s, -2.0 / (z + 1.0)) < 1e-9 + cond,
                    "ratio off by {} (allowed {})", rel(t.vs_m_s / r.vs_m_s, -2.0 / (z + 1.0)), 1e-9 + cond);
            }
            prop_assert!(a.ns_w >= t.ns_w - 1e-12 * t.ns_w.abs());
        }
    }

    /// η ≤ 1 in the physical model (rigid_body) for every μ, f_s ≥ 0, per element and in total; η is
    /// independent of power and speed (every model); scaling r2, rb, μ together leaves η unchanged.
    #[test]
    fn efficiency_bounds_and_invariance(g in design(), mu in 0.0f64..2.0, fs in 0.0f64..1.0,
                                        p in 1.0f64..1e6, n in 1.0f64..1e5, s in 0.2f64..5.0) {
        let r = eff(eff_req(&g, "rigid_body", mu, fs));
        prop_assert!(r.totals.eta_linear <= 1.0);
        prop_assert!(r.totals.eta_product.is_none_or(|e| e <= 1.0));
        prop_assert!(r.elements.as_ref().expect("on").iter().all(|e| e.eta_k <= 1.0 && e.ns_w >= 0.0));
        for model in ["paper_table", "paper_abs", "rigid_body"] {
            let a = eff(eff_req(&g, model, mu, fs));
            let mut v = eff_req(&g, model, mu, fs);
            v["power_W"] = json!(p);
            v["speed_rpm"] = json!(n);
            let b = eff(v);
            prop_assert!((a.totals.eta_linear - b.totals.eta_linear).abs() < 1e-12);
            let mut w = eff_req(&g, model, mu * s, fs);
            w["r2_mm"] = json!(g.r2 * 1e3 * s);
            w["rb_mm"] = json!(g.rb * 1e3 * s);
            let c = eff(w);
            prop_assert!((a.totals.eta_linear - c.totals.eta_linear).abs() < 1e-12);
        }
    }

    /// μ = f_s = 0 → η = 1 in "paper_abs" and "rigid_body"; in "paper_table" μ = 0, f_s > 0 gives negative
    /// losses wherever Vs < 0, flagged `NEGATIVE_LOSS`.
    #[test]
    fn efficiency_frictionless(g in design(), fs in 0.01f64..1.0) {
        for model in ["paper_abs", "rigid_body"] {
            let r = eff(eff_req(&g, model, 0.0, 0.0));
            prop_assert!((r.totals.eta_linear - 1.0).abs() < f64::EPSILON);
            prop_assert!(r.totals.eta_product.is_some_and(|e| (e - 1.0).abs() < f64::EPSILON));
        }
        let r = eff(eff_req(&g, "paper_table", 0.0, fs));
        let neg = r.elements.as_ref().expect("on").iter().any(|e| e.ns_w < 0.0);
        prop_assert_eq!(neg, r.warnings.iter().any(|w| w.code == "NEGATIVE_LOSS"));
    }
}

/// In the E1 geometry, "paper_table" with μ = 0, f_s = 0.1 gives η = 1.00045 (> 1) and warns.
#[test]
fn paper_table_frictionless_rolling_exceeds_one() {
    let g = Geometry::new_unchecked(0.02, 26, 1.4, 0.002);
    let r = eff(eff_req(&g, "paper_table", 0.0, 0.1));
    let e = r.totals.eta_product.expect("positive");
    assert!((e - 1.00045).abs() <= 5e-6, "{e}");
    assert!(r.warnings.iter().any(|w| w.code == "NEGATIVE_LOSS"));
}

/// Closed-form curvature vs finite differences of the generated profile (spec: ~2e-6 relative, limited by
/// the FD step). Central differences of the parametric contact curve A(t)/B(t) with step h = 1e-5 rad.
#[test]
fn curvature_matches_profile_finite_differences() {
    let mut worst: f64 = 0.0;
    for (z2, chi, rb_frac) in [
        (26u32, 1.4, 0.5),
        (10, 1.25, 0.3),
        (7, 1.67, 0.6),
        (40, 1.3, 0.4),
        (12, 2.0, 0.7),
    ] {
        let g0 = Geometry::new_unchecked(0.02, z2, chi, 1e-3);
        let g = Geometry::new_unchecked(0.02, z2, chi, rb_frac * g0.rb_overlap.min(g0.rb_undercut));
        for (w, m) in [(Wheel::Cam, g.z2f - 1.0), (Wheel::Crown, g.z2f + 1.0)] {
            // Parameters t whose φ = m·t runs over (0, π): t = φ/m.
            for i in 1..60 {
                let phi = PI * f64::from(i) / 60.0;
                let t = phi / m;
                let h = 1e-5;
                let p = |t: f64| g.profile_point(w, t).contact;
                let (a, b, c) = (p(t - h), p(t), p(t + h));
                let d1 = [(c[0] - a[0]) / (2.0 * h), (c[1] - a[1]) / (2.0 * h)];
                let d2 = [
                    (c[0] - 2.0 * b[0] + a[0]) / (h * h),
                    (c[1] - 2.0 * b[1] + a[1]) / (h * h),
                ];
                let kfd = (d1[0] * d2[1] - d1[1] * d2[0]) / d1[0].hypot(d1[1]).powi(3);
                let k = g.at(phi).kappa(w);
                // Orientation: the curves run clockwise around material for the cam (convex = negative
                // signed FD curvature) — compare |κ| and require the sign relation to be the same everywhere.
                let scale = k.abs().max(1.0 / g.r2);
                let err = (kfd.abs() - k.abs()).abs() / scale;
                worst = worst.max(err);
                assert!(
                    err < 1e-4,
                    "{w:?} Z2={z2} chi={chi} phi={phi}: FD {kfd} closed {k}"
                );
                if k.abs() > 0.05 / g.r2 {
                    let sign = match w {
                        Wheel::Cam => 1.0,
                        Wheel::Crown => -1.0,
                    };
                    assert_eq!(kfd * sign > 0.0, k > 0.0, "{w:?} sign at phi={phi}");
                }
            }
        }
    }
    eprintln!("worst relative FD curvature error: {worst:e}");
}

/// Grid convergence (irefc_stress.md): |σ_grid − σ_refined| decreases ~ step² — halving the step three times
/// (2° → 0.25°) shrinks the worst error over a few designs by well over 10 (ideal 64).
#[test]
fn grid_error_decreases_like_step_squared() {
    let designs = [(10u32, 1.25), (18, 1.42), (26, 1.5), (40, 1.67)];
    let err = |step: f64| {
        designs
            .iter()
            .map(|&(z2, chi)| {
                let g = Geometry::new_unchecked(0.02, z2, chi, 0.002);
                let mut v = stress_req(&g, 100.0);
                v["step_deg"] = json!(step);
                v["refine"] = json!(false);
                let a = single(v.clone());
                v["refine"] = json!(true);
                let b = single(v);
                rel(a.max.cam.sigma_mpa, b.max.cam.sigma_mpa)
                    .max(rel(a.max.crown.sigma_mpa, b.max.crown.sigma_mpa))
            })
            .fold(0.0, f64::max)
    };
    let (e2, e1, e05, e025) = (err(2.0), err(1.0), err(0.5), err(0.25));
    eprintln!("grid errors: {e2:e} {e1:e} {e05:e} {e025:e}");
    assert!(e2 > e025 * 10.0, "{e2} vs {e025}");
    assert!(e2 >= e1 && e1 >= e025);
}
