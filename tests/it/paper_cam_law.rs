//! Spec validation cases of `shared/specs/cam_law_fit.md` for the law evaluator and the
//! `/v1/cam-law/evaluate` computation: §5.2 golden values, §5.3 catalogue peaks, Appendix A peak
//! factors and the explicit MT/MS pieces of A.1, and the rejections of §2/§8b through `run()`.

// The Appendix-A table prints rounded constants (1.5708 = π/2 ...): they are the test data.
#![allow(clippy::approx_constant)]
// Reference formulas are written as printed in the spec.
#![allow(clippy::suboptimal_flops)]

use std::f64::consts::PI;

use approx::assert_relative_eq;
use mechcalc::calc::cam_law::catalogue::{NamedLaw, TABLE3, nearest};
use mechcalc::calc::cam_law::law::{
    BoundaryConditions, Quantity, SevenSegmentLaw, accelerations_cramer,
};
use mechcalc::calc::cam_law::run;
use mechcalc::calc::cam_law::wire::{EvaluateRequest, EvaluateResponse, Warning};
use mechcalc::calc::{CalcFailure, ProblemClass};
use mechcalc::numerics::Budget;
use serde_json::{Value, json};

use crate::support::cam_table1;
use cam_table1::{PHASE2_BC, PHASE2_C, TABLE1_BC};

/// Spec §5.2: 1e-9 absolute on s, v, a.
const ABS_SVA: f64 = 1e-9;
/// Spec §5.2: 1e-7 relative on jerk.
const REL_J: f64 = 1e-7;

fn table1_law() -> SevenSegmentLaw {
    SevenSegmentLaw::try_new(&[2.0, 4.0, 6.0, 3.0, 8.0, 7.0, 1.0], &TABLE1_BC)
        .expect("valid Table-1 law")
}

fn close(what: &str, got: f64, want: f64, abs: f64) {
    assert!(
        (got - want).abs() <= abs,
        "{what}: got {got:.12}, want {want:.12}, |diff| {:.3e} > {abs:e}",
        (got - want).abs()
    );
}

fn close_rel(what: &str, got: f64, want: f64, rel: f64, abs: f64) {
    let tol = abs.max(rel * want.abs());
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got:.12}, want {want:.12}, |diff| {:.3e} > {tol:e}",
        (got - want).abs()
    );
}

/// §5.2 Table-1 law: A1, A2, knots.
#[test]
fn table1_peaks_and_knots() {
    let law = table1_law();
    close("A1", law.a1(), 4.0093387580, 1e-9);
    close("A2", law.a2(), -2.2475427443, 1e-9);
    let knot_t = [
        0.0, 0.064516, 0.193548, 0.387097, 0.483871, 0.741935, 0.967742, 1.0,
    ];
    let knot_s = cam_table1::TABLE1_KNOT_S;
    let knot_v = cam_table1::TABLE1_KNOT_V;
    for (k, knot) in law.knots().iter().enumerate() {
        close(
            &format!("knot t_{k} (printed to 6 digits)"),
            knot.x,
            knot_t[k],
            5e-7,
        );
        close(&format!("knot s_{k}"), knot.s, knot_s[k], 1e-9);
        close(&format!("knot v_{k}"), knot.v, knot_v[k], 1e-9);
    }
    let p = law.peaks();
    close("v_max (spec §8 example)", p.v_max_abs, 1.4088456, 5e-8);
    close("x_at_v_max", p.x_at_v_max, 0.3870968, 5e-8);
    close_rel(
        "jerk_max_abs_finite",
        p.jerk_max_abs_finite,
        167.877012,
        5e-9,
        0.0,
    );
    close("a_max_abs", p.a_max_abs, 4.0093388, 5e-8);
    assert!(
        law.jumps().is_empty(),
        "Table-1 law has no acceleration jump: {:?}",
        law.jumps()
    );
}

