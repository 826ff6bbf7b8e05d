//! Stress tests near every hazard of the spatial-coupling spec §7: perpendicular shafts
//! (|cos 2α| → 1e-9), support planes at and near the validity boundary and points at and next to
//! the roots of D, exact and near multiples of 90°, huge input angles and sweeps over huge ranges,
//! extreme lengths and speeds, α → ±90°, exhausted budgets, and a random fuzz over the whole input
//! domain. Every request must end in a typed failure or an answer whose numbers are all finite.
//! `STRESS_CASES=…` scales the random part (default 3000).

#![allow(
    clippy::suboptimal_flops,
    reason = "test arithmetic follows the spec's formulas; mul_add gains nothing here"
)]

use std::time::Duration;

use mechcalc::calc::spatial_coupling::{SpatialCouplingRequest, run};
use mechcalc::calc::{CalcFailure, ProblemClass};
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

use crate::support::finite::first_null_or_non_finite;
use crate::support::proptest_cfg;
use crate::support::spatial_coupling::num;

/// `STRESS_CASES`, default 3000.
fn stress_cases() -> usize {
    proptest_cfg::stress_cases(3000)
}

const ALL: &str = r#"{"contact": true, "relative_1": true, "relative_2": true, "frames": true,
                      "check": true, "series": true, "summary": true}"#;

/// Sends `body` with every group on; returns the answer (all numbers finite) or the failure.
fn outcome(mut body: Value) -> Result<Value, CalcFailure> {
    body["outputs"] = serde_json::from_str(ALL).expect("outputs");
    if body.get("body3_points_m").is_none() {
        body["body3_points_m"] = json!([[0.5, -1.0, 2.0], [0, 0, 0]]);
    }
    let req: SpatialCouplingRequest = serde_json::from_value(body.clone()).expect("request JSON");
    match run(req, &Budget::unlimited()) {
        Ok(r) => {
            let v = serde_json::to_value(r).expect("serializes");
            if let Some(p) = first_null_or_non_finite(&v, &[]) {
                panic!("non-finite number at {p} for {body}");
            }
            Ok(v)
        }
        Err(e) => Err(e),
    }
}

