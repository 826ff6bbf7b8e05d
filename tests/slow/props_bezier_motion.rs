//! Invariants of spec `bezier_motion.md` as property tests on random drives and moves: the
//! law's boundary conditions pinned to round-off, residual energy ≥ 0 and finite in every damping
//! regime (ξ across 1 included), and the optimum's residual energy never above the reference
//! law's. Case counts honour PROPTEST_CASES.

use mechcalc::calc::bezier_motion::{BezierMotionRequest, run};
use mechcalc::numerics::Budget;
use proptest::prelude::*;
use serde_json::{Value, json};

use crate::support::proptest_cfg::cases;

/// A random drive with damping ratio near `xi` (c from ξ·2√(k J_load)) and a random move.
fn request(
    (j_load, k, xi, z): (f64, f64, f64, f64),
    (phi_rev, t_s, m, p): (f64, f64, u32, u32),
    mode: &str,
) -> Value {
    let c = xi * 2.0 * (k * j_load).sqrt();
    json!({
        "mode": mode,
        "system": {"inertias_kgm2": [0.005, 0.005, j_load], "k_Nm_per_rad": k,
                   "c_Nms_per_rad": c, "z": z},
        "motion": {"Phi_rev": phi_rev, "T_s": t_s, "m": m, "p": p}
    })
}

fn answer(v: &Value) -> Option<Value> {
    let req: BezierMotionRequest = serde_json::from_value(v.clone()).expect("request decodes");
    // A typed refusal (e.g. a rate the closed form cannot hold) is an allowed answer.
    run(req, &Budget::unlimited())
        .ok()
        .map(|r| serde_json::to_value(r).expect("serialisable"))
}

fn drive() -> impl Strategy<Value = (f64, f64, f64, f64)> {
    (0.1f64..10.0, 1e2f64..1e5, 0.0f64..2.0, 0.02f64..1.0)
}

fn motion() -> impl Strategy<Value = (f64, f64, u32, u32)> {
    (0.1f64..50.0, 0.1f64..3.0, 1u32..4, 3u32..7)
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

proptest! {
    #![proptest_config(cases(48))]

    /// The control polygon starts with m + 1 zeros and ends with m + 1 copies of Φ = 2π·Phi_rev
    /// (rest to rest), exactly up to round-off; E(T) ≥ 0 and finite.
    #[test]
    fn boundary_conditions_and_energy(d in drive(), mo in motion()) {
        let Some(a) = answer(&request(d, mo, "simulate")) else { return Ok(()); };
        let s: Vec<f64> = a["law"]["S_rad"].as_array().expect("S").iter().map(num).collect();
        let phi = std::f64::consts::TAU * mo.0;
        let m = mo.2 as usize;
        for (i, x) in s.iter().enumerate() {
            if i <= m {
                prop_assert!(x.abs() <= 1e-12 * phi, "S[{i}] = {x}");
            } else if i >= s.len() - 1 - m {
                prop_assert!((x - phi).abs() <= 1e-12 * phi, "S[{i}] = {x} vs Φ {phi}");
            }
        }
        let e = num(&a["residual"]["E_T_J"]);
        prop_assert!(e.is_finite() && e >= 0.0, "E(T) = {e}");
    }

    /// The optimum's residual energy is at most the reference law's (the optimiser could return
    /// the reference itself), in every damping regime.
    #[test]
    fn optimum_never_worse_than_the_reference(d in drive(), mo in motion()) {
        let Some(a) = answer(&request(d, mo, "optimize")) else { return Ok(()); };
        let e_opt = num(&a["residual"]["E_T_J"]);
        let e_ref = num(&a["reference"]["residual"]["E_T_J"]);
        prop_assert!(e_opt.is_finite() && e_opt >= 0.0);
        prop_assert!(e_opt <= e_ref * (1.0 + 1e-9) + 1e-300, "optimum {e_opt} > reference {e_ref}");
    }
}
