//! Stress tests near every hazard of spec §6 for the law evaluator and `/v1/cam-law/evaluate`:
//! near-empty pulses, tiny segments (1e-12·Δt and below), extreme scales (Δt 1e-6..1e6, Δs
//! 1e-9..1e9, end rates at the 1e12 limit), sign changes and falls, huge or subnormal
//! coefficients. Every result must be a typed error or all-finite numbers: never NaN, never a
//! panic. `STRESS_CASES` scales the random sweep (default 20 000).

use mechcalc::calc::cam_law::law::{BoundaryConditions, LawError, Quantity, SevenSegmentLaw};
use mechcalc::calc::cam_law::run;
use mechcalc::calc::cam_law::wire::EvaluateRequest;
use mechcalc::numerics::Budget;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;

const COEFFICIENT_DRAWS: [f64; 12] = [
    0.0,
    0.0,
    1.0,
    0.25,
    1e-9,
    5e-10,
    1e-12,
    1e-15,
    1e-16,
    1e-310,
    1e300,
    f64::MAX,
];
const DT_DRAWS: [f64; 7] = [1e-6, 1e-3, 1.0, 1e3, 1e6, 1e-300, 1e-12];
const T_A_DRAWS: [f64; 6] = [0.0, -1.0, 1e6, -1e6, 1e12, 5e11];
const DS_DRAWS: [f64; 9] = [0.0, 1.0, -1.0, 1e-9, -1e-9, 1e9, -1e9, 1e12, -2e12];
const RATE_DRAWS: [f64; 9] = [0.0, 1.0, -1.0, 1e-6, 1e6, -1e6, 1e12, -1e12, 3.7];

/// Check a law: either `try_new` fails with a typed error, or knots, peaks, jumps and curves over
/// a grid (including points just outside the interval) are all finite.
fn check(c: &[f64; 7], bc: &BoundaryConditions) -> Result<(), LawError> {
    let law = SevenSegmentLaw::try_new(c, bc)?;
    let ctx = || format!("c = {c:?}, bc = {bc:?}");
    for k in law.knots() {
        assert!(
            [k.x, k.s, k.v, k.a_left, k.a_right]
                .iter()
                .all(|x| x.is_finite()),
            "knot {k:?}; {}",
            ctx()
        );
    }
    let p = law.peaks();
    assert!(
        [
            p.a1,
            p.a2,
            p.a_max_abs,
            p.v_max_abs,
            p.x_at_v_max,
            p.jerk_max_abs_finite
        ]
        .iter()
        .all(|x| x.is_finite()),
        "peaks {p:?}; {}",
        ctx()
    );
    assert!(
        p.x_at_v_max >= bc.t_a && p.x_at_v_max <= bc.t_b,
        "x_at_v_max outside: {p:?}; {}",
        ctx()
    );
    for j in law.jumps() {
        assert!(
            [j.x, j.a_left, j.a_right].iter().all(|x| x.is_finite()),
            "jump {j:?}; {}",
            ctx()
        );
    }
    assert!(
        law.coefficients()
            .iter()
            .all(|x| x.is_finite() && *x >= 0.0),
        "{}",
        ctx()
    );
    let dt = bc.t_b - bc.t_a;
    let mut xs: Vec<f64> = (0..=64)
        .map(|i| bc.t_a + dt * f64::from(i) / 64.0)
        .collect();
    xs.extend(law.knot_times());
    xs.extend([bc.t_a - dt, bc.t_b + dt, f64::MIN, f64::MAX]);
    let mut out = vec![0.0; xs.len()];
    for q in Quantity::ALL {
        law.eval_quantity_into(&xs, q, &mut out);
        assert!(
            out.iter().all(|x| x.is_finite()),
            "{q:?} not finite: {out:?}; {}",
            ctx()
        );
    }
    // Values stay inside what the peaks promise (|v| ≤ v_max, |a| ≤ a_max up to round-off).
    let mut v = vec![0.0; xs.len()];
    law.eval_quantity_into(&xs, Quantity::V, &mut v);
    let vmax = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(
        vmax <= p.v_max_abs.mul_add(1.0 + 1e-9, 1e-300),
        "sampled |v| {vmax} > v_max {}; {}",
        p.v_max_abs,
        ctx()
    );
    Ok(())
}