/// §5.2 Table-1 law table of s, v, a, j at 7 abscissae (1e-9 abs on s, v, a; 1e-7 rel on j).
#[test]
fn table1_law_values() {
    let law = table1_law();
    #[rustfmt::skip]
    let rows: [[f64; 5]; 7] = [
        [0.0, 0.0, 0.2, 1.4, 63.53046592],
        [0.05, 0.0129788676, 0.3400775482, 3.8480590153, 21.98897790],
        [0.25, 0.1609163064, 1.1333264129, 3.5958666436, -14.39159427],
        [0.5, 0.4999836798, 1.4070675995, -0.2202977126, -13.61454858],
        [0.6, 0.6373951161, 1.3203763659, -1.4596622488, -10.40267569],
        [0.9, 0.9424636896, 0.6843423755, -2.2475427443, 0.0],
        [1.0, 1.0, 0.5, 1.2, 167.87701186],
    ];
    let xs: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let mut out = vec![0.0; xs.len()];
    for (qi, q) in Quantity::ALL.into_iter().enumerate() {
        law.eval_quantity_into(&xs, q, &mut out);
        for (r, got) in rows.iter().zip(&out) {
            let want = r[qi + 1];
            let single = law.eval(r[0]).get(q);
            assert_relative_eq!(single, *got, max_relative = 1e-15, epsilon = 1e-15);
            if q == Quantity::J {
                close_rel(&format!("j({})", r[0]), *got, want, REL_J, 1e-9);
            } else {
                close(&format!("{q:?}({})", r[0]), *got, want, ABS_SVA);
            }
        }
    }
}

/// §5.2 modified trapezoid, zero BCs, unit rise/time.
#[test]
fn modified_trapezoid_golden() {
    let law = SevenSegmentLaw::try_new(&TABLE3[4].coefficients, &BoundaryConditions::UNIT_RISE)
        .expect("MT");
    let ca = 8.0 * PI / (PI + 2.0);
    close("A1 = 8π/(π+2)", law.a1(), 4.8881237628, 1e-9);
    close("A1 closed form", law.a1(), ca, 1e-14);
    close("A2 = −A1", law.a2(), -ca, 1e-14);
    close("s(0.25)", law.eval(0.25).s, 0.1044801940, ABS_SVA);
    close("v(0.25)", law.eval(0.25).v, 1.0, ABS_SVA);
    close("s(0.4)", law.eval(0.4).s, 0.3094590641, ABS_SVA);
    close("v(0.4)", law.eval(0.4).v, 1.7312183006, ABS_SVA);
    close("a(0.4)", law.eval(0.4).a, 4.6488819571, ABS_SVA);
    close_rel("j(0)", law.eval(0.0).j, 61.42597481, REL_J, 0.0);
}

/// §5.2 L9 (asymmetric trapezoid).
#[test]
fn l9_golden() {
    let law = SevenSegmentLaw::try_new(&TABLE3[8].coefficients, &BoundaryConditions::UNIT_RISE)
        .expect("L9");
    close("A1", law.a1(), 7.5854699299, 1e-9);
    close("A2", law.a2(), -3.0135823184, 1e-9);
    let p = law.peaks();
    close("v_max", p.v_max_abs, 2.0, 1e-12);
    close("x at v_max (c3 = 0)", p.x_at_v_max, 0.30, 1e-12);
    close("s(0.5)", law.eval(0.5).s, 0.6499655353, ABS_SVA);
}

/// §5.2 Phase II of the real cam (paper Tables 8/10; coefficients sum to 1.05, renormalized).
#[test]
fn phase2_real_cam() {
    let law = SevenSegmentLaw::try_new(&PHASE2_C, &PHASE2_BC).expect("Phase II");
    close("A1 (fall: negative)", law.a1(), -0.0181122881, 1e-9);
    close("A2", law.a2(), 0.0190255423, 1e-9);
    close("s(240°)", law.eval(240.0).s, 16.8411839026, ABS_SVA);
    close("v(255°)", law.eval(255.0).v, -0.5725431661, ABS_SVA);
    close("a(270°)", law.eval(270.0).a, 0.0189910046, ABS_SVA);
    let sum: f64 = law.coefficients().iter().sum();
    close("Σĉ after renormalization", sum, 1.0, 1e-15);

    // Through the endpoint: 422 without `normalize`, warning with it.
    let mut req = request(json!({
        "coefficients": PHASE2_C,
        "constraints": {"t_a": 210.0, "t_b": 300.0, "s_a": 20.38, "s_b": -4.27, "v_a": -0.0028, "v_b": 0.0183, "a_a": 0.0, "a_b": 0.006},
        "abscissa": {"values": [240.0, 255.0, 270.0]}
    }));
    expect_pointers(run(req.clone(), &Budget::unlimited()), &["/coefficients"]);
    req.normalize = true;
    let resp = run(req, &Budget::unlimited()).expect("normalize: true accepts sum 1.05");
    assert_eq!(resp.warnings, vec![Warning::CoefficientsRenormalized]);
    let c = resp.curves.expect("curves");
    close(
        "s(240°) via run",
        c.s.expect("s")[0],
        16.8411839026,
        ABS_SVA,
    );
    close(
        "v(255°) via run",
        c.v.expect("v")[1],
        -0.5725431661,
        ABS_SVA,
    );
    close("a(270°) via run", c.a.expect("a")[2], 0.0189910046, ABS_SVA);
}

