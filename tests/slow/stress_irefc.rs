//! Inputs near every hazard of the IREFC specs: the undercut and overlap limits, Z2 at the ends of its range,
//! χ → 1⁺, zero and huge torque, extreme scales, grids and sweeps at their size limits, budgets that run
//! out, and mutated `api/irefc` examples. Every result must be a typed error (a spec code) or finite
//! numbers: never NaN, never a panic.

// Tests build values the way the specs write them.
#![allow(clippy::suboptimal_flops)]

use std::time::Duration;

use mechcalc::calc::CalcFailure;
use mechcalc::calc::irefc::geometry::Geometry;
use mechcalc::calc::irefc::stress::wire::{StressSingleResponse, StressSweepResponse};
use mechcalc::calc::irefc::{
    IrefcEfficiencyRequest, IrefcEfficiencyResponse, IrefcStressRequest, IrefcStressResponse,
    run_efficiency, run_stress,
};
use mechcalc::numerics::{Budget, StopReason};
use proptest::prelude::*;
use serde_json::{Value, json};

/// Every code the two endpoints may return.
const CODES: &[&str] = &[
    "BAD_RANGE",
    "MISSING_FIELD",
    "AMBIGUOUS_LOAD",
    "GRID_TOO_FINE",
    "SWEEP_TOO_LARGE",
    "UNDERCUT",
    "ELEMENT_OVERLAP",
    "NON_FINITE",
    "DEADLINE",
];

/// Whether a Debug rendering contains a non-finite float (`NaN`, `inf`, `-inf` as whole tokens).
fn has_non_finite(debug: &str) -> bool {
    debug
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '.'))
        .any(|tok| tok == "NaN" || tok == "inf")
}

fn check_failure(e: &CalcFailure) {
    assert!(CODES.contains(&e.code), "unexpected code {}: {e}", e.code);
    assert!(
        !has_non_finite(&format!("{e:?}")),
        "non-finite number in an error: {e:?}"
    );
}

/// Run a stress request: Ok with only finite numbers, or a typed failure.
fn stress(v: &Value, budget: &Budget) -> Result<IrefcStressResponse, CalcFailure> {
    let req: IrefcStressRequest = serde_json::from_value(v.clone()).expect("decodes");
    let r = run_stress(req, budget);
    match &r {
        Ok(resp) => assert!(
            !has_non_finite(&format!("{resp:?}")),
            "non-finite number in {v}"
        ),
        Err(e) => check_failure(e),
    }
    r
}

fn single(v: &Value) -> Result<StressSingleResponse, CalcFailure> {
    stress(v, &Budget::unlimited()).map(|r| match r {
        IrefcStressResponse::Single(s) => *s,
        IrefcStressResponse::Sweep(_) => panic!("single expected"),
    })
}

fn sweep(v: &Value, budget: &Budget) -> Result<StressSweepResponse, CalcFailure> {
    stress(v, budget).map(|r| match r {
        IrefcStressResponse::Sweep(s) => s,
        IrefcStressResponse::Single(_) => panic!("sweep expected"),
    })
}

fn efficiency(v: &Value) -> Result<IrefcEfficiencyResponse, CalcFailure> {
    let req: IrefcEfficiencyRequest = serde_json::from_value(v.clone()).expect("decodes");
    let r = run_efficiency(req, &Budget::unlimited());
    match &r {
        Ok(resp) => assert!(
            !has_non_finite(&format!("{resp:?}")),
            "non-finite number in {v}"
        ),
        Err(e) => check_failure(e),
    }
    r
}

fn design(r2: f64, z2: u32, chi: f64, rb: f64) -> Value {
    json!({"r2_mm": r2, "Z2": z2, "chi": chi, "rb_mm": rb, "torque_Nm": 100.0, "step_deg": 1})
}

fn limits_mm(r2: f64, z2: u32, chi: f64) -> (f64, f64) {
    let g = Geometry::new_unchecked(r2 / 1e3, z2, chi, 1e-6);
    (g.rb_undercut * 1e3, g.rb_overlap * 1e3)
}

