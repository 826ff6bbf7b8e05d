//! Stress tests near every hazard of the cognates spec §7: toggles, change points, parallelogram and
//! deltoid shapes, P on or near a coupler joint or on the line DE, near-degenerate coupler
//! triangles, extreme aspect ratios, scales over 6 orders of magnitude, huge N, exhausted budgets.
//! Every request must end in a typed failure or a response whose numbers are all finite.
//! `STRESS_CASES=…` scales the random sweeps (default 400).

#![allow(
    clippy::suboptimal_flops,
    reason = "test arithmetic follows the spec's formulas; mul_add gains nothing here"
)]

use std::time::Duration;

use mechcalc::calc::cognates::wire::{
    CognatesResponse, GrashofClassOut, MechanismId, SnapshotStatus, SpecialOut, WarningCode,
};
use mechcalc::calc::cognates::{CognatesRequest, run};
use mechcalc::calc::{CalcFailure, ProblemClass};
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

use crate::support::finite::first_null_or_non_finite;
use crate::support::proptest_cfg;

/// `STRESS_CASES`, default 400.
fn stress_cases() -> usize {
    proptest_cfg::stress_cases(400)
}

const ALL_OPTIONS: &str = r#"{"curves": true, "points_per_circuit": 32, "verify": ["sync", "implicit", "hausdorff"],
                              "geared_fivebars": true, "metrics": true}"#;

fn all_options() -> Value {
    serde_json::from_str(ALL_OPTIONS).expect("valid options")
}

/// Every number in the response is finite: serde_json turns NaN/∞ into `null`, and absent optional
/// outputs are omitted (never `null`), so any `null` is a defect.
fn assert_all_finite(v: &Value) {
    let bad = first_null_or_non_finite(v, &[]);
    assert!(
        bad.is_none(),
        "null (NaN/∞ or an unset optional) or non-finite at {bad:?}"
    );
}

/// Runs a request; returns the response after checking finiteness, or the typed failure.
/// The `sync` certificate was computed and passed.
fn assert_sync_passed(r: &CognatesResponse) {
    let sync = r
        .verification
        .as_ref()
        .and_then(|v| v.sync.as_ref())
        .expect("sync");
    assert!(sync.passed, "{sync:?}");
}

fn attempt(v: Value) -> Result<CognatesResponse, CalcFailure> {
    let req: CognatesRequest = match serde_json::from_value(v.clone()) {
        Ok(r) => r,
        Err(e) => panic!("request should decode: {e}: {v}"),
    };
    let out = std::panic::catch_unwind(|| run(req, &Budget::unlimited()));
    let out = out.unwrap_or_else(|_| panic!("panic for {v}"));
    if let Ok(r) = &out {
        let j = serde_json::to_value(r).expect("serialisable");
        assert_all_finite(&j);
    }
    out
}

fn ok(v: Value) -> CognatesResponse {
    attempt(v.clone()).unwrap_or_else(|e| panic!("expected success for {v}: {e}"))
}

fn fail(v: Value) -> CalcFailure {
    match attempt(v.clone()) {
        Ok(_) => panic!("expected a failure for {v}"),
        Err(e) => e,
    }
}

/// A linkage request: ground `l`, crank `a`, coupler `b`, rocker `c`, plus the `extra` fields.
fn lk([l, a, b, c]: [f64; 4], cp: Value, extra: Value) -> Value {
    let mut v = json!({"ground": {"A": [0, 0], "B": [l, 0]}, "crank": a, "coupler": b, "rocker": c, "coupler_point": cp});
    if let (Some(o), Some(x)) = (v.as_object_mut(), extra.as_object()) {
        o.extend(x.clone());
    }
    v
}

/// A linkage request at one input angle with every option on.
fn lk_at(bars: [f64; 4], cp: Value, input_angle_deg: f64) -> Value {
    lk(
        bars,
        cp,
        json!({"input_angle_deg": input_angle_deg, "options": all_options()}),
    )
}

/// The special-linkage class of the original and both cognates.
fn specials(r: &CognatesResponse) -> Vec<Option<SpecialOut>> {
    r.mechanisms.iter().map(|m| m.grashof.special).collect()
}