/// §5.3 catalogue: A1, A2, v_max for all nine Table-3 vectors (zero BCs, unit rise/time);
/// tolerances from the printed digits (exact closed forms: 1e-12).
#[test]
fn catalogue_table3_peaks() {
    let ms = 4.0 * PI * PI / (PI + 4.0);
    let mt = 8.0 * PI / (PI + 2.0);
    // (A1, A2, v_max, tolerance on A, tolerance on v_max)
    let want: [(f64, f64, f64, f64, f64); 9] = [
        (ms, -ms, 1.7596, 1e-12, 5e-5),
        (4.0, -4.0, 2.0, 1e-12, 1e-12),
        (16.0 / 3.0, -16.0 / 3.0, 4.0 / 3.0, 1e-12, 1e-12),
        (PI * PI / 2.0, -PI * PI / 2.0, PI / 2.0, 1e-12, 1e-12),
        (mt, -mt, 2.0, 1e-12, 1e-12),
        (5.6307308351, -5.6307308351, 1.6, 5e-11, 5e-2),
        (6.5174983504, -6.5174983504, 4.0 / 3.0, 5e-11, 1e-12),
        (2.0 * PI, -2.0 * PI, 2.0, 1e-12, 1e-12),
        (7.5854699299, -3.0135823184, 2.0, 5e-11, 1e-12),
    ];
    close("L1 A1 printed 5.5279571", ms, 5.5279571, 5e-8);
    close("L4 A1 printed 4.9348022", PI * PI / 2.0, 4.9348022, 5e-8);
    close("L5 A1 printed 4.8881238", mt, 4.8881238, 5e-8);
    for (entry, (a1, a2, vmax, tol_a, tol_v)) in TABLE3.iter().zip(want) {
        let law = SevenSegmentLaw::try_new(&entry.coefficients, &BoundaryConditions::UNIT_RISE)
            .expect(entry.id);
        let p = law.peaks();
        close(&format!("{} A1", entry.id), p.a1, a1, tol_a);
        close(&format!("{} A2", entry.id), p.a2, a2, tol_a);
        close(&format!("{} v_max", entry.id), p.v_max_abs, vmax, tol_v);
        assert_eq!(nearest(&entry.coefficients).0.id, entry.id);
        assert!(nearest(&entry.coefficients).1 < 1e-15);
    }
    // L6 sums to 1 after the §3.7 erratum (c3 = 0.25).
    close("L6 sum", TABLE3[5].coefficients.iter().sum(), 1.0, 1e-15);
}

/// Appendix A: peak factors Cv, Ca, Cj match the printed table (tolerance from its digits) and
/// the dense maxima of the closed forms.
#[test]
fn appendix_a_peak_factors() {
    // (law, Cv, Ca, Cj, half-unit of the last printed digit for Cv, Ca, Cj)
    let inf = f64::INFINITY;
    let table: [(NamedLaw, f64, f64, f64, [f64; 3]); 11] = [
        (NamedLaw::ConstantVelocity, 1.0, inf, inf, [0.0, 0.0, 0.0]),
        (
            NamedLaw::ConstantAcceleration,
            2.0,
            4.0,
            inf,
            [0.0, 0.0, 0.0],
        ),
        (
            NamedLaw::SimpleHarmonic,
            1.5708,
            4.9348,
            15.503,
            [5e-5, 5e-5, 5e-4],
        ),
        (NamedLaw::Cycloidal, 2.0, 6.2832, 39.478, [0.0, 5e-5, 5e-4]),
        (NamedLaw::Cubic, 1.5, 6.0, 12.0, [0.0, 0.0, 0.0]),
        (
            NamedLaw::Polynomial345,
            1.875,
            5.7735,
            60.0,
            [0.0, 5e-5, 0.0],
        ),
        (
            NamedLaw::Polynomial4567,
            2.1875,
            7.5132,
            52.5,
            [0.0, 5e-5, 0.0],
        ),
        (
            NamedLaw::Polynomial56789,
            2.4609,
            9.3720,
            78.75,
            [5e-5, 5e-5, 0.0],
        ),
        (
            NamedLaw::DoubleHarmonic,
            2.0405,
            9.8696,
            42.41,
            [5e-5, 5e-5, 5e-3],
        ),
        (
            NamedLaw::ModifiedTrapezoid,
            2.0,
            4.8881,
            61.426,
            [0.0, 5e-5, 5e-4],
        ),
        (
            NamedLaw::ModifiedSine,
            1.7596,
            5.5280,
            69.466,
            [5e-5, 5e-5, 5e-4],
        ),
    ];
    let n = 200_000;
    for (law, cv, ca, cj, tol) in table {
        let f = law.peak_factors();
        let name = law.wire_name();
        close(&format!("{name} Cv"), f.cv, cv, tol[0].max(1e-12));
        match f.ca {
            Some(x) => close(&format!("{name} Ca"), x, ca, tol[1].max(1e-12)),
            None => assert!(ca.is_infinite(), "{name}: Ca should be finite"),
        }
        match f.cj {
            Some(x) => close(&format!("{name} Cj"), x, cj, tol[2].max(1e-12)),
            None => assert!(cj.is_infinite(), "{name}: Cj should be finite"),
        }
        // Dense maxima of the closed forms (grid 1/200 000; smooth maxima converge like h²).
        let (mut mv, mut ma, mut mj) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..=n {
            let s = law.eval_normalized(f64::from(k) / f64::from(n));
            mv = mv.max(s.v.abs());
            ma = ma.max(s.a.abs());
            mj = mj.max(s.j.abs());
        }
        close(&format!("{name} dense Cv"), mv, f.cv, 1e-9);
        if let Some(x) = f.ca {
            close(&format!("{name} dense Ca"), ma, x, 1e-8);
        }
        if let Some(x) = f.cj {
            close(&format!("{name} dense Cj"), mj, x, 1e-7);
        }
        // Unit rise: S(0) = 0, S(1) = 1.
        close(
            &format!("{name} S(0)"),
            law.eval_normalized(0.0).s,
            0.0,
            1e-15,
        );
        close(
            &format!("{name} S(1)"),
            law.eval_normalized(1.0).s,
            1.0,
            1e-15,
        );
    }
}