#[test]
fn tiny_segments_in_every_position() {
    for k in 0..7 {
        for tiny in [1e-9, 1e-12, 1e-14, 1e-15, 1e-16, 1e-300, 4.9e-324] {
            let mut c = [1.0; 7];
            c[k] = tiny;
            for bc in [
                BoundaryConditions::UNIT_RISE,
                BoundaryConditions {
                    t_a: 1e6,
                    t_b: 1e6 + 1e-3,
                    v_a: 1e3,
                    a_b: -1e6,
                    ..BoundaryConditions::UNIT_RISE
                },
            ] {
                check(&c, &bc)
                    .unwrap_or_else(|e| panic!("tiny segment c{k} = {tiny:e} must be valid: {e}"));
            }
        }
    }
    // A 1e-12·Δt segment keeps its jump semantics: with c0 = 1e-12 the law starts at a_a, but the
    // jerk of that segment is not a finite maximum (spec §6 item 2).
    let bc = BoundaryConditions {
        a_a: 0.5,
        ..BoundaryConditions::UNIT_RISE
    };
    let law = SevenSegmentLaw::try_new(&[1e-12, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], &bc).expect("valid");
    assert!((law.eval(0.0).a - 0.5).abs() < 1e-12);
    assert!(law.peaks().jerk_max_abs_finite < 1e3, "{:?}", law.peaks());
    // Below 1e-15 the segment is dropped: a(t_a) = A1.
    let law = SevenSegmentLaw::try_new(&[1e-16, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], &bc).expect("valid");
    assert!((law.eval(0.0).a - law.a1()).abs() < 1e-12);
}

#[test]
fn near_empty_pulses() {
    for area in [0.0, 1e-12, 5e-10, 9.9e-10, 1.1e-9, 1e-8, 1e-6] {
        for k in 0..3 {
            let mut c = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
            c[k] = area * 4.0; // normalized by the sum 4
            let r = check(&c, &BoundaryConditions::UNIT_RISE);
            let mut m = c;
            m.reverse();
            let r2 = check(&m, &BoundaryConditions::UNIT_RISE);
            let pulse = area
                * if k == 1 {
                    1.0
                } else {
                    std::f64::consts::FRAC_2_PI
                };
            if pulse < 1e-9 * 0.999 {
                assert!(
                    matches!(r, Err(LawError::EmptyFirstPulse { .. })),
                    "area {area:e} k {k}: {r:?}"
                );
                assert!(
                    matches!(r2, Err(LawError::EmptySecondPulse { .. })),
                    "area {area:e} k {k}: {r2:?}"
                );
            } else if pulse > 1e-9 * 1.001 {
                assert!(r.is_ok() && r2.is_ok(), "area {area:e} k {k}: {r:?} {r2:?}");
            }
        }
    }
}

#[test]
fn degenerate_boundary_conditions_are_typed_errors() {
    let c = [1.0; 7];
    let u = BoundaryConditions::UNIT_RISE;
    let cases = [
        BoundaryConditions { t_b: 0.0, ..u },
        BoundaryConditions { t_b: -1.0, ..u },
        BoundaryConditions { s_b: f64::NAN, ..u },
        BoundaryConditions {
            v_a: f64::INFINITY,
            ..u
        },
        BoundaryConditions {
            a_b: 1.0000001e12,
            ..u
        },
        BoundaryConditions {
            t_a: 1e12,
            t_b: 1e12 + 1e-4,
            ..u
        },
        BoundaryConditions {
            t_a: 0.0,
            t_b: 1e-300,
            s_b: 1e12,
            ..u
        },
    ];
    for bc in cases {
        let r = SevenSegmentLaw::try_new(&c, &bc);
        assert!(r.is_err(), "{bc:?} must be rejected");
    }
    for bad in [f64::NAN, -1.0, f64::NEG_INFINITY, -0.0 - 1e-300] {
        let mut cc = c;
        cc[3] = bad;
        assert!(
            SevenSegmentLaw::try_new(&cc, &u).is_err(),
            "coefficient {bad} must be rejected"
        );
    }
    assert!(matches!(
        SevenSegmentLaw::try_new(&[0.0; 7], &u),
        Err(LawError::EmptyFirstPulse { .. })
    ));
}