fn has_warning(r: &CognatesResponse, code: WarningCode) -> bool {
    r.warnings.iter().any(|w| w.code == code)
}

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    10f64.powf(rng.random_range(lo.log10()..hi.log10()))
}

// ---------------------------------------------------------------------------------------------
// Random linkages over 6 orders of magnitude
// ---------------------------------------------------------------------------------------------

#[test]
fn random_linkages_six_orders_of_magnitude() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x00C0_6A7E);
    let (mut n_ok, mut n_fail) = (0, 0);
    for _ in 0..stress_cases() {
        let s = log_uniform(&mut rng, 1e-3, 1e3);
        // Links spread over up to 2 decades each: aspect ratios up to 1e2…1e4 with the scale on top.
        let mut len = || s * log_uniform(&mut rng, 0.1, 10.0);
        let (l, a, b, c) = (len(), len(), len(), len());
        let u = b * rng.random_range(-3.0..3.0);
        let v = b * rng.random_range(-3.0..3.0);
        let ax = s * rng.random_range(-100.0..100.0);
        let theta = rng.random_range(-720.0..720.0);
        let branch = if rng.random_bool(0.5) { 1 } else { -1 };
        let req = json!({
            "ground": {"A": [ax, -ax], "length": l, "angle_deg": rng.random_range(-180.0..180.0)},
            "crank": a, "coupler": b, "rocker": c, "coupler_point": {"u": u, "v": v},
            "input_angle_deg": theta, "branch": branch, "options": all_options()
        });
        match attempt(req) {
            Ok(r) => {
                n_ok += 1;
                let cls = r.mechanisms[0].grashof.class;
                assert!(r.mechanisms.iter().all(|m| m.grashof.class == cls));
            }
            Err(e) => {
                n_fail += 1;
                assert!(
                    ["NOT_ASSEMBLABLE", "COUPLER_POINT_AT_JOINT"].contains(&e.code),
                    "unexpected failure {e}"
                );
            }
        }
    }
    assert!(
        n_ok > stress_cases() / 4,
        "only {n_ok} successes, {n_fail} failures"
    );
}

#[test]
fn extreme_aspect_ratio_warns_and_stays_finite() {
    for (l, a, b, c) in [
        (1.0, 1e-6, 1.0, 0.5),
        (1e6, 1.0, 1e6, 1e6),
        (1.0, 1.0, 1.0, 1e-7),
        (3e5, 2e5, 1e-2, 1e5 + 1.0),
    ] {
        match attempt(lk_at(
            [l, a, b, c],
            json!({"u": b * 0.3, "v": b * 0.4}),
            10.0,
        )) {
            Ok(r) => assert!(
                has_warning(&r, WarningCode::ExtremeAspectRatio),
                "{:?}",
                r.warnings
            ),
            Err(e) => assert_eq!(e.code, "NOT_ASSEMBLABLE"),
        }
    }
}

#[test]
fn absolute_scale_extremes() {
    for s in [1e-90, 1e-30, 1e-6, 1.0, 1e6, 1e30, 1e90] {
        let r = ok(json!({
            "ground": {"A": [5.0 * s, -3.0 * s], "B": [8.1 * s, -3.0 * s]},
            "crank": 1.13 * s, "coupler": 1.23 * s, "rocker": 1.04 * s,
            "coupler_point": {"d": 0.92 * s, "e": 1.56 * s, "side": 1},
            "input_angle_deg": 30.0, "options": all_options()
        }));
        assert!(
            (r.c[0] / s - (5.0 - 0.076122)).abs() < 1e-6,
            "C at scale {s:e}: {:?}",
            r.c
        );
        assert_sync_passed(&r);
    }
}

// ---------------------------------------------------------------------------------------------
// Toggles
// ---------------------------------------------------------------------------------------------

