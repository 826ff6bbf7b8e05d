//! `POST /v1/irefc-stress` and `POST /v1/irefc-efficiency` over HTTP: answers come back, and every kind of
//! bad request gets the right problem+json answer (type, spec code, pointers). Mutated `api/irefc`
//! examples never give a 500.

use crate::common;

use std::path::Path;

use common::post_json;
use serde_json::{Value, json};

const STRESS: &str = "/v1/irefc-stress";
const EFFICIENCY: &str = "/v1/irefc-efficiency";

fn example(name: &str) -> Value {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("api/irefc/{name}.json"));
    serde_json::from_str(&std::fs::read_to_string(p).expect("example")).expect("json")
}

#[tokio::test]
async fn single_design_is_answered() {
    let r = post_json(STRESS, &example("stress_single")).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    assert_eq!(b["mode"], "single");
    assert_eq!(b["max"]["overall"], "cam");
    assert!(
        (b["max"]["cam"]["sigma_MPa"].as_f64().expect("n") - 2_951.872_751_472_897).abs() < 1e-6
    );
    assert_eq!(b["elements"].as_array().map(Vec::len), Some(14));
    assert!(
        b.get("curves").is_none() && b["geometry"].get("profiles").is_none(),
        "off by default"
    );
}

#[tokio::test]
async fn optional_outputs_only_when_asked() {
    let mut v = example("stress_single");
    v["include"] = json!({"elements": false, "curves": true, "profiles": true, "subsurface": true});
    v["curves_stride"] = json!(10);
    v["profile_points"] = json!(100);
    let r = post_json(STRESS, &v).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    assert!(b.get("elements").is_none());
    assert_eq!(b["curves"]["phi2_deg"].as_array().map(Vec::len), Some(19));
    assert_eq!(
        b["geometry"]["profiles"]["cam_mm"].as_array().map(Vec::len),
        Some(100)
    );
    assert!(b["max"]["cam"]["tau_max_MPa"].as_f64().is_some());
}

#[tokio::test]
async fn sweep_reports_records_best_and_worst() {
    let mut v = example("stress_sweep");
    v["sweep"]["chi"]["step"] = json!(0.06);
    let r = post_json(STRESS, &v).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    let recs = b["records"].as_array().expect("records");
    assert_eq!(recs.len(), 31 * 8);
    let invalid: Vec<&Value> = recs.iter().filter(|x| x["valid"] == false).collect();
    assert!(
        !invalid.is_empty(),
        "the undercut region is inside this sweep"
    );
    assert!(
        invalid
            .iter()
            .all(|x| x["reason"]["code"] == "UNDERCUT" && x.get("sigma_max_MPa").is_none())
    );
    let worst = b["worst"].as_u64().expect("worst") as usize;
    let best = b["best"].as_u64().expect("best") as usize;
    assert_eq!(recs[worst]["valid"], true);
    assert!(recs[worst]["sigma_max_MPa"].as_f64() > recs[best]["sigma_max_MPa"].as_f64());
    assert_eq!(b["meta"]["solver"]["stop_reason"], "completed");
}

#[tokio::test]
async fn efficiency_paper_example_is_answered() {
    let r = post_json(EFFICIENCY, &example("efficiency_paper")).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    assert!((b["totals"]["eta_product"].as_f64().expect("n") - 0.93224).abs() < 5e-6);
    assert_eq!(b["elements"].as_array().map(Vec::len), Some(14));
}

#[tokio::test]
async fn decode_errors_point_at_the_field() {
    let mut v = example("stress_single");
    v["Z2"] = json!(26.5);
    let r = post_json(STRESS, &v).await;
    r.assert_422_at(&["/Z2"]);

    let mut v = example("stress_single");
    v["include"]["plots"] = json!(true);
    let r = post_json(STRESS, &v).await;
    r.assert_422_at(&["/include/plots"]);

    let mut v = example("efficiency_paper");
    v["model"] = json!("exact");
    let r = post_json(EFFICIENCY, &v).await;
    r.assert_422_at(&["/model"]);
}