#[test]
fn detector_sees_non_finite() {
    assert!(
        has_non_finite("Foo { a: NaN }")
            && has_non_finite("[1.0, inf]")
            && has_non_finite("Some(-inf)")
    );
    assert!(!has_non_finite("Foo { infeasible: 1.0, info: 2 }"));
}

/// rb at the undercut limit: just below → finite (huge) stresses with `NEAR_UNDERCUT`; at or above →
/// `UNDERCUT` with the limit in the message; the scan may meet the cusp within round-off → `UNDERCUT`.
#[test]
fn designs_at_the_undercut_limit() {
    // Designs where the undercut limit is below the overlap limit (spec: eq. 3 admits them).
    for (z2, chi) in [
        (34u32, 1.25),
        (26, 1.28),
        (20, 1.3),
        (60, 1.26),
        (4, 1.6),
        (10, 1.4),
    ] {
        let (uc, ov) = limits_mm(20.0, z2, chi);
        assert!(
            uc < ov,
            "Z2 = {z2}, chi = {chi}: undercut {uc} vs overlap {ov}"
        );
        for f in [1.0 - 1e-3, 1.0 - 1e-6, 1.0 - 1e-9, 1.0 - 1e-12, 1.0 - 1e-15] {
            match single(&design(20.0, z2, chi, uc * f)) {
                Ok(r) => {
                    assert!(r.max.cam.sigma_mpa.is_finite() && r.max.cam.sigma_mpa > 0.0);
                    assert!(
                        r.warnings.iter().any(|w| w.code == "NEAR_UNDERCUT"),
                        "Z2 = {z2}, f = {f}"
                    );
                }
                Err(e) => assert_eq!(e.code, "UNDERCUT", "Z2 = {z2}, f = {f}: {e}"),
            }
        }
        for f in [1.0, 1.0 + 1e-12, 1.001, 2.0] {
            let e = single(&design(20.0, z2, chi, uc * f)).expect_err("undercut");
            assert_eq!(e.code, "UNDERCUT");
            assert_eq!(e.errors[0].pointer, "/rb_mm");
            assert!(
                e.errors[0].detail.contains("rb_undercut"),
                "{}",
                e.errors[0].detail
            );
        }
    }
    // The spec's example: Z2 = 34, χ = 1.25, rb = 2.15 mm, r2 = 20 mm gives ~21 GPa inside eq. 3's range.
    let r = single(&design(20.0, 34, 1.25, 2.15)).expect("feasible");
    assert!(r.max.cam.sigma_mpa > 1e4, "{}", r.max.cam.sigma_mpa);
    assert!(r.warnings.iter().any(|w| w.code == "NEAR_UNDERCUT"));
}

/// rb at the overlap limit: just below → fine; at or above → `ELEMENT_OVERLAP` (or both codes listed).
#[test]
fn designs_at_the_overlap_limit() {
    for (z2, chi) in [(26u32, 1.4), (10, 1.67), (60, 1.6), (3, 2.0), (1000, 1.5)] {
        let (uc, ov) = limits_mm(20.0, z2, chi);
        if ov < uc {
            let r = single(&design(20.0, z2, chi, ov * (1.0 - 1e-12))).expect("feasible");
            assert!(r.max.cam.sigma_mpa > 0.0);
            let e = single(&design(20.0, z2, chi, ov)).expect_err("overlap");
            assert_eq!(e.code, "ELEMENT_OVERLAP", "Z2 = {z2}: {e}");
        }
        let e = single(&design(20.0, z2, chi, ov.max(uc) * 1.01)).expect_err("both");
        assert!(e.code == "UNDERCUT" || e.code == "ELEMENT_OVERLAP");
        assert_eq!(e.errors.len(), 2, "both limits listed: {e}");
    }
}