#[test]
fn near_toggle_snapshots() {
    let cases = [
        lk(
            [3.1, 1.13, 1.23, 1.04],
            json!({"d": 0.92, "e": 1.56, "side": 1}),
            json!({}),
        ),
        lk(
            [4.0, 3.5, 3.0, 1.0],
            json!({"d": 2.0, "e": 2.5, "side": 1}),
            json!({}),
        ),
        lk(
            [4.0, 3.0, 1.0, 3.5],
            json!({"d": 0.8, "e": 0.6, "side": -1}),
            json!({}),
        ),
    ];
    for base in cases {
        let r0 = ok(base.clone());
        for (i, m) in r0.mechanisms.iter().enumerate() {
            let toggles: Vec<f64> = m.input_range.toggle_angles_abs_deg.clone();
            assert!(!toggles.is_empty() || i > 0 || m.input_range.full_rotation);
            if i > 0 {
                continue;
            }
            for t in toggles {
                for delta in [0.0, 1e-15, 1e-12, 1e-9, 1e-6, -1e-15, -1e-12, -1e-9, -1e-6] {
                    for branch in [1, -1] {
                        let mut v = base.clone();
                        v["input_angle_deg"] = json!(t + delta);
                        v["branch"] = json!(branch);
                        v["options"] = all_options();
                        let r = ok(v);
                        let s = r.mechanisms[0].snapshot.as_ref().expect("snapshot");
                        assert!(matches!(
                            s.status,
                            SnapshotStatus::Ok
                                | SnapshotStatus::Toggle
                                | SnapshotStatus::NotAssemblable
                        ));
                        if s.status == SnapshotStatus::Toggle {
                            assert!(has_warning(&r, WarningCode::SnapshotAtToggle));
                        }
                        if delta.abs() >= 1e-9 && s.status != SnapshotStatus::NotAssemblable {
                            // Assembled a hair inside the range: the pose map still holds.
                            let j0 = s.joints.as_ref().expect("joints");
                            for m in &r.mechanisms[1..] {
                                let jm = m
                                    .snapshot
                                    .as_ref()
                                    .and_then(|x| x.joints.as_ref())
                                    .expect("joints");
                                assert!(
                                    (jm.p[0] - j0.p[0]).abs() < 1e-12
                                        && (jm.p[1] - j0.p[1]).abs() < 1e-12
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn joints_at_toggle_warns() {
    // E on the segment D–B: the drawn configuration is a toggle (cross product exactly 0).
    let r = ok(
        json!({"joints": {"A": [0, 0], "B": [4, 0], "D": [1, 1], "E": [2.5, 0.5], "P": [1.5, 1.5]}}),
    );
    assert!(
        has_warning(&r, WarningCode::SnapshotAtToggle),
        "{:?}",
        r.warnings
    );
    assert_eq!(
        r.mechanisms[0].snapshot.as_ref().and_then(|s| s.branch),
        Some(1)
    );
}

// ---------------------------------------------------------------------------------------------
// Change point, parallelogram, deltoid
// ---------------------------------------------------------------------------------------------

#[test]
fn change_point_warns_with_folded_angles() {
    // s + l = p + q: 1 + 4 = 2 + 3 (crank + ground = coupler + rocker: folds at φ = 180°).
    for (l, a, b, c) in [
        (4.0, 1.0, 2.0, 3.0),
        (4.0, 1.0, 3.0, 2.0),
        (3.0, 2.0, 4.0, 1.0),
        (2.0, 1.0, 4.0, 3.0),
    ] {
        for eps in [0.0, 1e-15, -1e-15, 1e-11, -1e-11] {
            let r = ok(lk_at(
                [l, a + eps, b, c],
                json!({"u": 0.3 * b, "v": 0.5 * b}),
                179.0,
            ));
            for m in &r.mechanisms {
                assert_eq!(
                    m.grashof.class,
                    GrashofClassOut::ChangePoint,
                    "{l} {a} {b} {c} eps {eps}"
                );
            }
            let w = r
                .warnings
                .iter()
                .find(|w| w.code == WarningCode::ChangePoint)
                .expect("change_point warning");
            assert!(
                w.angles_deg.as_ref().is_some_and(|a| !a.is_empty()),
                "{w:?}"
            );
        }
    }
}

#[test]
fn grashof_rtol_zero_and_max() {
    for rtol in [0.0, 1e-3] {
        let r = ok(lk(
            [4.0, 1.0 + 1e-5, 2.0, 3.0],
            json!({"u": 0.6, "v": 1.0}),
            json!({"options": {"grashof_rtol": rtol}}),
        ));
        let want = if rtol > 0.0 {
            GrashofClassOut::ChangePoint
        } else {
            GrashofClassOut::NonGrashof
        };
        assert_eq!(r.mechanisms[0].grashof.class, want);
    }
}

#[test]
fn parallelogram_original_locks_cognate_one() {
    // a = c, b = l: cognate 1 is a deltoid with crank = ground (spec §7).
    for side in [1.0, -1.0] {
        let r = ok(lk_at(
            [3.0, 1.0, 3.0, 1.0],
            json!({"u": 1.2, "v": side * 0.8}),
            40.0,
        ));
        let sp: Vec<_> = specials(&r);
        assert_eq!(
            sp,
            [
                Some(SpecialOut::Parallelogram),
                Some(SpecialOut::Deltoid),
                Some(SpecialOut::Deltoid)
            ]
        );
        assert!(has_warning(&r, WarningCode::Parallelogram));
        let locked = r
            .warnings
            .iter()
            .find(|w| w.code == WarningCode::InputLockedSegment)
            .expect("locked warning");
        assert_eq!(locked.mechanism, Some(MechanismId::Cognate1));
        let sync = r
            .verification
            .as_ref()
            .and_then(|v| v.sync.as_ref())
            .expect("sync");
        assert!(sync.n_skipped_locked > 0, "{sync:?}");
        assert!(sync.max_constraint_residual < 1e-12 * 3.0, "{sync:?}");
        assert!(
            sync.max_dev < 1e-6 * 3.0,
            "locked samples must be skipped: {sync:?}"
        );
        // In the snapshot (parallelogram mode) cognate 1's crank tip sits on C.
        let s1 = r.mechanisms[1].snapshot.as_ref().expect("snapshot");
        assert_eq!(s1.status, SnapshotStatus::Singular);
    }
}

#[test]
fn deltoid_original_singular_at_zero() {
    // a = l, b = c: D reaches B at φ = 0.
    let base = lk(
        [2.0, 2.0, 1.5, 1.5],
        json!({"u": 0.5, "v": 0.7}),
        json!({"options": all_options()}),
    );
    let mut v = base.clone();
    v["input_angle_deg"] = json!(0.0);
    let r = ok(v);
    assert_eq!(r.mechanisms[0].grashof.special, Some(SpecialOut::Deltoid));
    assert_eq!(
        r.mechanisms[0].snapshot.as_ref().map(|s| s.status),
        Some(SnapshotStatus::Singular)
    );
    assert!(has_warning(&r, WarningCode::Deltoid));
    assert!(
        r.warnings
            .iter()
            .any(|w| w.code == WarningCode::InputLockedSegment
                && w.mechanism == Some(MechanismId::Original))
    );
    // The φ = 0 samples (one per circuit) are excluded from the original's curves.
    let excluded: usize = r.mechanisms[0]
        .curves
        .as_ref()
        .expect("curves")
        .iter()
        .map(|c| c.n_singular_excluded)
        .sum();
    assert!(excluded >= 1, "singular samples excluded: {excluded}");
    // Specials map as spec §7: deltoid crank=ground → (parallelogram, deltoid).
    assert_eq!(
        r.mechanisms[1].grashof.special,
        Some(SpecialOut::Parallelogram)
    );
    assert_eq!(r.mechanisms[2].grashof.special, Some(SpecialOut::Deltoid));
    // Deltoid crank = coupler (a = b, c = l) → (deltoid, parallelogram).
    let r2 = ok(lk_at(
        [2.0, 1.5, 1.5, 2.0],
        json!({"u": 0.5, "v": 0.7}),
        30.0,
    ));
    let sp: Vec<_> = specials(&r2);
    assert_eq!(
        sp,
        [
            Some(SpecialOut::Deltoid),
            Some(SpecialOut::Deltoid),
            Some(SpecialOut::Parallelogram)
        ]
    );
    // Rhombus.
    let r3 = ok(lk_at(
        [1.0, 1.0, 1.0, 1.0],
        json!({"u": 0.5, "v": 0.7}),
        0.0,
    ));
    assert_eq!(r3.mechanisms[0].grashof.special, Some(SpecialOut::Rhombus));
}

#[test]
fn crank_tip_near_output_pivot() {
    // a = l with b ≠ c: s → 0 is never assemblable; the snapshot at φ = 0 must say so cleanly.
    let r = ok(lk_at(
        [2.0, 2.0, 1.0, 1.5],
        json!({"u": 0.5, "v": 0.7}),
        0.0,
    ));
    let s = r.mechanisms[0].snapshot.as_ref().expect("snapshot");
    assert!(matches!(
        s.status,
        SnapshotStatus::NotAssemblable | SnapshotStatus::Singular
    ));
    for eps in [1e-15, 1e-12, 1e-9] {
        let _ = ok(lk_at(
            [2.0, 2.0 - eps, 1.5, 1.5],
            json!({"u": 0.5, "v": 0.7}),
            0.0,
        ));
    }
}

// ---------------------------------------------------------------------------------------------
// Coupler point hazards
// ---------------------------------------------------------------------------------------------

#[test]
fn coupler_point_on_or_near_a_joint() {
    for (u, v) in [(0.0, 0.0), (3.5, 0.0), (1e-10, 0.0), (3.5 - 1e-10, 1e-10)] {
        let e = fail(lk([4.0, 1.0, 3.5, 3.0], json!({"u": u, "v": v}), json!({})));
        assert_eq!(e.code, "COUPLER_POINT_AT_JOINT", "{e}");
        assert_eq!(e.errors[0].pointer, "/coupler_point");
    }
    for (u, v, who) in [
        (1e-4, 1e-4, MechanismId::Cognate1),
        (3.5 - 1e-4, 1e-4, MechanismId::Cognate2),
    ] {
        let r = ok(lk_at([4.0, 1.0, 3.5, 3.0], json!({"u": u, "v": v}), 20.0));
        let w = r
            .warnings
            .iter()
            .find(|w| w.code == WarningCode::NearDegenerateCognate)
            .expect("warning");
        assert_eq!(w.mechanism, Some(who));
    }
    for (u, v) in [(1e-8, 0.0), (3.5 * (1.0 - 1e-8), 1e-9), (1e-6, -1e-6)] {
        let _ = ok(lk_at([4.0, 1.0, 3.5, 3.0], json!({"u": u, "v": v}), 20.0));
    }
}

#[test]
fn collinear_and_near_degenerate_coupler_triangles() {
    let b = 3.5;
    // d + e = b (P between D and E), d = b + e and e = b + d (P beyond a joint), with tiny offsets.
    let shapes: [(f64, f64); 3] = [(1.5, 2.0), (5.0, 1.5), (1.5, 5.0)];
    for (d, e) in shapes {
        for delta in [0.0, 1e-16, -1e-16, 1e-13, -1e-13, 1e-12, 1e-10, 1e-8] {
            for side in [1, -1] {
                let d2 = d * (1.0 + delta);
                // Largest excess of one side over the sum of the other two, as the server sees it.
                let excess = (d2 - (b + e)).max(e - (b + d2)).max(b - (d2 + e));
                let slack = 1e-12 * b.max(d2).max(e);
                match attempt(lk_at(
                    [4.0, 1.0, b, 3.0],
                    json!({"d": d2, "e": e, "side": side}),
                    33.0,
                )) {
                    Ok(r) => {
                        assert!(excess <= slack, "accepted beyond the slack: {d2} {e}");
                        // Degenerate or within the slack: clamped onto the line DE. A triangle one
                        // ulp inside is a genuine (thin) triangle: P sits ~sqrt(ε)·b off the line.
                        if excess >= 0.0 {
                            assert!(
                                has_warning(&r, WarningCode::CollinearCouplerTriangle),
                                "{d2} {e}: {:?}",
                                r.warnings
                            );
                        }
                        assert_sync_passed(&r);
                    }
                    Err(err) => {
                        assert_eq!(err.code, "COUPLER_TRIANGLE_INVALID", "{d2} {e}: {err}");
                        assert!(excess > slack, "rejected within the slack: {d2} {e}");
                    }
                }
            }
        }
    }
    // θ3 = 90° ± tiny: C_x ill-conditioned but finite.
    for dv in [0.0, 1e-15, 1e-9] {
        let _ = ok(lk_at(
            [3.1, 1.13, 1.23, 1.04],
            json!({"u": dv, "v": 0.92}),
            30.0,
        ));
    }
}

#[test]
fn random_near_degenerate_triangles() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..stress_cases() / 4 {
        let b = log_uniform(&mut rng, 1e-2, 1e2);
        let d = b * rng.random_range(0.01..0.99);
        let gap = [0.0, 1e-15, 1e-12, 1e-9, -1e-15, -1e-12][rng.random_range(0..6)];
        let e = (b - d) * (1.0 + gap);
        let (l, a, c) = (
            b * rng.random_range(0.5..2.0),
            b * rng.random_range(0.1..1.0),
            b * rng.random_range(0.5..2.0),
        );
        let req = lk_at(
            [l, a, b, c],
            json!({"d": d, "e": e, "side": 1}),
            rng.random_range(-180.0..180.0),
        );
        if let Err(err) = attempt(req) {
            assert!(
                ["NOT_ASSEMBLABLE", "COUPLER_TRIANGLE_INVALID"].contains(&err.code),
                "{err}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Rejections and limits
// ---------------------------------------------------------------------------------------------

#[test]
fn rejections_carry_codes_and_pointers() {
    let cp = json!({"d": 0.92, "e": 1.56, "side": 1});
    let e = fail(lk([3.1, -1.0, 1.23, 0.0], cp.clone(), json!({})));
    assert_eq!(e.code, "NON_POSITIVE_LENGTH");
    assert_eq!(e.class, ProblemClass::InvalidInput);
    let ptrs: Vec<_> = e.errors.iter().map(|i| i.pointer.as_str()).collect();
    assert_eq!(ptrs, ["/crank", "/rocker"]);
    let e = fail(lk(
        [3.1, 1.13, 1.23, 1.04],
        json!({"d": -0.1, "e": 1.56}),
        json!({}),
    ));
    assert_eq!(
        (e.code, e.errors[0].pointer.as_str()),
        ("NON_POSITIVE_LENGTH", "/coupler_point/d")
    );
    let e = fail(lk([0.0, 1.13, 1.23, 1.04], cp.clone(), json!({})));
    assert_eq!(
        (e.code, e.errors[0].pointer.as_str()),
        ("COINCIDENT_PIVOTS", "/ground/B")
    );
    let e = fail(lk([1e-13, 1.13, 1.23, 1.04], cp.clone(), json!({})));
    assert_eq!(e.code, "COINCIDENT_PIVOTS");
    let e = fail(lk(
        [3.1, 1.13, 1.23, 1.04],
        json!({"d": 0.2, "e": 1.56}),
        json!({}),
    ));
    assert_eq!(
        (e.code, e.errors[0].pointer.as_str()),
        ("COUPLER_TRIANGLE_INVALID", "/coupler_point")
    );
    let e = fail(lk([10.0, 1.0, 2.0, 3.0], cp.clone(), json!({})));
    assert_eq!(
        (e.code, e.class),
        ("NOT_ASSEMBLABLE", ProblemClass::Infeasible)
    );
    // Longest = sum of the others: a rigid, single configuration.
    let e = fail(lk(
        [6.0, 1.0, 2.0, 3.0],
        json!({"u": 0.5, "v": 0.5}),
        json!({}),
    ));
    assert_eq!(e.code, "NOT_ASSEMBLABLE");
    let e = fail(lk(
        [3.1, 1.13, 1.23, 1.04],
        cp.clone(),
        json!({"options": {"points_per_circuit": 8, "grashof_rtol": 0.1}}),
    ));
    let ptrs: Vec<_> = e.errors.iter().map(|i| i.pointer.as_str()).collect();
    assert_eq!(
        ptrs,
        ["/options/points_per_circuit", "/options/grashof_rtol"]
    );
    // Missing fields and mixed modes.
    let e = fail(json!({"crank": 1.0}));
    assert_eq!(e.errors.len(), 4, "{e}");
    let e = fail(
        json!({"joints": {"A": [0, 0], "B": [3, 0], "D": [1, 0], "E": [2, 1], "P": [1, 1]}, "crank": 1.0, "branch": 1}),
    );
    let ptrs: Vec<_> = e.errors.iter().map(|i| i.pointer.as_str()).collect();
    assert_eq!(ptrs, ["/crank", "/branch"]);
    let e =
        fail(json!({"joints": {"A": [0, 0], "B": [0, 0], "D": [1, 0], "E": [2, 1], "P": [1, 1]}}));
    assert_eq!(
        (e.code, e.errors[0].pointer.as_str()),
        ("COINCIDENT_PIVOTS", "/joints/B")
    );
    let e = fail(
        json!({"ground": {"B": [1e200, 0]}, "crank": 1.0, "coupler": 1.0, "rocker": 1.0, "coupler_point": {"u": 0.5, "v": 0.5}}),
    );
    assert_eq!(e.errors[0].pointer, "/ground/B/0");
    let e = fail(
        json!({"ground": {"B": [3, 0], "length": 3.0}, "crank": 1.0, "coupler": 1.0, "rocker": 1.0, "coupler_point": {"u": 0.5, "v": 0.5}}),
    );
    assert_eq!(e.errors[0].pointer, "/ground/length");
}

#[test]
fn decode_errors_for_malformed_shapes() {
    let bad = [
        json!({"branch": 2}),
        json!({"branch": 0}),
        json!({"coupler_point": {"d": 1.0, "e": 1.0, "u": 0.5}}),
        json!({"coupler_point": {"d": 1.0}}),
        json!({"coupler_point": {"d": 1.0, "e": 1.0, "side": 0}}),
        json!({"options": {"spacing": "cosine"}}),
        json!({"options": {"verify": ["sync", "proof"]}}),
        json!({"angle_reference": "local"}),
        json!({"unknown": 1}),
        json!({"options": {"points_per_circuit": -5}}),
    ];
    for v in bad {
        assert!(
            serde_json::from_value::<CognatesRequest>(v.clone()).is_err(),
            "should not decode: {v}"
        );
    }
}

#[test]
fn too_many_points_and_deadline() {
    // Grashof double rocker: verification samples 3 × 2 circuits × 1e5 = 6e5 points, fixed-branch
    // curves another (2 + 1 + 2) intervals × 1e5 = 5e5: above the 1e6 cap.
    let base = lk(
        [4.0, 3.0, 1.0, 3.5],
        json!({"d": 0.8, "e": 0.6, "side": 1}),
        json!({}),
    );
    let mut v = base.clone();
    v["options"] = json!({"curves": true, "points_per_circuit": 100000, "curve_mode": "fixed_branch", "verify": ["sync"]});
    let e = fail(v);
    assert_eq!(
        (e.code, e.class),
        ("TOO_MANY_POINTS", ProblemClass::TooLarge)
    );
    assert_eq!(e.errors[0].pointer, "/options/points_per_circuit");
    // An exhausted budget stops sampling with a typed failure.
    let mut v = base;
    v["options"] = json!({"curves": true, "points_per_circuit": 100000});
    let req: CognatesRequest = serde_json::from_value(v).expect("decodes");
    let e = run(req, &Budget::new(Duration::ZERO)).expect_err("deadline");
    assert_eq!(e.code, "DEADLINE_EXCEEDED");
}

#[test]
fn huge_angles_and_fixed_branch_without_snapshot() {
    let r = ok(lk_at(
        [3.1, 1.13, 1.23, 1.04],
        json!({"d": 0.92, "e": 1.56}),
        1e15,
    ));
    assert!(r.mechanisms[0].snapshot.is_some());
    let mut opts = all_options();
    opts["curve_mode"] = json!("fixed_branch");
    let r = ok(lk(
        [3.1, 1.13, 1.23, 1.04],
        json!({"d": 0.92, "e": 1.56}),
        json!({"options": opts.clone()}),
    ));
    assert!(has_warning(&r, WarningCode::FixedBranchDefaultBranches));
    let r = ok(lk(
        [3.1, 1.13, 1.23, 1.04],
        json!({"d": 0.92, "e": 1.56}),
        json!({"input_angle_deg": 100.0, "options": opts}),
    ));
    assert!(has_warning(&r, WarningCode::FixedBranchDefaultBranches));
}