#[tokio::test]
async fn range_errors_list_every_field_with_code_bad_range() {
    let mut v = example("stress_single");
    v["chi"] = json!(1.0);
    v["Z2"] = json!(2);
    v["torque_Nm"] = json!(-1);
    v["wheel_material"]["nu"] = json!(0.5);
    let r = post_json(STRESS, &v).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    assert_eq!(p["code"], "BAD_RANGE");
    let ptrs = r.pointers();
    for q in ["/chi", "/Z2", "/torque_Nm", "/wheel_material/nu"] {
        assert!(ptrs.iter().any(|x| x == q), "{q} missing in {ptrs:?}");
    }
}

/// Scalar Z2 and χ are ignored in a sweep (a warning says so) but still held to their documented
/// ranges: a request the published schema rejects is not answered 200.
#[tokio::test]
async fn ignored_scalars_of_a_sweep_are_still_range_checked() {
    let mut v = example("stress_sweep");
    v["chi"] = json!(6.0);
    v["Z2"] = json!(2);
    let r = post_json(STRESS, &v).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "BAD_RANGE");
    let ptrs = r.pointers();
    for q in ["/chi", "/Z2"] {
        assert!(ptrs.iter().any(|x| x == q), "{q} missing in {ptrs:?}");
    }
    v["chi"] = json!(1.5);
    v["Z2"] = json!(30);
    let r = post_json(STRESS, &v).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert!(
        r.json()["warnings"]
            .as_array()
            .is_some_and(|w| w.iter().any(|x| x["code"] == "FIELD_IGNORED"))
    );
}

#[tokio::test]
async fn infeasible_designs_carry_the_spec_codes() {
    let mut v = example("stress_single");
    v["rb_mm"] = json!(3.4);
    let r = post_json(STRESS, &v).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/infeasible");
    assert_eq!(p["code"], "ELEMENT_OVERLAP");
    assert_eq!(r.pointers(), vec!["/rb_mm"]);
    assert!(
        p["detail"].as_str().is_some_and(|d| d.contains("3.375")),
        "limit in the message: {p}"
    );

    let mut v = example("stress_single");
    v["Z2"] = json!(40);
    v["chi"] = json!(1.25);
    let r = post_json(STRESS, &v).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "UNDERCUT");

    let mut v = example("efficiency_paper");
    v["Z2"] = json!(40);
    v["chi"] = json!(1.25);
    assert_eq!(
        post_json(EFFICIENCY, &v).await.problem(422)["code"],
        "UNDERCUT"
    );
}

#[tokio::test]
async fn oversized_work_is_too_large() {
    let mut v = example("stress_single");
    v["step_deg"] = json!(1e-5);
    let p = post_json(STRESS, &v).await.problem(422);
    assert_eq!(p["type"], "/problems/too-large");
    assert_eq!(p["code"], "GRID_TOO_FINE");

    let mut v = example("stress_sweep");
    v["sweep"]["chi"]["step"] = json!(1e-6);
    let p = post_json(STRESS, &v).await.problem(422);
    assert_eq!(p["type"], "/problems/too-large");
    assert_eq!(p["code"], "SWEEP_TOO_LARGE");
}

#[tokio::test]
async fn ambiguous_load_is_rejected() {
    let mut v = example("efficiency_paper");
    v["input_torque_Nm"] = json!(9.55);
    let r = post_json(EFFICIENCY, &v).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "AMBIGUOUS_LOAD");
    assert_eq!(r.pointers(), vec!["/input_torque_Nm"]);
}