/// Z2 at the ends of its range (3 and 1000), χ from 1⁺ to 5, small and large rb fractions.
#[test]
fn z2_and_chi_at_the_ends_of_their_ranges() {
    for z2 in [3u32, 4, 5, 999, 1000] {
        for chi in [
            1.0 + 1e-15,
            1.0 + 1e-12,
            1.0 + 1e-9,
            1.0 + 1e-6,
            1.001,
            1.25,
            2.0,
            3.0,
            4.99,
            5.0,
        ] {
            let (uc, ov) = limits_mm(20.0, z2, chi);
            for frac in [1e-6, 0.3, 0.9] {
                let rb = frac * uc.min(ov);
                if rb.is_nan() || rb <= 0.0 {
                    continue;
                }
                for mode in ["paper_phase0", "phase_exact"] {
                    let mut v = design(20.0, z2, chi, rb);
                    v["load_sharing"] = json!(mode);
                    v["step_deg"] = json!(2);
                    match single(&v) {
                        Ok(r) => {
                            assert!(r.max.cam.sigma_mpa >= 0.0 && r.max.crown.sigma_mpa >= 0.0);
                            assert!(r.fmax_n > 0.0);
                        }
                        Err(e) => assert!(
                            ["UNDERCUT", "NON_FINITE", "BAD_RANGE"].contains(&e.code),
                            "Z2 = {z2}, chi = {chi}, rb = {rb}: {e}"
                        ),
                    }
                }
            }
        }
    }
    // χ = 1 exactly and χ > 5, Z2 = 2 and 1001: rejected with pointers.
    for (z2, chi, ptr) in [
        (26i64, 1.0, "/chi"),
        (26, 5.000_001, "/chi"),
        (2, 1.4, "/Z2"),
        (1001, 1.4, "/Z2"),
    ] {
        let v = json!({"r2_mm": 20, "Z2": z2, "chi": chi, "rb_mm": 1, "torque_Nm": 1});
        let e = single(&v).expect_err("out of range");
        assert_eq!(e.code, "BAD_RANGE");
        assert_eq!(e.errors[0].pointer, ptr);
    }
}

/// χ ≥ Z2 makes the crown profile concave everywhere: min_profile_radius_crown_mm is null, not ∞.
#[test]
fn crown_concave_everywhere() {
    let (uc, ov) = limits_mm(20.0, 3, 4.5);
    let r = single(&design(20.0, 3, 4.5, 0.5 * uc.min(ov))).expect("feasible");
    assert!(r.geometry.min_profile_radius_crown_mm.is_none());
    assert!(r.geometry.rb_undercut_mm.is_finite());
}

/// Zero torque: every stress and force 0, no arg max (null), no warnings about NaN; tiny and huge torques.
#[test]
fn zero_tiny_and_huge_torque() {
    let mut v = design(20.0, 26, 1.4, 2.0);
    v["torque_Nm"] = json!(0.0);
    v["include"] = json!({"curves": true, "subsurface": true});
    let r = single(&v).expect("computes");
    assert!(
        r.max.cam.phi2_deg.is_none() && r.max.crown.phi2_deg.is_none() && r.max.overall.is_none()
    );
    assert!(
        r.max.cam.sigma_mpa.abs() < f64::MIN_POSITIVE && r.max.cam.f_n.abs() < f64::MIN_POSITIVE
    );
    assert!(r.fmax_n.abs() < f64::MIN_POSITIVE);
    let c = r.curves.as_ref().expect("requested");
    assert!(c.sigma_cam_mpa.iter().all(|s| s.abs() < f64::MIN_POSITIVE));

    for t in [1e-300, 1e-12, 1e7] {
        v["torque_Nm"] = json!(t);
        let r = single(&v).expect("computes");
        assert!(r.max.cam.sigma_mpa >= 0.0);
    }
    v["torque_Nm"] = json!(1.000_000_1e7);
    assert_eq!(single(&v).expect_err("too large").code, "BAD_RANGE");
    v["torque_Nm"] = json!(-1.0);
    assert_eq!(single(&v).expect_err("negative").code, "BAD_RANGE");
}