/// Appendix A.1: the explicit MT and MS pieces equal the general law with the class vectors,
/// and class members' peaks equal their factors (A.2).
#[test]
fn appendix_a1_explicit_pieces_match_general_law() {
    for named in NamedLaw::ALL {
        let Some(c) = named.seven_segment_coefficients() else {
            continue;
        };
        let law =
            SevenSegmentLaw::try_new(&c, &BoundaryConditions::UNIT_RISE).expect("class member");
        let n = 4000;
        let mut worst = [0.0f64; 4];
        for k in 0..=n {
            let x = f64::from(k) / f64::from(n);
            let g = law.eval(x);
            let e = named.eval_normalized(x);
            for (w, d) in worst
                .iter_mut()
                .zip([g.s - e.s, g.v - e.v, g.a - e.a, g.j - e.j])
            {
                *w = w.max(d.abs());
            }
        }
        let name = named.wire_name();
        assert!(
            worst[0] < 1e-14 && worst[1] < 1e-13 && worst[2] < 1e-12,
            "{name}: worst |Δ| s,v,a = {worst:?}"
        );
        assert!(worst[3] < 1e-10, "{name}: worst |Δj| = {}", worst[3]);
        let p = law.peaks();
        let f = named.peak_factors();
        close(&format!("{name} v_max = Cv"), p.v_max_abs, f.cv, 1e-13);
        close(
            &format!("{name} a_max = Ca"),
            p.a_max_abs,
            f.ca.expect("finite Ca"),
            1e-13,
        );
        if let Some(cj) = f.cj {
            close(
                &format!("{name} jerk_max = Cj"),
                p.jerk_max_abs_finite,
                cj,
                1e-11,
            );
        }
    }
    // A.1: S(1) = 1 and V(½) = 2 for MT.
    close(
        "MT V(1/2)",
        NamedLaw::ModifiedTrapezoid.eval_normalized(0.5).v,
        2.0,
        1e-15,
    );
}

/// §3.2: both A-formulas agree on the spec's cases.
#[test]
fn cramer_matches_centroid_on_spec_cases() {
    let cases = [
        ([2.0, 4.0, 6.0, 3.0, 8.0, 7.0, 1.0], TABLE1_BC),
        (PHASE2_C, PHASE2_BC),
    ];
    for (c, bc) in cases {
        let law = SevenSegmentLaw::try_new(&c, &bc).expect("valid");
        let (a1, a2) = accelerations_cramer(&c, &bc).expect("non-singular");
        assert_relative_eq!(a1, law.a1(), max_relative = 1e-12);
        assert_relative_eq!(a2, law.a2(), max_relative = 1e-12);
    }
}