/// Mutate the examples' numbers with degenerate values (seeded): a 200 with finite numbers or a 4xx
/// problem, never a 500.
#[tokio::test]
async fn mutated_examples_never_fail_with_500() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let draws: [f64; 13] = [
        -1.0,
        0.0,
        1.0,
        1.0 + 1e-12,
        2.0,
        3.0,
        1e-300,
        1e-9,
        1e6,
        1e300,
        -1e300,
        0.5,
        4.99,
    ];
    for i in 0..60 {
        let (name, path) = match i % 3 {
            0 => ("stress_single", STRESS),
            1 => ("stress_sweep", STRESS),
            _ => ("efficiency_paper", EFFICIENCY),
        };
        let mut v = example(name);
        let keys: Vec<String> = v
            .as_object()
            .expect("object")
            .iter()
            .filter(|(_, x)| x.is_number())
            .map(|(k, _)| k.clone())
            .collect();
        for _ in 0..rng.random_range(1..=3) {
            let k = &keys[rng.random_range(0..keys.len())];
            let x = draws[rng.random_range(0..draws.len())];
            // Integral draws below 1e15 are exact as i64 (integer fields need integers to decode).
            v[k.as_str()] = if x.fract().abs() < f64::MIN_POSITIVE && x.abs() < 1e15 {
                json!(x as i64)
            } else {
                json!(x)
            };
        }
        if name == "stress_sweep" {
            v["step_deg"] = json!(5);
        }
        let r = post_json(path, &v).await;
        assert!(
            r.status.as_u16() == 200 || r.status.is_client_error(),
            "{name} {v}: {} {}",
            r.status,
            String::from_utf8_lossy(&r.bytes)
        );
    }
}

/// The codes the document lists under the operation's `x-cross-field-rules`.
async fn documented_cross_codes(path: &str) -> Vec<String> {
    let doc = common::get("/openapi.json").await.json();
    doc["paths"][path]["post"]["x-cross-field-rules"]
        .as_array()
        .expect("x-cross-field-rules listed")
        .iter()
        .map(|r| r["code"].as_str().expect("code").to_owned())
        .collect()
}

/// `example` with the members of `patch` set (a `null` member is removed).
fn patched(name: &str, patch: &Value) -> Value {
    let mut b = example(name);
    for (k, v) in patch.as_object().expect("object") {
        if v.is_null() {
            b.as_object_mut().map(|m| m.remove(k));
        } else {
            b[k] = v.clone();
        }
    }
    b
}

#[tokio::test]
#[expect(
    clippy::too_many_lines,
    reason = "one table: a request per rule of both routes"
)]
async fn every_rule_between_fields_is_listed_and_reachable() {
    let stress_codes = documented_cross_codes(STRESS).await;
    let eff_codes = documented_cross_codes(EFFICIENCY).await;
    let sweep =
        json!({"Z2": {"from": 10, "to": 12}, "chi": {"from": 1.25, "to": 1.3, "step": 0.01}});
    let cases = [
        // (path, code, pointer, example, patch)
        (
            STRESS,
            "BAD_RANGE",
            "/sweep",
            "stress_single",
            json!({"sweep": sweep}),
        ),
        (
            STRESS,
            "BAD_RANGE",
            "/shard",
            "stress_single",
            json!({"shard": {"index": 0, "count": 2}}),
        ),
        (
            STRESS,
            "SHARD_INDEX_BELOW_COUNT",
            "/shard/index",
            "stress_sweep",
            json!({"shard": {"index": 2, "count": 2}}),
        ),
        (
            STRESS,
            "MISSING_FIELD",
            "/Z2",
            "stress_single",
            json!({"Z2": null}),
        ),
        (
            STRESS,
            "MISSING_FIELD",
            "/rb_mm",
            "stress_sweep",
            json!({"rb_mm": null}),
        ),
        (
            STRESS,
            "BAD_RANGE",
            "/sweep/Z2/to",
            "stress_sweep",
            json!({"sweep": {"Z2": {"from": 12, "to": 10}, "chi": {"from": 1.25, "to": 1.3, "step": 0.01}}}),
        ),
        (
            STRESS,
            "BAD_RANGE",
            "/sweep/chi/to",
            "stress_sweep",
            json!({"sweep": {"Z2": {"from": 10, "to": 12}, "chi": {"from": 1.3, "to": 1.25, "step": 0.01}}}),
        ),
        (
            STRESS,
            "BAD_RANGE",
            "/lb_mm",
            "stress_single",
            json!({"lb_mm": 2000.001}),
        ),
        (
            STRESS,
            "GRID_TOO_FINE",
            "/step_deg",
            "stress_single",
            json!({"step_deg": 1e-5}),
        ),
        (
            STRESS,
            "SWEEP_TOO_LARGE",
            "/sweep",
            "stress_sweep",
            json!({"sweep": {"Z2": {"from": 10, "to": 40}, "chi": {"from": 1.25, "to": 1.67, "step": 1e-6}}}),
        ),
        (
            STRESS,
            "ELEMENT_OVERLAP",
            "/rb_mm",
            "stress_single",
            json!({"rb_mm": 3.4}),
        ),
        (
            STRESS,
            "UNDERCUT",
            "/rb_mm",
            "stress_single",
            json!({"Z2": 40, "chi": 1.25}),
        ),
        (
            EFFICIENCY,
            "AMBIGUOUS_LOAD",
            "/input_torque_Nm",
            "efficiency_paper",
            json!({"input_torque_Nm": 9.55}),
        ),
        (
            EFFICIENCY,
            "MISSING_FIELD",
            "/power_W",
            "efficiency_paper",
            json!({"power_W": null}),
        ),
        (
            EFFICIENCY,
            "BAD_RANGE",
            "/phase_deg",
            "efficiency_paper",
            json!({"phase_deg": 14.0}),
        ),
        (
            EFFICIENCY,
            "UNDERCUT",
            "/rb_mm",
            "efficiency_paper",
            json!({"Z2": 40, "chi": 1.25}),
        ),
        (
            EFFICIENCY,
            "ELEMENT_OVERLAP",
            "/rb_mm",
            "efficiency_paper",
            json!({"rb_mm": 3.4}),
        ),
    ];
    for (path, code, pointer, name, patch) in cases {
        let codes = if path == STRESS {
            &stress_codes
        } else {
            &eff_codes
        };
        assert!(
            codes.iter().any(|c| c == code),
            "{path}: {code} is not listed: {codes:?}"
        );
        let r = post_json(path, &patched(name, &patch)).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{path} {patch}: {p}");
        assert!(
            r.pointers().iter().any(|q| q == pointer),
            "{path} {code}: expected pointer {pointer}, got {p}"
        );
    }
    // Failures found while computing, listed too.
    for code in ["NON_FINITE", "DEADLINE", "RESPONSE_TOO_LARGE"] {
        assert!(
            stress_codes.iter().any(|c| c == code),
            "{code}: {stress_codes:?}"
        );
        assert!(eff_codes.iter().any(|c| c == code), "{code}: {eff_codes:?}");
    }
}