/// Scales from 1e-6 to 1e4 mm, extreme contact lengths and moduli: finite numbers or `NON_FINITE`.
#[test]
fn extreme_scales() {
    for r2 in [1e-300, 1e-12, 1e-6, 1e-3, 1.0, 1e3, 1e4] {
        for frac in [1e-9, 0.5] {
            let (uc, ov) = limits_mm(r2, 26, 1.4);
            let rb = frac * uc.min(ov);
            for lb in [None, Some(1e-300), Some(r2 * 100.0)] {
                let mut v = design(r2, 26, 1.4, rb);
                v["torque_Nm"] = json!(1e7);
                if let Some(lb) = lb {
                    v["lb_mm"] = json!(lb);
                }
                v["wheel_material"] = json!({"E_MPa": 1e7, "nu": 0.499});
                v["include"] = json!({"curves": true, "profiles": true, "subsurface": true});
                v["curves_stride"] = json!(7);
                v["profile_points"] = json!(64);
                if let Err(e) = single(&v) {
                    assert!(
                        ["NON_FINITE", "UNDERCUT"].contains(&e.code),
                        "r2 = {r2}, rb = {rb}, lb = {lb:?}: {e}"
                    );
                }
            }
        }
    }
    // lb beyond 100·r2 is rejected.
    let mut v = design(20.0, 26, 1.4, 2.0);
    v["lb_mm"] = json!(2000.001);
    assert_eq!(single(&v).expect_err("lb").errors[0].pointer, "/lb_mm");
}

/// Every range problem is reported at once, each with its pointer.
#[test]
fn every_offending_field_at_once() {
    let v = json!({"r2_mm": -1, "Z2": 2, "chi": 0.5, "rb_mm": 0, "torque_Nm": -5, "lb_mm": 0,
        "wheel_material": {"E_MPa": 1, "nu": 0.5}, "step_deg": 0, "curves_stride": 0, "profile_points": 1});
    let e = single(&v).expect_err("invalid");
    assert_eq!(e.code, "BAD_RANGE");
    let ptrs: Vec<&str> = e.errors.iter().map(|i| i.pointer.as_str()).collect();
    for p in [
        "/r2_mm",
        "/Z2",
        "/chi",
        "/rb_mm",
        "/torque_Nm",
        "/lb_mm",
        "/wheel_material/E_MPa",
        "/wheel_material/nu",
        "/step_deg",
        "/curves_stride",
        "/profile_points",
    ] {
        assert!(ptrs.contains(&p), "{p} missing in {ptrs:?}");
    }
    // Missing design fields in mode "single".
    let e = single(&json!({"torque_Nm": 1})).expect_err("missing");
    assert_eq!(e.code, "MISSING_FIELD");
    assert_eq!(e.errors.len(), 4);
}

/// Non-finite values through the Rust API (JSON cannot carry them): `BAD_RANGE`, never a panic.
#[test]
fn non_finite_inputs_through_the_rust_api() {
    let base: IrefcStressRequest =
        serde_json::from_value(design(20.0, 26, 1.4, 2.0)).expect("decodes");
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut reqs = Vec::new();
        let mut r = base.clone();
        r.r2_mm = Some(bad);
        reqs.push(r);
        let mut r = base.clone();
        r.chi = Some(bad);
        reqs.push(r);
        let mut r = base.clone();
        r.rb_mm = Some(bad);
        reqs.push(r);
        let mut r = base.clone();
        r.torque_nm = bad;
        reqs.push(r);
        let mut r = base.clone();
        r.lb_mm = Some(bad);
        reqs.push(r);
        let mut r = base.clone();
        r.step_deg = Some(bad);
        reqs.push(r);
        for req in reqs {
            let e = run_stress(req, &Budget::unlimited()).expect_err("non-finite");
            assert_eq!(e.code, "BAD_RANGE", "{e}");
        }
    }
    let eff: IrefcEfficiencyRequest =
        serde_json::from_value(json!({"r2_mm": 20, "Z2": 26, "chi": 1.4,
        "rb_mm": 2, "power_W": 1500, "speed_rpm": 1500}))
        .expect("decodes");
    for bad in [f64::NAN, f64::INFINITY] {
        let mut r = eff.clone();
        r.speed_rpm = bad;
        assert_eq!(
            run_efficiency(r, &Budget::unlimited())
                .expect_err("nan")
                .code,
            "BAD_RANGE"
        );
        let mut r = eff.clone();
        r.rolling_friction_mm = Some(bad);
        r.phase_deg = Some(bad);
        let e = run_efficiency(r, &Budget::unlimited()).expect_err("nan");
        assert_eq!(e.errors.len(), 2);
    }
}