fn codes(v: &Value) -> Vec<String> {
    v["warnings"]
        .as_array()
        .map(|w| {
            w.iter()
                .filter_map(|w| w["code"].as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default()
}

/// §7.1: |cos 2α| from 1e-9 (admitted) down through the rejection limit; i12 stays ≤ 1/|cos 2α|.
#[test]
fn near_perpendicular_shafts() {
    for k in 0..=80 {
        // δ = 45° − |α| from 1e-1 down to 1e-13 degrees.
        let delta = 10f64.powf(-1.0 - 12.0 * f64::from(k) / 80.0);
        for alpha in [45.0 - delta, -45.0 + delta, 45.0 + delta, -45.0 - delta] {
            let c2a = (2.0 * alpha).to_radians().cos().abs();
            // β = 0 (|α| < 45°) or 90° (|α| > 45°) keeps the support plane valid.
            let beta = if alpha.abs() < 45.0 { 0.0 } else { 90.0 };
            let body = json!({"alpha_deg": alpha, "beta_deg": beta,
                              "theta1_deg": [0.0, 1e-9, 1e-5, 0.5, 90.0, 179.999_999, 180.0],
                              "sweep": {"n_points": 181}});
            match outcome(body) {
                Ok(v) => {
                    assert!(c2a >= 0.9e-9, "α = {alpha}: |cos 2α| = {c2a:e} admitted");
                    assert!(
                        codes(&v).iter().any(|c| c == "NEAR_PERPENDICULAR_SHAFTS"),
                        "α = {alpha}"
                    );
                    let max = v["points"]
                        .as_array()
                        .expect("points")
                        .iter()
                        .filter_map(|p| p["i12"].as_f64())
                        .fold(0f64, |m, x| m.max(x.abs()));
                    assert!(
                        max <= 1.0 / c2a * (1.0 + 1e-6),
                        "α = {alpha}: |i12| {max:e} > 1/|cos 2α|"
                    );
                }
                Err(e) => {
                    assert!(
                        c2a < 1.1e-9,
                        "α = {alpha} (|cos 2α| = {c2a:e}) refused: {e}"
                    );
                    assert_eq!(e.code, "PERPENDICULAR_SHAFTS", "{e}");
                }
            }
        }
    }
}

/// §7.2: β across the validity boundary (D(0) → 0 at β = α ± 90°, D(90°) → 0 at β = ±90° − α),
/// sweeps and points; typed refusals or finite numbers, error objects only where D ≈ 0.
#[test]
fn support_plane_boundaries() {
    let mut n_ok = 0;
    let mut n_refused = 0;
    for alpha in [-60.0, -30.0, -15.0, 0.0, 10.0, 15.0, 30.0, 44.0, 50.0, 80.0] {
        for edge in [alpha - 90.0, alpha + 90.0, 90.0 - alpha, -90.0 - alpha] {
            for d in [0.0, 1e-14, -1e-14, 1e-10, -1e-10, 1e-6, -1e-6, 1e-3, -1e-3] {
                let beta: f64 = edge + d;
                if !(beta > -90.0 && beta <= 90.0) {
                    continue;
                }
                match outcome(
                    json!({"alpha_deg": alpha, "beta_deg": beta, "sweep": {"n_points": 361}}),
                ) {
                    Ok(v) => {
                        n_ok += 1;
                        assert!(
                            v["configuration"]["support_plane"]["valid"]
                                .as_bool()
                                .expect("bool")
                        );
                    }
                    Err(e) => {
                        n_refused += 1;
                        assert_eq!(e.code, "SUPPORT_PLANE_INVALID", "α={alpha} β={beta}: {e}");
                        assert_eq!(e.class, ProblemClass::Infeasible);
                    }
                }
                // Points only, including the roots of D and their neighbours.
                let roots: Vec<f64> = outcome(json!({"alpha_deg": alpha, "beta_deg": beta, "theta1_deg": [0.0]}))
                    .expect("points-only requests answer")["configuration"]["support_plane"]["d_roots_theta1_deg"]
                    .as_array().expect("roots").iter().map(num).collect();
                let mut th = vec![0.0, 90.0, 180.0, 270.0, 1e-300, 89.999_999_999];
                for r in roots {
                    for k in [-1e-6, -1e-12, 0.0, 1e-12, 1e-6] {
                        th.push(r + k);
                    }
                }
                let v = outcome(json!({"alpha_deg": alpha, "beta_deg": beta, "theta1_deg": th}))
                    .expect("points-only requests answer");
                for p in v["points"].as_array().expect("points") {
                    if p.get("error").is_some() {
                        assert_eq!(p["error"]["code"], "CONTACT_AT_INFINITY");
                    } else {
                        assert!(
                            p["check"]["max_residual"].as_f64().expect("check") < 1e-6,
                            "{p}"
                        );
                    }
                }
            }
        }
    }
    assert!(
        n_ok > 0 && n_refused > 0,
        "both sides of the boundary reached: {n_ok} / {n_refused}"
    );
}

/// D ≡ 0 (α = 0, β = 90°): the plane is parallel to the body's plane line at every θ1.
#[test]
fn degenerate_plane_everywhere() {
    let e = outcome(json!({"alpha_deg": 0.0, "beta_deg": 90.0, "sweep": {}}))
        .expect_err("sweep refused");
    assert_eq!(e.code, "SUPPORT_PLANE_INVALID");
    let v = outcome(json!({"alpha_deg": 0.0, "beta_deg": 90.0, "theta1_deg": [0, 33, 90]}))
        .expect("answers");
    assert!(
        v["points"]
            .as_array()
            .expect("points")
            .iter()
            .all(|p| p["error"]["code"] == "CONTACT_AT_INFINITY")
    );
}

/// §7.6: huge angles, sweeps over huge ranges and reversed sweeps; extreme a and ω1; α → ±90°.
#[test]
fn extreme_angles_lengths_and_speeds() {
    for t in [
        1e9,
        -1e9,
        1e15,
        1e300,
        -1e300,
        f64::MAX,
        -f64::MAX,
        5e-324,
        360.0 * 1e12 + 30.0,
    ] {
        let v = outcome(
            json!({"theta1_deg": [t], "sweep": {"start_deg": t, "end_deg": -t, "n_points": 5}}),
        )
        .unwrap_or_else(|e| panic!("θ1 = {t}: {e}"));
        assert!(num(&v["points"][0]["theta2_deg"]) < 360.0);
    }
    for (a, w) in [
        (5e-324, 1e6),
        (1e6, 1e6),
        (1e6, -1e6),
        (1e-300, 0.0),
        (1.0, 0.0),
    ] {
        for alpha in [15.0, 44.999_999_9, -89.999_999, 89.999_999_999] {
            let beta = if f64::abs(alpha) < 45.0 { 0.0 } else { 90.0 };
            outcome(
                json!({"alpha_deg": alpha, "beta_deg": beta, "a_m": a, "omega1_rad_s": w,
                           "theta1_deg": [0, 1e-7, 45, 90], "sweep": {"n_points": 101},
                           "body3_points_m": [[1e6, -1e6, 1e6]]}),
            )
            .unwrap_or_else(|e| panic!("a = {a}, ω1 = {w}, α = {alpha}: {e}"));
        }
    }
    // α → ±90°: |cos 2α| → 1, homokinetic with i12 → +1.
    let v =
        outcome(json!({"alpha_deg": 89.999_999_999_9, "beta_deg": 90, "sweep": {"n_points": 11}}))
            .expect("answers");
    assert_eq!(v["configuration"]["homokinetic"], true);
    assert!((num(&v["summary"]["i12_max"]) - 1.0).abs() < 1e-12);
}

/// A spent budget stops a long sweep with a typed failure.
#[test]
fn exhausted_budget_is_typed() {
    let req: SpatialCouplingRequest =
        serde_json::from_value(json!({"sweep": {"n_points": 1_000_000}})).expect("request");
    let budget = Budget::new(Duration::from_nanos(1));
    std::thread::sleep(Duration::from_millis(2));
    match run(req, &budget) {
        Ok(_) => panic!("a 1 ns budget cannot cover 10⁶ points"),
        Err(e) => {
            assert_eq!(e.code, "DEADLINE_EXCEEDED");
            assert_eq!(e.class, ProblemClass::TooLarge);
        }
    }
}

/// Random requests over the whole domain (and just outside): typed failure or finite numbers.
#[test]
fn random_fuzz_is_finite_or_typed() {
    let mut rng = ChaCha8Rng::seed_from_u64(20_261_125);
    let mut answered = 0usize;
    for _ in 0..stress_cases() {
        let alpha = match rng.random_range(0..4) {
            0 => rng.random_range(-90.0..90.0),
            1 => {
                45.0 * if rng.random_bool(0.5) { 1.0 } else { -1.0 } + rng.random_range(-1e-6..1e-6)
            }
            2 => f64::from(rng.random_range(-3i32..=3)) * 15.0,
            _ => rng.random_range(-1e-9..1e-9),
        };
        let beta = match rng.random_range(0..3) {
            0 => rng.random_range(-90.0..=90.0),
            1 => {
                alpha
                    + if rng.random_bool(0.5) { 90.0 } else { -90.0 }
                    + rng.random_range(-1e-9..1e-9)
            }
            _ => 90.0 - alpha + rng.random_range(-1e-9..1e-9),
        };
        let thetas: Vec<f64> = (0..4)
            .map(|_| match rng.random_range(0..3) {
                0 => rng.random_range(-1e4..1e4),
                1 => f64::from(rng.random_range(-8i32..8)) * 90.0 + rng.random_range(-1e-10..1e-10),
                _ => rng.random_range(-1e18..1e18),
            })
            .collect();
        let body = json!({
            "alpha_deg": alpha, "beta_deg": beta, "a_m": 10f64.powf(rng.random_range(-8.0..6.0)),
            "omega1_rad_s": rng.random_range(-1e6..1e6), "branch": if rng.random_bool(0.5) { 1 } else { -1 },
            "theta1_deg": thetas,
            "sweep": {"start_deg": rng.random_range(-1e3..1e3), "end_deg": rng.random_range(-1e3..1e3), "n_points": rng.random_range(2..40)}
        });
        match outcome(body.clone()) {
            Ok(_) => answered += 1,
            Err(e) => assert!(
                [
                    "PERPENDICULAR_SHAFTS",
                    "SUPPORT_PLANE_INVALID",
                    "INVALID_INPUT"
                ]
                .contains(&e.code),
                "{body}: {e}"
            ),
        }
    }
    assert!(answered > stress_cases() / 4, "answered {answered}");
}