/// Acceleration jumps of §3.2: L2 (c0 = c2 = c4 = c6 = 0) jumps at 0, ½ and 1.
#[test]
fn jumps_of_constant_acceleration() {
    let law = SevenSegmentLaw::try_new(&TABLE3[1].coefficients, &BoundaryConditions::UNIT_RISE)
        .expect("L2");
    let j = law.jumps();
    assert_eq!(j.len(), 3, "{j:?}");
    let want = [(0.0, 0.0, 4.0), (0.5, 4.0, -4.0), (1.0, -4.0, 0.0)];
    for (got, (x, l, r)) in j.iter().zip(want) {
        close("jump x", got.x, x, 1e-15);
        close("jump a_left", got.a_left, l, 1e-14);
        close("jump a_right", got.a_right, r, 1e-14);
    }
    // Value convention: right-continuous inside, left-continuous at t_b.
    close("a(0) = A1", law.eval(0.0).a, 4.0, 1e-14);
    close("a(0.5) = A2", law.eval(0.5).a, -4.0, 1e-14);
    close("a(1) = A2", law.eval(1.0).a, -4.0, 1e-14);
    assert_eq!(law.peaks().jerk_max_abs_finite.to_bits(), 0.0f64.to_bits());
}

// ---------------------------------------------------------------------------------------------
// The endpoint computation: validation (§2, §8b) through `run()`.

fn request(v: Value) -> EvaluateRequest {
    serde_json::from_value(v).expect("request decodes")
}

fn expect_pointers(r: Result<EvaluateResponse, CalcFailure>, pointers: &[&str]) -> CalcFailure {
    let err = r.expect_err("request must be rejected");
    assert_eq!(err.class, ProblemClass::InvalidInput, "{err}");
    let got: Vec<&str> = err.errors.iter().map(|e| e.pointer.as_str()).collect();
    assert_eq!(got, pointers, "{err}");
    for e in &err.errors {
        assert!(!e.detail.is_empty());
    }
    err
}

fn base() -> Value {
    json!({
        "coefficients": [0.0645, 0.129, 0.1935, 0.0968, 0.2581, 0.2258, 0.0323],
        "constraints": {"t_a": 0.0, "t_b": 1.0, "s_a": 0.0, "s_b": 1.0, "v_a": 0.2, "v_b": 0.5, "a_a": 1.4, "a_b": 1.2},
        "abscissa": {"values": [0.0, 0.25, 0.5, 0.75, 1.0]}
    })
}

fn with(mut v: Value, pointer: &str, value: Value) -> Value {
    *v.pointer_mut(pointer)
        .expect("pointer exists in the base request") = value;
    v
}

fn without(mut v: Value, key: &str) -> Value {
    v.as_object_mut().expect("object").remove(key);
    v
}