/// Random sweep over the hazard draws (fixed seed).
#[test]
fn random_hazard_sweep() {
    let n = crate::support::proptest_cfg::stress_cases(20_000);
    let mut rng = ChaCha8Rng::seed_from_u64(0x00ca_11a0);
    let mut ok = 0usize;
    let mut errors = std::collections::BTreeMap::<String, usize>::new();
    for _ in 0..n {
        let mut pick = |xs: &[f64]| xs[rng.random_range(0..xs.len())];
        let c: [f64; 7] = std::array::from_fn(|_| pick(&COEFFICIENT_DRAWS));
        let t_a = pick(&T_A_DRAWS);
        let dt = pick(&DT_DRAWS);
        let s_a = pick(&DS_DRAWS);
        let ds = pick(&DS_DRAWS);
        let r = std::array::from_fn::<f64, 4, _>(|_| pick(&RATE_DRAWS));
        let bc = BoundaryConditions {
            t_a,
            t_b: t_a + dt,
            s_a,
            s_b: s_a + ds,
            v_a: r[0],
            v_b: -r[1],
            a_a: r[2],
            a_b: -r[3],
        };
        match check(&c, &bc) {
            Ok(()) => ok += 1,
            Err(e) => {
                let key = format!("{e:?}")
                    .split([' ', '{'])
                    .next()
                    .unwrap_or_default()
                    .to_owned();
                *errors.entry(key).or_default() += 1;
            }
        }
    }
    eprintln!("{ok} valid laws, typed errors: {errors:?}");
    assert!(
        ok > n / 10,
        "the sweep must exercise valid laws too ({ok} of {n})"
    );
}

/// Falls, sign changes of the peaks and end rates opposing the motion.
#[test]
fn falls_and_sign_changes() {
    let patterns = [
        [1.0; 7],
        [0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        [0.2, 0.0, 0.0, 5.0, 0.0, 0.0, 0.2],
    ];
    for c in patterns {
        for ds in [-5.0, 0.0, 5.0] {
            for (va, vb, aa, ab) in [
                (0.0, 0.0, 0.0, 0.0),
                (20.0, -20.0, 0.0, 0.0),
                (-3.0, 4.0, 50.0, -70.0),
                (0.0, 0.0, -100.0, 100.0),
            ] {
                let bc = BoundaryConditions {
                    t_a: -2.0,
                    t_b: 1.0,
                    s_a: 3.0,
                    s_b: 3.0 + ds,
                    v_a: va,
                    v_b: vb,
                    a_a: aa,
                    a_b: ab,
                };
                check(&c, &bc).unwrap_or_else(|e| panic!("{c:?} {bc:?}: {e}"));
            }
        }
    }
}

/// The endpoint under extreme inputs: a typed failure or an all-finite response.
#[test]
fn endpoint_extremes() {
    let b = Budget::unlimited();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let laws = [
        json!({"coefficients": [0.0645, 0.129, 0.1935, 0.0968, 0.2581, 0.2258, 0.0323]}),
        json!({"law": "double_harmonic"}),
        json!({"law": "constant_velocity"}),
        json!({"law": "modified_sine"}),
        json!({"coefficients": [1e-12, 0, 1, 0, 1, 0, 1e-12], "normalize": true}),
    ];
    let mut n_ok = 0;
    for _ in 0..2000 {
        let mut req = laws[rng.random_range(0..laws.len())].clone();
        let zero_rates = rng.random_bool(0.5);
        let mut pick = |xs: &[f64]| xs[rng.random_range(0..xs.len())];
        let t_a = pick(&T_A_DRAWS);
        let dt = pick(&DT_DRAWS);
        let rate = |r: f64| if zero_rates { 0.0 } else { r };
        let obj = req.as_object_mut().expect("object");
        obj.insert(
            "constraints".into(),
            json!({"t_a": t_a, "t_b": t_a + dt, "s_a": 0.0, "s_b": pick(&DS_DRAWS),
                   "v_a": rate(pick(&RATE_DRAWS)), "v_b": rate(pick(&RATE_DRAWS)), "a_a": rate(pick(&RATE_DRAWS)), "a_b": rate(pick(&RATE_DRAWS))}),
        );
        obj.insert(
            "abscissa".into(),
            json!({"grid": {"start": t_a, "end": t_a + dt, "count": 33}}),
        );
        let Ok(req) = serde_json::from_value::<EvaluateRequest>(req) else {
            continue;
        };
        match run(req, &b) {
            Ok(resp) => {
                let v = serde_json::to_value(&resp).expect("serializes");
                assert!(
                    crate::support::finite::all_numbers_finite(&v),
                    "non-finite number in {v}"
                );
                n_ok += 1;
            }
            Err(e) => assert!(
                !e.code.is_empty() && (!e.errors.is_empty() || !e.detail.is_empty()),
                "{e}"
            ),
        }
    }
    assert!(n_ok > 100, "only {n_ok} valid responses");
}
