//! Invariants of spec 6.3 as property tests: mirror symmetry, stiffness and length scaling,
//! translation of the guides, det J > 0 at stable solutions, the exact Jacobian against finite
//! differences, and thread-count independence of the sweep. `PROPTEST_CASES` raises the case count.

// Test arithmetic stays in textbook form.
#![allow(clippy::suboptimal_flops)]

use mechcalc::calc::continuum_workspace::model::{Model, Params};
use mechcalc::calc::continuum_workspace::newton::{self, NewtonOptions};
use mechcalc::calc::continuum_workspace::presets::Preset;
use mechcalc::calc::continuum_workspace::sweep::{self, Limits, StabilityCheck, SweepSettings};
use mechcalc::calc::continuum_workspace::{compute, fk, run};
use mechcalc::numerics::Budget;
use proptest::prelude::*;
use serde_json::{Value, json};

/// Design 1 of spec 6.2 as an explicit request, transformed: mirror x -> -x, scale lengths by
/// `s`, modulus by `c`, translate the guide origins by `t`.
fn design1(mirror: bool, s: f64, c: f64, t: [f64; 2]) -> Value {
    let m = if mirror { -1.0 } else { 1.0 };
    let a = 0.045 * s;
    let clamp = |deg: f64| if mirror { 180.0 - deg } else { deg };
    let rod = |act: usize, ox: f64, cl: f64, ax: f64| {
        json!({"actuator": act, "offset_m": [m * ox, 0.0], "clamp_angle_deg": clamp(cl), "length_m": 0.5 * s,
               "diameter_m": 0.004 * s, "youngs_modulus_pa": 2.1e11 * c, "attach_m": [m * ax, 0.0]})
    };
    let guide = |lo: f64, hi: f64| json!({"origin_m": t, "direction": [m, 0.0], "stroke_m": [lo * s, hi * s]});
    json!({"actuators": [guide(-0.7, 0.2), guide(-0.1775, 0.7225)],
           "rods": [rod(0, -a / 2.0, -60.0, -a / 2.0), rod(0, a / 2.0, -60.0, a / 2.0), rod(1, 0.0, -120.0, a / 2.0)],
           "home_inputs_m": [-0.25 * s, 0.2725 * s]})
}

fn fk_call(design: Value, inputs: [f64; 2], force: [f64; 2], moment: f64) -> Option<Value> {
    let req = json!({"mode": "fk", "design": design, "inputs_m": inputs,
                     "load": {"force_n": force, "moment_nm": moment}, "outputs": {"stability": false}});
    let resp = run(serde_json::from_value(req).ok()?, &Budget::unlimited()).ok()?;
    let v = serde_json::to_value(resp).ok()?;
    (v["status"] == "ok").then_some(v)
}

fn num(v: &Value, ptr: &str) -> f64 {
    v.pointer(ptr).and_then(Value::as_f64).unwrap_or(f64::NAN)
}

fn pose(v: &Value) -> (f64, f64, f64) {
    (
        num(v, "/platform/position_m/0"),
        num(v, "/platform/position_m/1"),
        num(v, "/platform/parasitic_angle_deg"),
    )
}