#[test]
#[expect(
    clippy::too_many_lines,
    reason = "a table of 23 rejected requests with the pointers each 422 must carry, checked by one loop; one row per case"
)]
fn rejections_carry_pointers() {
    let b = Budget::unlimited();
    let cases: Vec<(&str, Value, Vec<&str>)> = vec![
        (
            "sum 1.05 without normalize",
            with(base(), "/coefficients/0", json!(0.1145)),
            vec!["/coefficients"],
        ),
        (
            "negative coefficient",
            with(base(), "/coefficients/2", json!(-0.1)),
            vec!["/coefficients/2"],
        ),
        (
            "empty first pulse",
            with(
                base(),
                "/coefficients",
                json!([0, 0, 0, 0.25, 0.25, 0.25, 0.25]),
            ),
            vec!["/coefficients"],
        ),
        (
            "empty second pulse",
            with(
                base(),
                "/coefficients",
                json!([0.25, 0.25, 0.25, 0.25, 0, 0, 0]),
            ),
            vec!["/coefficients"],
        ),
        (
            "near-empty pulse",
            with(
                base(),
                "/coefficients",
                json!([1e-10, 0, 0, 0.5, 0.25, 0.25, 0.0]),
            ),
            vec!["/coefficients"],
        ),
        (
            "6 coefficients",
            with(
                base(),
                "/coefficients",
                json!([0.2, 0.2, 0.2, 0.2, 0.1, 0.1]),
            ),
            vec!["/coefficients"],
        ),
        (
            "both coefficients and law",
            with(base(), "/constraints", json!({}))
                .as_object()
                .cloned()
                .map(|mut o| {
                    o.insert("law".into(), json!("cycloidal"));
                    Value::Object(o)
                })
                .expect("object"),
            vec!["/law"],
        ),
        (
            "neither coefficients nor law",
            without(base(), "coefficients"),
            vec!["/coefficients"],
        ),
        (
            "t_b <= t_a",
            with(
                with(base(), "/constraints/t_b", json!(0.0)),
                "/abscissa/values",
                json!([0.0]),
            ),
            vec!["/constraints/t_b"],
        ),
        (
            "|s_b| > 1e12",
            with(base(), "/constraints/s_b", json!(2e12)),
            vec!["/constraints/s_b"],
        ),
        (
            "abscissa not increasing",
            with(base(), "/abscissa/values", json!([0.0, 0.5, 0.5, 1.0])),
            vec!["/abscissa/values/2"],
        ),
        (
            "sample outside [t_a, t_b]",
            with(base(), "/abscissa/values", json!([0.0, 0.5, 1.1])),
            vec!["/abscissa/values/2"],
        ),
        (
            "sample before t_a",
            with(base(), "/abscissa/values", json!([-1e-6, 0.5])),
            vec!["/abscissa/values/0"],
        ),
        (
            "empty values",
            with(base(), "/abscissa/values", json!([])),
            vec!["/abscissa/values"],
        ),
        (
            "grid count 1",
            with(
                base(),
                "/abscissa",
                json!({"grid": {"start": 0.0, "end": 1.0, "count": 1}}),
            ),
            vec!["/abscissa/grid/count"],
        ),
        (
            "grid count 200001",
            with(
                base(),
                "/abscissa",
                json!({"grid": {"start": 0.0, "end": 1.0, "count": 200_001}}),
            ),
            vec!["/abscissa/grid/count"],
        ),
        (
            "grid end <= start",
            with(
                base(),
                "/abscissa",
                json!({"grid": {"start": 1.0, "end": 0.0, "count": 10}}),
            ),
            vec!["/abscissa/grid/end"],
        ),
        (
            "grid beyond t_b",
            with(
                base(),
                "/abscissa",
                json!({"grid": {"start": 0.0, "end": 2.0, "count": 10}}),
            ),
            vec!["/abscissa/grid/end"],
        ),
        (
            "values and grid",
            with(
                base(),
                "/abscissa",
                json!({"values": [0.0], "grid": {"start": 0.0, "end": 1.0, "count": 10}}),
            ),
            vec!["/abscissa"],
        ),
        (
            "neither values nor grid",
            with(base(), "/abscissa", json!({})),
            vec!["/abscissa"],
        ),
        (
            "named law outside the class with end rates",
            json!({"law": "polynomial_345", "constraints": {"v_a": 0.1, "a_b": -2.0}}),
            vec!["/constraints/v_a", "/constraints/a_b"],
        ),
        (
            "unit label too long",
            with(base(), "/abscissa", json!({"values": [0.5]}))
                .as_object()
                .cloned()
                .map(|mut o| {
                    o.insert("units".into(), json!({"x": "x".repeat(33)}));
                    Value::Object(o)
                })
                .expect("object"),
            vec!["/units/x"],
        ),
        (
            "every problem at once",
            json!({
                "coefficients": [0.5, -0.1, 0.2, 0.2, 0.1, 0.1, 0.0],
                "constraints": {"t_a": 0.0, "t_b": 1.0, "s_b": 5e12},
                "abscissa": {"grid": {"start": 0.0, "end": 1.0, "count": 0}}
            }),
            // Listed in the order of the request's fields (the door walks them in order).
            vec![
                "/coefficients/1",
                "/constraints/s_b",
                "/abscissa/grid/count",
            ],
        ),
    ];
    for (name, req, pointers) in cases {
        let r = run(request(req), &b);
        let err = r
            .as_ref()
            .err()
            .map(ToString::to_string)
            .unwrap_or_default();
        eprintln!("{name}: {err}");
        expect_pointers(r, &pointers);
    }
}

/// Non-finite values cannot arrive through JSON, but direct callers of `run()` must get a 422.
#[test]
fn non_finite_inputs_are_rejected() {
    let b = Budget::unlimited();
    let mut req = request(base());
    req.constraints.v_a = Some(f64::NAN);
    expect_pointers(run(req, &b), &["/constraints/v_a"]);
    let mut req = request(base());
    if let Some(c) = req.coefficients.as_mut() {
        c[3] = f64::INFINITY;
    }
    expect_pointers(run(req, &b), &["/coefficients/3"]);
    let mut req = request(base());
    if let Some(a) = req.abscissa.as_mut() {
        a.values = Some(vec![0.0, f64::NAN, 1.0]);
    }
    expect_pointers(run(req, &b), &["/abscissa/values/1"]);
}

