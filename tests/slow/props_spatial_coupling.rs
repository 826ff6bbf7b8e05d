//! Property tests of the spatial-coupling spec (§6 "Property tests"; the identities,
//! symmetry in the shaft angle, periodicity in θ1), on inputs that include the hazards of §7
//! (|cos 2α| down to 0.05, support planes down to min|D|/max|D| = 1e-3, both assembly modes).
//!
//! Where the spec is unqualified and its sections disagree, the deciding property is tested:
//! §6 says ∫₀^{2π} i12 dθ1 = −2π, §3.2 gives i12 = −cos 2α/(…), whose mean is −sign(cos 2α) —
//! +1 for |α| > 45° (admitted by §2). The test checks −2π·sign(cos 2α) and the unwrapped output
//! turning once per input turn in that sense.

#![allow(
    clippy::suboptimal_flops,
    reason = "test arithmetic follows the spec's formulas; mul_add gains nothing here"
)]

use proptest::prelude::*;
use serde_json::{Value, json};

use crate::support::proptest_cfg::cases;
use crate::support::spatial_coupling::{
    Differences, answer, closure_residual, cross, dang, dot, fd_error, num, sub, v3,
};

/// α with |cos 2α| ≥ 0.05 (either side of 45°), β giving a valid plane with min|D|/max|D| ≥ 1e-3.
fn config() -> impl Strategy<Value = (f64, f64, f64, i64)> {
    (
        -89.0f64..89.0,
        -89.9f64..90.0,
        -3.0f64..3.0,
        prop::bool::ANY,
    )
        .prop_filter(
            "valid, well-conditioned configuration",
            |&(alpha, beta, _, _)| {
                let c2a = (2.0 * alpha).to_radians().cos();
                let d0 = (alpha - beta).to_radians().cos() * c2a;
                let d90 = (alpha + beta).to_radians().cos();
                c2a.abs() >= 0.05
                    && d0 * d90 > 0.0
                    && d0.abs().min(d90.abs()) >= 1e-3 * d0.abs().max(d90.abs())
            },
        )
        .prop_map(|(alpha, beta, la, s)| (alpha, beta, 10f64.powf(la), if s { 1 } else { -1 }))
}

fn all(alpha: f64, beta: f64, a: f64, sigma: i64, thetas: &[f64]) -> Vec<Value> {
    answer(json!({
        "alpha_deg": alpha, "beta_deg": beta, "a_m": a, "branch": sigma, "theta1_deg": thetas,
        "outputs": {"contact": true, "relative_1": true, "relative_2": true, "frames": true, "check": true},
        "body3_points_m": [[0.2 * a, 0.1 * a, -0.4 * a]]
    }))["points"]
        .as_array()
        .expect("points")
        .clone()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1.0)
}