/// Grid limits: 180/step ≤ 2·10⁶ (`GRID_TOO_FINE` beyond), 0 < step ≤ 10 (`BAD_RANGE`); the finest grid
/// still computes.
#[test]
fn grid_at_its_limits() {
    let mut v = design(20.0, 26, 1.4, 2.0);
    for (step, code) in [
        (8.9e-5, Some("GRID_TOO_FINE")),
        (0.0, Some("BAD_RANGE")),
        (10.000_001, Some("BAD_RANGE")),
    ] {
        v["step_deg"] = json!(step);
        assert_eq!(single(&v).err().map(|e| e.code), code, "step {step}");
    }
    v["step_deg"] = json!(1);
    let reference = single(&v).expect("computes").max.cam.sigma_mpa;
    for step in [9e-5, 10.0, 7.3] {
        v["step_deg"] = json!(step);
        let r = single(&v).expect("computes");
        let rel = (r.max.cam.sigma_mpa - reference).abs() / reference;
        assert!(
            rel < 1e-12,
            "step {step}: {} vs {reference}",
            r.max.cam.sigma_mpa
        );
    }
}

/// Sweeps at the size limit: exactly 100 000 combinations run (coarse grid); one more, or more than 5·10⁸
/// grid points in total, is `SWEEP_TOO_LARGE`. Infeasible combinations are records, not errors.
#[test]
fn sweeps_at_the_size_limit() {
    let v = json!({"mode": "sweep", "r2_mm": 20, "rb_mm": 0.4, "torque_Nm": 100, "step_deg": 10,
        "sweep": {"Z2": {"from": 3, "to": 102}, "chi": {"from": 1.01, "to": 1.01 + 999.0 * 0.003, "step": 0.003}}});
    let r = sweep(&v, &Budget::unlimited()).expect("at the limit");
    assert_eq!(r.records.len(), 100_000);
    assert_eq!(r.n_valid + r.n_invalid, 100_000);
    assert_eq!(r.n_not_evaluated, 0);
    assert!(
        r.n_invalid > 0 && r.n_valid > 0,
        "the feasible region ends inside this sweep"
    );
    assert_eq!(r.meta.solver.stop_reason, StopReason::Completed);
    let (w, b) = (r.worst.expect("valid"), r.best.expect("valid"));
    let s = |i: usize| r.records[i].sigma_max_mpa.expect("valid record");
    assert!(r.records.iter().filter(|x| x.valid).all(|x| {
        let v = x.sigma_max_mpa.expect("valid");
        v <= s(w) && v >= s(b)
    }));
    assert!(
        r.records
            .iter()
            .filter(|x| !x.valid)
            .all(|x| x.reason.is_some() && x.sigma_max_mpa.is_none())
    );
    // Order: Z2, then χ.
    assert!(
        r.records
            .windows(2)
            .all(|p| (p[0].z2, p[0].chi) < (p[1].z2, p[1].chi))
    );

    let mut over = v.clone();
    over["sweep"]["Z2"]["to"] = json!(103);
    assert_eq!(
        sweep(&over, &Budget::unlimited())
            .expect_err("too many")
            .code,
        "SWEEP_TOO_LARGE"
    );
    let mut huge = v.clone();
    huge["sweep"]["chi"]["step"] = json!(1e-12);
    assert_eq!(
        sweep(&huge, &Budget::unlimited())
            .expect_err("too many")
            .code,
        "SWEEP_TOO_LARGE"
    );
    let mut work = v.clone();
    work["sweep"]["Z2"] = json!({"from": 10, "to": 19});
    work["sweep"]["chi"] = json!({"from": 1.25, "to": 1.34, "step": 0.001});
    work["step_deg"] = json!(0.0003);
    assert_eq!(
        sweep(&work, &Budget::unlimited())
            .expect_err("too much work")
            .code,
        "SWEEP_TOO_LARGE"
    );
}