#[test]
fn unknown_fields_are_decode_errors() {
    assert!(
        serde_json::from_value::<EvaluateRequest>(with(
            base(),
            "/constraints",
            json!({"t_c": 1.0})
        ))
        .is_err()
    );
    let mut v = base();
    v.as_object_mut()
        .expect("object")
        .insert("extra".into(), json!(1));
    assert!(serde_json::from_value::<EvaluateRequest>(v).is_err());
}

#[test]
fn accepted_variants_and_warnings() {
    let b = Budget::unlimited();
    // Inside the 1e-9·Δt tolerance: clamped, evaluated at t_b, reported at the given abscissa.
    let r = run(
        request(with(base(), "/abscissa/values", json!([0.0, 1.0 + 5e-10]))),
        &b,
    )
    .expect("clamped");
    let c = r.curves.expect("curves");
    close("x echoed", c.x[1], 1.0 + 5e-10, 0.0);
    close("s clamped to s_b", c.s.expect("s")[1], 1.0, 1e-14);
    // Sum off by 5e-4: accepted, renormalized with a warning.
    let r =
        run(request(with(base(), "/coefficients/0", json!(0.065))), &b).expect("sum within 1e-3");
    assert_eq!(r.warnings, vec![Warning::CoefficientsRenormalized]);
    close(
        "Σĉ",
        r.coefficients.expect("coefficients").iter().sum(),
        1.0,
        1e-15,
    );
    // The §8b example itself: sum is 1 up to round-off, no warning.
    let r = run(request(base()), &b).expect("spec example");
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    // Flat law: Δs = 0 with zero end rates.
    let r = run(request(json!({"coefficients": [1, 1, 1, 1, 1, 1, 1], "normalize": true, "constraints": {"s_b": 0.0}})), &b)
        .expect("flat law");
    assert_eq!(
        r.warnings,
        vec![Warning::CoefficientsRenormalized, Warning::NonIdentifiable]
    );
    assert!(r.curves.is_none());
    close("flat A1", r.peaks.a1.expect("a1"), 0.0, 1e-15);
    // A rise that starts too fast must first decelerate: A1 < 0.
    let r = run(
        request(json!({"law": "modified_trapezoid", "constraints": {"v_a": 4.0}})),
        &b,
    )
    .expect("unusual");
    assert!(
        r.warnings.contains(&Warning::PeakSignUnusual),
        "{:?} A1 = {:?}",
        r.warnings,
        r.peaks.a1
    );
    assert!(
        r.peaks.peak_factors.is_none(),
        "factors only with zero end rates"
    );
    // Quantities subset and default: only the requested ones appear.
    let r = run(
        request(
            with(without(base(), "coefficients"), "/constraints", json!({}))
                .as_object()
                .cloned()
                .map(|mut o| {
                    o.insert("law".into(), json!("cycloidal"));
                    o.insert("quantities".into(), json!(["a", "a"]));
                    Value::Object(o)
                })
                .expect("object"),
        ),
        &b,
    )
    .expect("cycloidal");
    let c = r.curves.expect("curves");
    assert!(c.s.is_none() && c.v.is_none() && c.j.is_none());
    let a = c.a.expect("a");
    for (x, a) in c.x.iter().zip(&a) {
        close(
            "cycloidal a = 2π sin 2πx",
            *a,
            2.0 * PI * (2.0 * PI * x).sin(),
            1e-13,
        );
    }
}