proptest! {
    #![proptest_config(cases(64))]

    /// Closure residuals (spec §5 `check` and the independent seven equations) < 1e-12.
    #[test]
    fn closure_holds((alpha, beta, a, sigma) in config(), t in -1e4f64..1e4) {
        let p = &all(alpha, beta, a, sigma, &[t])[0];
        prop_assert!(num(&p["check"]["max_residual"]) < 1e-12, "{}", p["check"]);
        let r = closure_residual(alpha, beta, a, p);
        prop_assert!(r < 1e-12, "independent closure residual {r:e}");
    }

    /// i12(θ1 + π) = i12(θ1), i12(−θ1) = i12(θ1); all outputs periodic in θ1 with period 360°.
    #[test]
    fn ratio_symmetry_and_periodicity((alpha, beta, a, sigma) in config(), t in -360f64..360.0, k in -1000i32..1000) {
        let shifted = t + 360.0 * f64::from(k);
        let p = all(alpha, beta, a, sigma, &[t, t + 180.0, -t, shifted]);
        let i = |j: usize| num(&p[j]["i12"]);
        prop_assert!(rel(i(1), i(0)) < 1e-12 && rel(i(2), i(0)) < 1e-12, "{} {} {}", i(0), i(1), i(2));
        // θ1 + 360k carries the rounding of the sum (ulp(360·1000) ≈ 6e-11°).
        let tol = 1e-9;
        prop_assert!(dang(num(&p[3]["theta2_deg"]), num(&p[0]["theta2_deg"])).abs() < tol);
        for g in [("relative_1", "theta31_deg"), ("relative_2", "theta32_deg")] {
            prop_assert!(dang(num(&p[3][g.0][g.1]), num(&p[0][g.0][g.1])).abs() < tol);
        }
        // rB: the rounding of θ1 + 360k (≈ 1e-12 rad) times |drB/dθ1| (up to ~1e6·a near min|D|).
        for (x, y) in v3(&p[3]["contact"]["rB_m"]).into_iter().zip(v3(&p[0]["contact"]["rB_m"])) {
            prop_assert!((x - y).abs() <= 1e-6 * a, "rB periodic: {x} {y}");
        }
    }

    /// θ2 is the Cardan output with bend 2α and input 90° − θ1 (σ = +1; σ = −1 adds 180°).
    #[test]
    fn cardan_equivalence((alpha, beta, a, sigma) in config(), t in -720f64..720.0) {
        let p = &all(alpha, beta, a, sigma, &[t])[0];
        let c2a = (2.0 * alpha).to_radians().cos();
        let u = (90.0 - t).to_radians();
        let mut cardan = (c2a * u.sin()).atan2(u.cos()).to_degrees();
        if sigma < 0 {
            cardan += 180.0;
        }
        prop_assert!(dang(num(&p["theta2_deg"]), cardan).abs() < 1e-9);
        // tan θ1 · tan θ2 = cos 2α (the closure condition) away from the poles.
        let (t1, t2) = (t.to_radians(), num(&p["theta2_deg"]).to_radians());
        if t1.cos().abs() > 0.1 && t2.cos().abs() > 0.1 {
            prop_assert!((t1.tan() * t2.tan() - c2a).abs() < 1e-9);
        }
    }

    /// Symmetry in the shaft angle: (α, β) → (−α, −β) mirrors the mechanism in y. i12, θ2 and the
    /// B-distances are unchanged; yB, z1B, z2B and the relative rotations change sign.
    #[test]
    fn mirror_symmetry_in_the_shaft_angle((alpha, beta, a, sigma) in config(), t in -360f64..360.0) {
        let p = &all(alpha, beta, a, sigma, &[t])[0];
        let m = &all(-alpha, -beta, a, sigma, &[t])[0];
        prop_assert!(rel(num(&m["i12"]), num(&p["i12"])) < 1e-12);
        prop_assert!(dang(num(&m["theta2_deg"]), num(&p["theta2_deg"])).abs() < 1e-9);
        let (rp, rm) = (v3(&p["contact"]["rB_m"]), v3(&m["contact"]["rB_m"]));
        let scale = a.max(dot(rp, rp).sqrt());
        prop_assert!((rm[0] - rp[0]).abs() <= 1e-12 * scale && (rm[1] + rp[1]).abs() <= 1e-12 * scale && (rm[2] - rp[2]).abs() <= 1e-12 * scale, "{rp:?} {rm:?}");
        for (g, x, z, th) in [("relative_1", "x1B_m", "z1B_m", "theta31_deg"), ("relative_2", "x2B_m", "z2B_m", "theta32_deg")] {
            prop_assert!((num(&m[g][x]) - num(&p[g][x])).abs() <= 1e-12 * scale);
            prop_assert!((num(&m[g][z]) + num(&p[g][z])).abs() <= 1e-12 * scale);
            prop_assert!(dang(num(&m[g][th]), -num(&p[g][th])).abs() < 1e-9);
        }
    }

    /// Lengths scale with a; angles and ratios do not depend on a; β changes only B-related outputs.
    #[test]
    fn scaling_and_beta_independence((alpha, beta, a, sigma) in config(), t in -360f64..360.0, f in -3.0f64..3.0) {
        let k = 10f64.powf(f);
        let p = &all(alpha, beta, a, sigma, &[t])[0];
        let q = &all(alpha, beta, a * k, sigma, &[t])[0];
        prop_assert!(rel(num(&q["i12"]), num(&p["i12"])) < 1e-12);
        let scale = a.max(dot(v3(&p["contact"]["rB_m"]), v3(&p["contact"]["rB_m"])).sqrt());
        for j in 0..3 {
            prop_assert!((num(&q["contact"]["rB_m"][j]) - k * num(&p["contact"]["rB_m"][j])).abs() <= 1e-12 * k * scale);
        }
        prop_assert!(dang(num(&q["relative_1"]["theta31_deg"]), num(&p["relative_1"]["theta31_deg"])).abs() < 1e-9);
        // Another β (still valid): θ2, i12, θ31, ω31, θ32, ω32 unchanged.
        let o = answer(json!({"alpha_deg": alpha, "beta_deg": alpha, "a_m": a, "branch": sigma, "theta1_deg": [t],
                              "outputs": {"relative_1": true, "relative_2": true}}))["points"][0].clone();
        prop_assert!(rel(num(&o["i12"]), num(&p["i12"])) < 1e-12);
        prop_assert!(dang(num(&o["theta2_deg"]), num(&p["theta2_deg"])).abs() < 1e-9);
        for (g, th, w) in [("relative_1", "theta31_deg", "omega31_rad_s"), ("relative_2", "theta32_deg", "omega32_rad_s")] {
            prop_assert!(dang(num(&o[g][th]), num(&p[g][th])).abs() < 1e-9);
            prop_assert!(rel(num(&o[g][w]), num(&p[g][w])) < 1e-12);
        }
    }

    /// β = α: |rB| = a, |vB| = 2aω1, z1B = 0. β = −α: |rB| = a, z2B = 0, |vB| = 2a|i12|ω1.
    #[test]
    fn special_support_planes(alpha in -80f64..80.0, t in -360f64..360.0, la in -3.0f64..3.0, w in -100f64..100.0, s in prop::bool::ANY) {
        prop_assume!((2.0 * alpha).to_radians().cos().abs() >= 0.05);
        let a = 10f64.powf(la);
        let sigma = if s { 1 } else { -1 };
        let q = |beta: f64| answer(json!({"alpha_deg": alpha, "beta_deg": beta, "a_m": a, "branch": sigma,
            "omega1_rad_s": w, "theta1_deg": [t], "outputs": {"contact": true, "relative_1": true, "relative_2": true}}))["points"][0].clone();
        let p = q(alpha);
        let r = v3(&p["contact"]["rB_m"]);
        prop_assert!(rel(dot(r, r).sqrt(), a) < 1e-12 || (dot(r, r).sqrt() - a).abs() < 1e-12 * a);
        prop_assert!((num(&p["contact"]["vB_mag"]) - 2.0 * a * w.abs()).abs() <= 1e-12 * a * w.abs().max(1.0));
        prop_assert!(num(&p["relative_1"]["z1B_m"]).abs() <= 1e-12 * a);
        let m = q(-alpha);
        let r = v3(&m["contact"]["rB_m"]);
        prop_assert!((dot(r, r).sqrt() - a).abs() <= 1e-12 * a);
        prop_assert!(num(&m["relative_2"]["z2B_m"]).abs() <= 1e-12 * a);
        let want = 2.0 * a * num(&m["i12"]).abs() * w.abs();
        prop_assert!((num(&m["contact"]["vB_mag"]) - want).abs() <= 1e-12 * want.max(a));
    }

    /// The absolute angular velocity of body 3 by both chains agrees:
    /// ω1 k1 + ω31 j1 = ω2 k2 + ω32 j2 (checked through the returned body-point velocity).
    #[test]
    fn body3_angular_velocity_both_chains((alpha, beta, a, sigma) in config(), t in -360f64..360.0) {
        let p = &all(alpha, beta, a, sigma, &[t])[0];
        let f = &p["frames"];
        let w2 = num(&p["omega2_rad_s"]);
        let w32 = num(&p["relative_2"]["omega32_rad_s"]);
        let omega = [0, 1, 2].map(|k| w2 * num(&f["k2"][k]) + w32 * num(&f["j2"][k]));
        let b = &p["body3_points"][0];
        let q = sub(v3(&b["r0_m"]), v3(&p["contact"]["rB_m"]));
        let want = cross(omega, q);
        let got = sub(v3(&b["v0_m_s"]), v3(&p["contact"]["vB_m_s"]));
        let scale = dot(omega, omega).sqrt() * dot(q, q).sqrt() + 1e-300;
        for k in 0..3 {
            prop_assert!((got[k] - want[k]).abs() <= 1e-12 * scale.max(a), "{got:?} {want:?}");
        }
    }

    /// Analytic rates against central differences of the returned positions (h = 1e-5 rad and
    /// h/2, Richardson-extrapolated: the sampled configurations reach min|D|/max|D| = 1e-3, where
    /// the plain difference's own truncation error passes the bound).
    #[test]
    fn derivatives_match_central_differences((alpha, beta, a, sigma) in config(), t in -360f64..360.0) {
        let e = fd_error((alpha, beta, a, sigma), t, 1.0, Differences::Extrapolated);
        prop_assert!(e < 1e-6, "FD error {e:e}");
    }

    /// Sweep vs points: the unwrapped series equals the single points modulo 360°, θ2 is
    /// continuous (steps ≈ i12·Δθ1), and θ2(end) − θ2(start) = −sign(cos 2α)·(end − start) over
    /// whole revolutions; ∫ i12 dθ1 over a revolution = −2π·sign(cos 2α).
    #[test]
    fn sweep_unwraps_and_integrates((alpha, beta, a, sigma) in config(), start in -720f64..720.0, turns in 1u32..3) {
        let c2a = (2.0 * alpha).to_radians().cos();
        prop_assume!(c2a.abs() >= 0.3);
        let n = 1200 * turns as usize + 1;
        let end = start + 360.0 * f64::from(turns);
        let s = answer(json!({"alpha_deg": alpha, "beta_deg": beta, "a_m": a, "branch": sigma,
            "sweep": {"start_deg": start, "end_deg": end, "n_points": n},
            "outputs": {"series": true, "relative_1": true, "relative_2": true}}));
        let series = s["series"].as_array().expect("series");
        prop_assert_eq!(series.len(), n);
        let th2: Vec<f64> = series.iter().map(|p| num(&p["theta2_deg"])).collect();
        prop_assert!((0.0..360.0).contains(&th2[0]));
        let sign = c2a.signum();
        prop_assert!(((th2[n - 1] - th2[0]) + sign * 360.0 * f64::from(turns)).abs() < 1e-9);
        let i12: Vec<f64> = series.iter().map(|p| num(&p["i12"])).collect();
        let step = (end - start) / (n - 1) as f64;
        for k in 1..n {
            let d = th2[k] - th2[k - 1];
            prop_assert!((d - 0.5 * (i12[k] + i12[k - 1]) * step).abs() < 0.05 * step.abs(), "jump at {k}: {d}");
        }
        // Trapezoid over whole periods of a smooth periodic function: spectrally accurate.
        let h = step.to_radians();
        let integral: f64 = (1..n).map(|k| 0.5 * (i12[k] + i12[k - 1]) * h).sum();
        prop_assert!((integral + sign * std::f64::consts::TAU * f64::from(turns)).abs() < 1e-9 * f64::from(turns), "∫ i12 = {integral}");
        let pts = answer(json!({"alpha_deg": alpha, "beta_deg": beta, "a_m": a, "branch": sigma,
            "theta1_deg": [num(&series[n / 3]["theta1_deg"])], "outputs": {"relative_1": true, "relative_2": true}}))["points"][0].clone();
        let sp = &series[n / 3];
        prop_assert!(dang(num(&sp["theta2_deg"]), num(&pts["theta2_deg"])).abs() < 1e-9);
        prop_assert!(dang(num(&sp["relative_1"]["theta31_deg"]), num(&pts["relative_1"]["theta31_deg"])).abs() < 1e-9);
        prop_assert!(dang(num(&sp["relative_2"]["theta32_deg"]), num(&pts["relative_2"]["theta32_deg"])).abs() < 1e-9);
        // Amplitudes of §3.5: 2|α| below 45°, 180° − 2|α| above.
        let amp = if alpha.abs() < 45.0 { 2.0 * alpha.abs() } else { 180.0 - 2.0 * alpha.abs() };
        prop_assert!((num(&s["summary"]["theta31_amplitude_deg"]) - amp).abs() < 1e-3);
        prop_assert!((num(&s["summary"]["theta32_amplitude_deg"]) - amp).abs() < 1e-3);
    }

    /// α → 0: i12 → −1, θ31 → 0, θ32 − 180° → 0, z2B → 0 (parallel shafts, homokinetic).
    #[test]
    fn small_alpha_limit(le in -12.0f64..-2.0, t in -360f64..360.0) {
        let alpha = 10f64.powf(le);
        let p = &all(alpha, alpha, 1.0, 1, &[t])[0];
        let x = alpha.to_radians();
        prop_assert!((num(&p["i12"]) + 1.0).abs() <= 10.0 * x * x + 1e-15);
        prop_assert!(dang(num(&p["relative_1"]["theta31_deg"]), 0.0).abs() <= 3.0 * alpha);
        prop_assert!(dang(num(&p["relative_2"]["theta32_deg"]), 180.0).abs() <= 3.0 * alpha);
        prop_assert!(num(&p["relative_2"]["z2B_m"]).abs() <= 3.0 * x);
    }
}

/// α = 0 exactly: homokinetic, i12 ≡ −1.
#[test]
fn alpha_zero_is_homokinetic() {
    let b = answer(json!({"alpha_deg": 0, "sweep": {"n_points": 101}}));
    assert_eq!(b["configuration"]["homokinetic"], true);
    assert_eq!(b["summary"]["homokinetic"], true);
    assert!((num(&b["summary"]["i12_min"]) + 1.0).abs() < 1e-15);
    assert!((num(&b["summary"]["i12_max"]) + 1.0).abs() < 1e-15);
    assert!(num(&b["summary"]["fluctuation"]).abs() < 1e-15);
}