/// Sweep ranges: from > to, bad steps, empty lists and bad list entries are `BAD_RANGE` with pointers;
/// rb and r2 lists multiply the combinations; the last χ is kept within 1e-12.
#[test]
fn sweep_ranges_and_lists() {
    let base = json!({"mode": "sweep", "torque_Nm": 100, "step_deg": 5,
        "sweep": {"Z2": {"from": 20, "to": 10}, "chi": {"from": 1.5, "to": 1.4, "step": -0.1},
                  "rb_mm": [], "r2_mm": [20, -1]}});
    // The per-field rules (checked at the door) are listed together; the order of a range's ends
    // is a rule between fields, checked once every field is valid.
    let e = sweep(&base, &Budget::unlimited()).expect_err("bad ranges");
    let ptrs: Vec<&str> = e.errors.iter().map(|i| i.pointer.as_str()).collect();
    for p in ["/sweep/chi/step", "/sweep/rb_mm", "/sweep/r2_mm/1"] {
        assert!(ptrs.contains(&p), "{p} missing in {ptrs:?}");
    }
    let reversed = json!({"mode": "sweep", "torque_Nm": 100, "step_deg": 5, "rb_mm": 1,
        "sweep": {"Z2": {"from": 20, "to": 10}, "chi": {"from": 1.5, "to": 1.4, "step": 0.1},
                  "r2_mm": [20]}});
    let e = sweep(&reversed, &Budget::unlimited()).expect_err("reversed ranges");
    assert_eq!(e.code, "BAD_RANGE");
    let ptrs: Vec<&str> = e.errors.iter().map(|i| i.pointer.as_str()).collect();
    for p in ["/sweep/Z2/to", "/sweep/chi/to"] {
        assert!(ptrs.contains(&p), "{p} missing in {ptrs:?}");
    }
    let ok = json!({"torque_Nm": 100, "step_deg": 5,
        "sweep": {"Z2": {"from": 20, "to": 21}, "chi": {"from": 1.25, "to": 1.67, "step": 0.14},
                  "rb_mm": [1, 2, 2.5], "r2_mm": [20, 30]}});
    let r = sweep(&ok, &Budget::unlimited()).expect("mode inferred from sweep");
    assert_eq!(r.records.len(), 2 * 4 * 3 * 2);
    assert!((r.records[3].chi - 1.25).abs() < 1e-15 && (r.records[6].chi - 1.39).abs() < 1e-12);
    assert!((r.records[23].chi - 1.67).abs() < 1e-12);
    assert!((r.records[1].r2_mm - 30.0).abs() < 1e-12 && (r.records[2].rb_mm - 2.0).abs() < 1e-12);
}