/// An answer without its timing fields (`compute_ms`, the report's `elapsed_ms`).
fn untimed(mut v: Value) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                m.retain(|k, _| k != "compute_ms" && k != "elapsed_ms");
                m.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

#[tokio::test]
async fn null_optional_fields_answer_as_absent() {
    let with_nulls = |name: &str, top: &[&str], nested: &[(&str, &str)]| {
        let mut b = example(name);
        for k in top {
            b[*k] = Value::Null;
        }
        for (o, k) in nested {
            b[*o][*k] = Value::Null;
        }
        b
    };
    let cases = [
        (
            STRESS,
            "stress_single",
            with_nulls(
                "stress_single",
                &[
                    "curves_stride",
                    "profile_points",
                    "sweep",
                    "shard",
                    "time_limit_ms",
                ],
                &[("include", "profiles"), ("include", "subsurface")],
            ),
        ),
        (
            STRESS,
            "stress_sweep",
            with_nulls(
                "stress_sweep",
                &[
                    "Z2",
                    "chi",
                    "output_link",
                    "lb_mm",
                    "wheel_material",
                    "roller_material",
                    "load_sharing",
                    "include",
                    "curves_stride",
                    "profile_points",
                    "shard",
                    "time_limit_ms",
                ],
                &[("sweep", "rb_mm"), ("sweep", "r2_mm")],
            ),
        ),
        (
            EFFICIENCY,
            "efficiency_paper",
            with_nulls(
                "efficiency_paper",
                &["input_torque_Nm", "time_limit_ms"],
                &[],
            ),
        ),
    ];
    for (path, name, nulls) in cases {
        let a = post_json(path, &example(name)).await;
        assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
        let b = post_json(path, &nulls).await;
        assert_eq!(
            b.status,
            200,
            "{name}: {}",
            String::from_utf8_lossy(&b.bytes)
        );
        assert_eq!(untimed(a.json()), untimed(b.json()), "{name}");
    }
}