/// Named laws outside the class: closed forms scaled to physical units, peaks Cv, Ca, Cj scaled.
#[test]
fn named_law_outside_class_scaled() {
    let b = Budget::unlimited();
    let (ta, tb, sa, sb): (f64, f64, f64, f64) = (2.0, 6.0, 10.0, 4.0); // a fall of 6 U over 4 x
    let (dt, ds) = (tb - ta, sb - sa);
    let xs: Vec<f64> = (0..=40).map(|k| ta + dt * f64::from(k) / 40.0).collect();
    for named in [
        NamedLaw::Cubic,
        NamedLaw::Polynomial345,
        NamedLaw::Polynomial4567,
        NamedLaw::Polynomial56789,
        NamedLaw::DoubleHarmonic,
        NamedLaw::ConstantVelocity,
    ] {
        let req = request(
            json!({"law": named, "constraints": {"t_a": ta, "t_b": tb, "s_a": sa, "s_b": sb}, "abscissa": {"values": xs}}),
        );
        let r = run(req, &b).expect("named law");
        assert!(r.coefficients.is_none() && r.durations.is_none() && r.knots.is_none());
        let f = named.peak_factors();
        let name = named.wire_name();
        close(
            &format!("{name} v_max"),
            r.peaks.v_max_abs,
            f.cv * ds.abs() / dt,
            1e-14,
        );
        assert_eq!(r.peaks.a_max_abs.is_some(), f.ca.is_some());
        if let (Some(a), Some(ca)) = (r.peaks.a_max_abs, f.ca) {
            close(&format!("{name} a_max"), a, ca * ds.abs() / dt / dt, 1e-14);
        }
        if let (Some(j), Some(cj)) = (r.peaks.jerk_max_abs_finite, f.cj) {
            close(
                &format!("{name} jerk_max"),
                j,
                cj * ds.abs() / dt.powi(3),
                1e-13,
            );
        }
        let c = r.curves.expect("curves");
        let (s, v, a, j) = (
            c.s.expect("s"),
            c.v.expect("v"),
            c.a.expect("a"),
            c.j.expect("j"),
        );
        for (i, x) in xs.iter().enumerate() {
            let n = named.eval_normalized((x - ta) / dt);
            close(&format!("{name} s({x})"), s[i], sa + ds * n.s, 1e-12);
            close(&format!("{name} v({x})"), v[i], ds / dt * n.v, 1e-12);
            close(&format!("{name} a({x})"), a[i], ds / dt / dt * n.a, 1e-12);
            close(
                &format!("{name} j({x})"),
                j[i],
                ds / dt.powi(3) * n.j,
                1e-11,
            );
        }
        close(&format!("{name} s(t_b)"), s[40], sb, 1e-13);
    }
    // Cubic: acceleration jumps at both ends (A(0) = 6, A(1) = −6, scaled).
    let r = run(request(json!({"law": "cubic"})), &b).expect("cubic");
    assert_eq!(r.acceleration_jumps.len(), 2);
    close(
        "cubic jump at 0",
        r.acceleration_jumps[0].a_right,
        6.0,
        1e-14,
    );
    close(
        "cubic jump at 1",
        r.acceleration_jumps[1].a_left,
        -6.0,
        1e-14,
    );
    let r = run(request(json!({"law": "polynomial_345"})), &b).expect("3-4-5");
    assert!(r.acceleration_jumps.is_empty());
}

// ---------------------------------------------------------------------------------------------
// The api/ examples with their expected key outputs (format in api/README.md).

fn leaves_match(path: &str, want: &Value, got: &Value, errors: &mut Vec<String>) {
    match (want, got) {
        (Value::Object(w), Value::Object(g)) => {
            for (k, wv) in w {
                match g.get(k) {
                    Some(gv) => leaves_match(&format!("{path}/{k}"), wv, gv, errors),
                    None => errors.push(format!("{path}/{k}: missing in response")),
                }
            }
        }
        (Value::Array(w), Value::Array(g)) => {
            if w.len() == g.len() {
                for (i, (wv, gv)) in w.iter().zip(g).enumerate() {
                    leaves_match(&format!("{path}/{i}"), wv, gv, errors);
                }
            } else {
                errors.push(format!(
                    "{path}: length {} != expected {}",
                    g.len(),
                    w.len()
                ));
            }
        }
        (Value::Number(w), Value::Number(g)) => {
            let (w, g) = (
                w.as_f64().unwrap_or(f64::NAN),
                g.as_f64().unwrap_or(f64::NAN),
            );
            if !((g - w).abs() <= 1e-9 || (g - w).abs() <= 1e-6 * w.abs()) {
                errors.push(format!("{path}: got {g}, expected {w}"));
            }
        }
        _ if want == got => {}
        _ => errors.push(format!("{path}: got {got}, expected {want}")),
    }
}

#[test]
fn api_examples_match_expected() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cam_law");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("api/cam_law exists") {
        let path = entry.expect("dir entry").path();
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default()
            .to_owned();
        if !name.ends_with(".json") || name.ends_with(".expected.json") {
            continue;
        }
        let req: EvaluateRequest =
            serde_json::from_str(&std::fs::read_to_string(&path).expect("read"))
                .expect("example decodes");
        let resp = run(req, &Budget::unlimited()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let got = serde_json::to_value(&resp).expect("serializes");
        let expected_path = path.with_extension("expected.json");
        let want: Value = serde_json::from_str(
            &std::fs::read_to_string(&expected_path).expect("expected file exists"),
        )
        .expect("json");
        let mut errors = Vec::new();
        leaves_match("", &want, &got, &mut errors);
        assert!(errors.is_empty(), "{name}:\n{}", errors.join("\n"));
        n += 1;
    }
    assert_eq!(n, 2, "both cam_law examples were checked");
}