/// Budgets: a spent deadline leaves every sweep record NOT_EVALUATED with stop_reason deadline; an
/// evaluation cap evaluates exactly that many combinations; a single design past its deadline is
/// `DEADLINE`.
#[test]
fn budgets_run_out() {
    let v = json!({"mode": "sweep", "r2_mm": 20, "rb_mm": 2, "torque_Nm": 100, "step_deg": 1,
        "sweep": {"Z2": {"from": 10, "to": 40}, "chi": {"from": 1.25, "to": 1.67, "step": 0.01}}});
    let r = sweep(&v, &Budget::new(Duration::ZERO)).expect("partial result");
    assert_eq!(r.n_not_evaluated, r.records.len() as u64);
    assert_eq!(r.meta.solver.stop_reason, StopReason::Deadline);
    assert!(r.worst.is_none() && r.best.is_none());
    assert!(r.warnings.iter().any(|w| w.code == "SWEEP_INCOMPLETE"));

    let r = sweep(&v, &Budget::unlimited().with_max_evaluations(100)).expect("partial result");
    assert_eq!(r.meta.solver.evaluations, 100);
    assert_eq!(r.meta.solver.stop_reason, StopReason::MaxEvaluations);
    assert!(
        r.records[..100]
            .iter()
            .all(|x| x.reason.as_ref().is_none_or(|m| m.code != "NOT_EVALUATED"))
    );
    assert!(
        r.records[100..]
            .iter()
            .all(|x| x.reason.as_ref().is_some_and(|m| m.code == "NOT_EVALUATED"))
    );

    let mut s = design(20.0, 1000, 1.5, 0.01);
    s["step_deg"] = json!(1e-4);
    s["load_sharing"] = json!("phase_exact");
    let e = stress(&s, &Budget::new(Duration::from_millis(1))).expect_err("deadline");
    assert_eq!(e.code, "DEADLINE");
}

/// Sweeps are deterministic: the same request gives the same records in the same order.
#[test]
fn sweep_is_deterministic() {
    let v = json!({"mode": "sweep", "r2_mm": 20, "rb_mm": 2, "torque_Nm": 100, "step_deg": 2,
        "load_sharing": "phase_exact",
        "sweep": {"Z2": {"from": 8, "to": 40}, "chi": {"from": 1.05, "to": 2.0, "step": 0.05}}});
    let a = sweep(&v, &Budget::unlimited()).expect("a");
    let b = sweep(&v, &Budget::unlimited()).expect("b");
    let strip = |r: &StressSweepResponse| serde_json::to_string(&r.records).expect("json");
    assert_eq!(strip(&a), strip(&b));
    assert_eq!((a.worst, a.best), (b.worst, b.best));
}

/// Efficiency hazards: LA ≤ 0 (warning, finite), losses beyond the input (eta_product null + warning),
/// ambiguous or missing load, zero speed, phase out of range, the largest phase average.
#[test]
fn efficiency_hazards() {
    let e1 =
        json!({"r2_mm": 20, "Z2": 26, "chi": 1.4, "rb_mm": 2, "power_W": 1500, "speed_rpm": 1500});
    // rb ≥ r2(χ−1): contact A before the pitch point near φ = 0.
    let (uc, ov) = limits_mm(20.0, 8, 1.3);
    let rb = 0.99 * uc.min(ov);
    assert!(rb >= 20.0 * 0.3, "design must have LA <= 0");
    let mut v = e1.clone();
    v["Z2"] = json!(8);
    v["chi"] = json!(1.3);
    v["rb_mm"] = json!(rb);
    let r = efficiency(&v).expect("computes");
    assert!(
        r.warnings
            .iter()
            .any(|w| w.code == "CONTACT_A_BEYOND_PITCH")
    );
    assert!(r.elements.as_ref().expect("on")[0].la_mm <= 0.0);

    let mut v = e1.clone();
    v["model"] = json!("rigid_body");
    v["rolling_friction_mm"] = json!(10);
    v["sliding_friction"] = json!(1);
    let r = efficiency(&v).expect("computes");
    assert!(r.totals.eta_product.is_none());
    assert!(r.totals.eta_linear < 0.0);
    assert!(r.warnings.iter().any(|w| w.code == "LOSSES_EXCEED_INPUT"));

    let mut v = e1.clone();
    v["input_torque_Nm"] = json!(9.55);
    assert_eq!(
        efficiency(&v).expect_err("ambiguous").code,
        "AMBIGUOUS_LOAD"
    );
    let mut v = e1.clone();
    v.as_object_mut().expect("object").remove("power_W");
    assert_eq!(efficiency(&v).expect_err("missing").code, "MISSING_FIELD");
    v["input_torque_Nm"] = json!(9.549_296_585_513_72);
    let r = efficiency(&v).expect("torque instead of power");
    assert!((r.p_in_w - 1500.0).abs() < 1e-9);

    for (key, val) in [
        ("speed_rpm", json!(0)),
        ("power_W", json!(0)),
        ("phase_deg", json!(360.0 / 26.0)),
    ] {
        let mut v = e1.clone();
        v[key] = val;
        let e = efficiency(&v).expect_err("rejected");
        assert_eq!(e.code, "BAD_RANGE");
        assert_eq!(e.errors[0].pointer, format!("/{key}"));
    }
    let mut v = e1.clone();
    v["rb_mm"] = json!(3.5);
    assert_eq!(efficiency(&v).expect_err("overlap").code, "ELEMENT_OVERLAP");

    let (uc, ov) = limits_mm(20.0, 1000, 1.5);
    let v = json!({"r2_mm": 20, "Z2": 1000, "chi": 1.5, "rb_mm": 0.5 * uc.min(ov), "power_W": 1e8,
        "speed_rpm": 1e6, "n_phase": 10_000, "phase_deg": 0.359, "model": "paper_abs"});
    let r = efficiency(&v).expect("largest phase average");
    assert!(r.phase_stats.as_ref().expect("stats").eta_linear.mean <= 1.0);
}