fn inputs() -> impl Strategy<Value = [f64; 2]> {
    (-0.35..-0.12f64, 0.17..0.37f64).prop_map(|(a, b)| [a, b])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Spec 6.3 mirror: x -> -x (origins, directions, offsets, attachments mirrored, clamp
    /// angles pi - theta_c, F_x -> -F_x, M -> -M) gives p_x -> -p_x, theta -> -theta (ref 5e-15).
    #[test]
    fn mirror_symmetry(l in inputs(), fx in -20.0..20.0f64, fy in -40.0..10.0f64, mo in -0.5..0.5f64) {
        let a = fk_call(design1(false, 1.0, 1.0, [0.0, 0.0]), l, [fx, fy], mo);
        let b = fk_call(design1(true, 1.0, 1.0, [0.0, 0.0]), l, [-fx, fy], -mo);
        prop_assume!(a.is_some() && b.is_some());
        let (pa, pb) = (pose(&a.unwrap_or_default()), pose(&b.unwrap_or_default()));
        prop_assert!((pa.0 + pb.0).abs() < 1e-10, "px {} vs {}", pa.0, pb.0);
        prop_assert!((pa.1 - pb.1).abs() < 1e-10, "py {} vs {}", pa.1, pb.1);
        prop_assert!((pa.2 + pb.2).abs() < 1e-8, "theta {} vs {}", pa.2, pb.2);
    }

    /// Spec 6.3: E -> cE and loads -> cF keep the pose and scale the forces by c; all lengths and
    /// d -> s x with loads x s^2 scale the pose by s.
    #[test]
    fn stiffness_and_length_scaling(l in inputs(), fy in -40.0..0.0f64, c in 0.2..5.0f64, s in 0.1..10.0f64) {
        let base = fk_call(design1(false, 1.0, 1.0, [0.0, 0.0]), l, [0.0, fy], 0.0);
        let stiff = fk_call(design1(false, 1.0, c, [0.0, 0.0]), l, [0.0, c * fy], 0.0);
        let big = fk_call(design1(false, s, 1.0, [0.0, 0.0]), [l[0] * s, l[1] * s], [0.0, fy * s * s], 0.0);
        prop_assume!(base.is_some() && stiff.is_some() && big.is_some());
        let (base, stiff, big) = (base.unwrap_or_default(), stiff.unwrap_or_default(), big.unwrap_or_default());
        let (p0, p1, p2) = (pose(&base), pose(&stiff), pose(&big));
        prop_assert!((p0.0 - p1.0).abs() < 1e-10 && (p0.1 - p1.1).abs() < 1e-10 && (p0.2 - p1.2).abs() < 1e-8);
        prop_assert!((p0.0 * s - p2.0).abs() < 1e-10 * s && (p0.1 * s - p2.1).abs() < 1e-10 * s);
        prop_assert!((p0.2 - p2.2).abs() < 1e-8);
        for i in 0..3 {
            for k in 0..2 {
                let f0 = num(&base, &format!("/rods/{i}/tip_force_n/{k}"));
                let f1 = num(&stiff, &format!("/rods/{i}/tip_force_n/{k}"));
                prop_assert!((f0 * c - f1).abs() < 1e-7 * c.max(1.0) * (1.0 + f0.abs()), "force {f0} x {c} vs {f1}");
            }
        }
    }

    /// Spec 6.3: translating both guide origins translates p_P; theta is unchanged.
    #[test]
    fn translation_of_the_guides(l in inputs(), tx in -1.0..1.0f64, ty in -1.0..1.0f64) {
        let a = fk_call(design1(false, 1.0, 1.0, [0.0, 0.0]), l, [0.0, -30.0], 0.0);
        let b = fk_call(design1(false, 1.0, 1.0, [tx, ty]), l, [0.0, -30.0], 0.0);
        prop_assume!(a.is_some() && b.is_some());
        let (pa, pb) = (pose(&a.unwrap_or_default()), pose(&b.unwrap_or_default()));
        prop_assert!((pa.0 + tx - pb.0).abs() < 1e-10 && (pa.1 + ty - pb.1).abs() < 1e-10);
        prop_assert!((pa.2 - pb.2).abs() < 1e-8);
    }

    /// Spec 6.3 / 4.5: stable solutions have det J > 0.
    #[test]
    fn stable_solutions_have_positive_det(l in inputs(), fy in -50.0..0.0f64) {
        let req = json!({"mode": "fk", "design": {"preset": "keops_d1"}, "inputs_m": l,
                         "load": {"force_n": [0.0, fy]}, "outputs": {"stability": true, "stability_segments": 20}});
        let resp = run(serde_json::from_value(req).map_err(|e| TestCaseError::fail(e.to_string()))?, &Budget::unlimited())
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let v = serde_json::to_value(resp).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assume!(v["status"] == "ok");
        if v["stability"]["stable"] == true {
            prop_assert_eq!(v["stability"]["det_sign"].as_i64(), Some(1));
        }
    }

    /// The exact Jacobian of spec 4.2 (sensitivities integrated with the same RK4 stages)
    /// against central finite differences of the residual, Kirchhoff and extensible rods.
    #[test]
    fn jacobian_matches_finite_differences(
        q in proptest::collection::vec(-2.0..2.0f64, 9),
        th in -0.5..0.5f64,
        extensible in any::<bool>(),
    ) {
        let model = Model::new(Preset::KeopsD1.design(), 32, extensible);
        let p = Params { lambda: vec![-0.2, 0.25], force: [3.0, -20.0], moment: 0.3 };
        let mut v = q.clone();
        v.extend([0.05, -0.9, th]);
        let steps = vec![32; 3];
        let e = model.evaluate(&v, &p, &steps, true);
        let n = v.len();
        let h = 1e-6;
        for c in 0..n {
            let (mut vp, mut vm) = (v.clone(), v.clone());
            vp[c] += h;
            vm[c] -= h;
            let gp = model.evaluate(&vp, &p, &steps, false).g;
            let gm = model.evaluate(&vm, &p, &steps, false).g;
            for r in 0..n {
                let fd = (gp[r] - gm[r]) / (2.0 * h);
                let an = e.jac[r * n + c];
                prop_assert!((fd - an).abs() <= 1e-6 * (1.0 + an.abs()), "J[{r}][{c}]: analytic {an} vs FD {fd}");
            }
        }
    }
}

/// The wave gives bit-identical results for 1 and 2 threads (level-synchronous FIFO, spec 4.7).
#[test]
fn sweep_is_independent_of_thread_count() {
    let model = Model::new(Preset::KeopsD1.design(), 32, false);
    let base = Params {
        lambda: vec![-0.25, 0.2725],
        force: [0.0, -20.0],
        moment: 0.0,
    };
    let run_with = |threads: usize| {
        let s = SweepSettings {
            stability: StabilityCheck::DetSign,
            limits: Limits {
                min_gap: Some(0.05),
                sigma_allow: None,
                rod_crossing: false,
            },
            threads,
            ..SweepSettings::with_defaults([13, 13], [[-0.7, 0.2], [-0.1775, 0.7225]])
        };
        let home = compute::resolve_home(&model).expect("design 1 has a home");
        let seed_l = sweep::lambda_at(&s, 6, 6);
        let target = Params {
            lambda: seed_l.to_vec(),
            ..base.clone()
        };
        let opts = NewtonOptions::new(1e-10, 50);
        let mut counter = mechcalc::calc::continuum_workspace::newton::Counter::default();
        let sol = fk::from_home(
            &model,
            &home,
            &target,
            30,
            newton::Stepping::Adaptive,
            opts,
            &Budget::unlimited(),
            &mut counter,
        )
        .expect("seed");
        let seed = sweep::accept(&model, &s, &seed_l, &sol.solution, None).expect("seed accepted");
        sweep::wave(&model, &base, &s, (6, 6), seed, opts, &Budget::unlimited())
    };
    let (a, b) = (run_with(1), run_with(2));
    assert_eq!(a.status, b.status);
    assert!(
        a.status
            .iter()
            .filter(|s| **s == sweep::NodeStatus::Ok)
            .count()
            > 60
    );
    for (x, y) in a.nodes.iter().zip(&b.nodes) {
        match (x, y) {
            (Some(x), Some(y)) => assert!(
                x.v.iter()
                    .zip(&y.v)
                    .all(|(p, q)| p.to_bits() == q.to_bits())
            ),
            (None, None) => {}
            _ => panic!("node accepted by one run only"),
        }
    }
}

/// Issue 17 (adaptive continuation): over seeded random targets and loads in design 1's stable
/// workspace, the adaptive path from home (the default) lands on the same equilibrium as the
/// spec's fixed-step path: the platform point P and every rod tip B_i agree to 1e-9 L_ref (the
/// issue's criterion, on positions). The platform angle and the scaled unknowns (rod forces,
/// base moments) are compared at what the two end solves can honestly share: both stop at
/// `||g||_inf < tol` on the same discrete map, so they differ by at most about
/// `||J^-1|| ||g_a - g_f|| <= cond(J) 2 sqrt(n) tol` (||J||_2 >= 1: the closure rows hold -I2 in
/// the position columns). Measured over 300 targets (benches/RESULTS.md): P 9.5e-12 m apart,
/// L_ref |dtheta| 9.7e-11 m, unknowns 5.8e-10; with a tighter chord tolerance one target's angle
/// differed by L_ref |dtheta| = 6.0e-10 m, so the angle is not held to 1e-9 L_ref.
/// Targets whose fixed-path solution is not stable (margin of spec 4.5) are outside the claim.
/// CI runs 32 cases; `PROPTEST_CASES=300` runs the few hundred.
mod adaptive_continuation {
    use mechcalc::calc::continuum_workspace::model::{Model, Params};
    use mechcalc::calc::continuum_workspace::newton::{Counter, NewtonOptions, Stepping};
    use mechcalc::calc::continuum_workspace::presets::Preset;
    use mechcalc::calc::continuum_workspace::{compute, fk};
    use mechcalc::numerics::Budget;
    use proptest::prelude::*;
    use std::sync::OnceLock;

    fn model() -> &'static Model {
        static M: OnceLock<Model> = OnceLock::new();
        M.get_or_init(|| Model::new(Preset::KeopsD1.design(), 32, false))
    }

    proptest! {
        #![proptest_config(crate::support::proptest_cfg::cases(32))]

        #[test]
        fn adaptive_path_reaches_the_fixed_paths_solution(
            l0 in -0.35..-0.12f64,
            l1 in 0.17..0.37f64,
            fx in -20.0..20.0f64,
            fy in -20.0..20.0f64,
        ) {
            let m = model();
            let home = compute::resolve_home(m).expect("design 1 has a home");
            let p = Params { lambda: vec![l0, l1], force: [fx, fy], moment: 0.0 };
            let k = fk::continuation_steps(m, &home.lambda, &p.lambda);
            let tol = 1e-10;
            let opts = NewtonOptions::new(tol, 50);
            let run = |s: Stepping| {
                fk::from_home(m, &home, &p, k, s, opts, &Budget::unlimited(), &mut Counter::default())
            };
            let Ok(fixed) = run(Stepping::Fixed) else {
                return Ok(());
            };
            let stable = fk::margin_of(m, &fixed.solution, 20).is_some_and(|g| g > fk::STABLE_MARGIN);
            prop_assume!(stable);
            let adaptive = run(Stepping::Adaptive);
            prop_assert!(adaptive.is_ok(), "adaptive path failed at {:?}: {:?}", p, adaptive.err());
            let adaptive = adaptive.expect("checked");
            let (a, f) = (&adaptive.solution.v, &fixed.solution.v);
            prop_assert!(adaptive.solution.eval.norm_inf() < tol);
            let dp = {
                let (pa, pf) = (m.position(a), m.position(f));
                (pa[0] - pf[0]).hypot(pa[1] - pf[1])
            };
            let dtip = adaptive.solution.eval.tips.iter().zip(&fixed.solution.eval.tips)
                .fold(0.0f64, |x, (u, w)| x.max((u[0] - w[0]).hypot(u[1] - w[1])));
            let limit = 1e-9 * m.l_ref;
            prop_assert!(dp <= limit && dtip <= limit,
                "branch differs at {:?}: P {:.2e} m, tips {:.2e} m (limit {:.1e} m); steps {} vs {}",
                p, dp, dtip, limit, adaptive.steps, fixed.steps);
            let dv = a.iter().zip(f).fold(0.0f64, |x, (u, w)| x.max((u - w).abs()));
            let cond = fk::condition(m, &fixed.solution);
            let shared = cond * 2.0 * (a.len() as f64).sqrt() * tol;
            let dt = (m.angle(a) - m.angle(f)).abs();
            prop_assert!(dv <= shared && dt <= shared,
                "unknowns differ by {:.2e}, angle by {:.2e} rad > cond(J) 2 sqrt(n) tol = {:.2e} at {:?}",
                dv, dt, shared, p);
        }
    }
}