fn example(name: &str) -> Value {
    let path = format!("{}/api/irefc/{name}.json", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json")
}

/// Degenerate draws for mutating the api examples (Ruckig-style −1/0/1 plus extreme scales).
fn nasty() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(-1.0),
        Just(0.0),
        Just(1.0),
        Just(1.0 + 1e-12),
        Just(3.0),
        Just(1e-300),
        Just(1e-9),
        Just(1e6),
        Just(1e300),
        Just(-1e300),
        -1e4f64..1e4,
        0.0f64..10.0,
    ]
}

/// The numeric leaves of a JSON value as paths.
fn numeric_paths(v: &Value, path: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Number(_) => out.push(path.clone()),
        Value::Object(m) => {
            for (k, x) in m {
                path.push(k.clone());
                numeric_paths(x, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

fn set(v: &mut Value, path: &[String], x: f64) {
    let mut cur = v;
    for k in path {
        cur = &mut cur[k.as_str()];
    }
    // Integer fields get an integer when x is integral (otherwise decoding, not the calculation, fails).
    *cur = if x.fract().abs() < f64::MIN_POSITIVE && x.abs() < 1e15 {
        // |x| < 1e15 and integral: exact as i64.
        json!(x as i64)
    } else {
        json!(x)
    };
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Mutate up to three numeric fields of the api examples with degenerate values: typed error or finite.
    #[test]
    fn mutated_api_examples(which in 0usize..3, picks in proptest::collection::vec((any::<prop::sample::Index>(), nasty()), 1..4)) {
        let name = ["stress_single", "stress_sweep", "efficiency_paper"][which];
        let mut v = example(name);
        let mut paths = Vec::new();
        numeric_paths(&v, &mut Vec::new(), &mut paths);
        for (idx, x) in picks {
            let p = idx.get(&paths).clone();
            set(&mut v, &p, x);
        }
        if name == "stress_sweep" {
            // Keep the mutated sweep quick in debug builds.
            v["step_deg"] = json!(v["step_deg"].as_f64().unwrap_or(1.0).max(2.0));
        }
        if name == "efficiency_paper" {
            if let Ok(req) = serde_json::from_value::<IrefcEfficiencyRequest>(v.clone()) {
                match run_efficiency(req, &Budget::unlimited()) {
                    Ok(r) => { let d = format!("{r:?}"); prop_assert!(!has_non_finite(&d)); }
                    Err(e) => check_failure(&e),
                }
            }
        } else if let Ok(req) = serde_json::from_value::<IrefcStressRequest>(v.clone()) {
            match run_stress(req, &Budget::new(Duration::from_secs(20))) {
                Ok(r) => { let d = format!("{r:?}"); prop_assert!(!has_non_finite(&d)); }
                Err(e) => check_failure(&e),
            }
        }
    }
}
