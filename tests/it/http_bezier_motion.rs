//! `POST /v1/bezier-motion-law` over HTTP: the api/ examples are answered, optional outputs only
//! when asked, and bad requests get problem+json with a JSON pointer per offending field (400
//! malformed, 415 content type, 422 out of range, shape rules, wrong types, and the typed
//! `too-large` refusals RHO_TOO_LARGE / HISTORY_TOO_LARGE); ξ ≥ 1 omits the oscillation-only
//! outputs (never `null`) and warns.

use serde_json::{Value, json};

use crate::common::{self, post_json};

const PATH: &str = "/v1/bezier-motion-law";

fn example(name: &str) -> Value {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("api/bezier_motion/{name}.json"));
    serde_json::from_str(&std::fs::read_to_string(p).expect("example")).expect("json")
}

#[tokio::test]
async fn the_spec_case_is_answered_with_zero_residual() {
    let r = post_json(PATH, &example("optimize_paper")).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    // Spec §8: the optimal interior ordinates and a residual at the numerical floor.
    for (got, want) in b["law"]["gamma_rad"]
        .as_array()
        .expect("gamma")
        .iter()
        .zip([31.61598184, 126.51464532, 125.05308850])
    {
        assert!(
            (got.as_f64().expect("n") - want).abs() < 1e-7,
            "{got} vs {want}"
        );
    }
    assert_eq!(b["residual"]["at_numerical_floor"], true);
    assert_eq!(b["report"]["stop_reason"], "completed");
}

#[tokio::test]
async fn optional_outputs_only_when_asked() {
    let mut v = example("simulate_reference");
    v.as_object_mut().expect("object").remove("outputs");
    let r = post_json(PATH, &v).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    for key in ["time_history", "sensitivity"] {
        assert!(
            b.get(key).is_none(),
            "{key} present without being asked for"
        );
    }
    // Kinematic peaks are cheap and on by default (spec §2: `outputs.kinematic_peaks` true).
    assert!(b["kinematics"].is_object());
}

#[tokio::test]
async fn out_of_range_fields_are_named_by_pointer() {
    let mut v = example("optimize_paper");
    v["system"]["k_Nm_per_rad"] = json!(-1.0);
    v["motion"]["T_s"] = json!(0.0);
    v["motion"]["m"] = json!(9);
    let r = post_json(PATH, &v).await;
    r.problem(422);
    let ptrs = r.pointers();
    for q in ["/system/k_Nm_per_rad", "/motion/T_s", "/motion/m"] {
        assert!(ptrs.iter().any(|x| x == q), "{q} missing in {ptrs:?}");
    }
}

#[tokio::test]
async fn malformed_json_and_wrong_content_type() {
    let r = common::send(
        "POST",
        PATH,
        Some("application/json"),
        b"{\"mode\":".to_vec(),
    )
    .await;
    assert_eq!(r.status, 400, "{}", String::from_utf8_lossy(&r.bytes));
    let body = serde_json::to_vec(&example("optimize_paper")).expect("json");
    let r = common::send("POST", PATH, Some("text/plain"), body).await;
    assert_eq!(r.status, 415, "{}", String::from_utf8_lossy(&r.bytes));
}

// ---------------------------------------------------------------------------------------------
// Every kind of bad request: a problem+json 422 naming each offending field (spec §2).

fn paper() -> Value {
    json!({
        "mode": "simulate",
        "system": {"inertias_kgm2": [0.005, 0.005, 2.8], "k_Nm_per_rad": 8000.0, "c_Nms_per_rad": 35.0, "z": 0.05},
        "motion": {"Phi_rev": 20.0, "T_s": 1.0, "m": 2, "p": 3}
    })
}

fn with(pointer: &str, value: Value) -> Value {
    let mut b = paper();
    *b.pointer_mut(pointer)
        .unwrap_or_else(|| panic!("{pointer}")) = value;
    b
}

/// Posts `body`, asserts a 422 of `kind` naming every pointer in `pointers`, returns the problem.
async fn rejected(body: &Value, kind: &str, pointers: &[&str]) -> Value {
    let r = post_json(PATH, body).await;
    let p = r.problem(422);
    assert_eq!(p["type"], format!("/problems/{kind}"), "{p}");
    let got = r.pointers();
    for want in pointers {
        assert!(got.iter().any(|g| g == want), "{want} not in {got:?}: {p}");
    }
    p
}

#[tokio::test]
async fn simulates_the_paper_case_without_optional_extras() {
    let r = post_json(PATH, &paper()).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    let e = b["residual"]["E_T_J"].as_f64().expect("E");
    assert!((e / 5.0327322960901e-02 - 1.0).abs() < 1e-10);
    for key in [
        "optimizer",
        "reference",
        "time_history",
        "sensitivity",
        "robust",
    ] {
        assert!(
            b.get(key).is_none(),
            "{key} present in simulate without being asked"
        );
    }
}

#[tokio::test]
async fn each_out_of_range_field_is_422_with_its_pointer() {
    let cases: Vec<(&str, Value)> = vec![
        ("/system/k_Nm_per_rad", json!(0.0)),
        ("/system/k_Nm_per_rad", json!(-8000.0)),
        ("/system/c_Nms_per_rad", json!(-1.0)),
        ("/system/z", json!(0.0)),
        ("/system/z", json!(2000.0)),
        ("/motion/T_s", json!(0.0)),
        ("/motion/T_s", json!(2e4)),
        ("/motion/Phi_rev", json!(0.0)),
        ("/motion/m", json!(0)),
        ("/motion/m", json!(7)),
        ("/motion/p", json!(0)),
        ("/motion/p", json!(21)),
    ];
    for (pointer, value) in cases {
        rejected(&with(pointer, value), "invalid-input", &[pointer]).await;
    }
    let mut b = paper();
    b["system"]["inertias_kgm2"] = json!([0.005, -1.0]);
    rejected(&b, "invalid-input", &["/system/inertias_kgm2/1"]).await;
    b["system"]["inertias_kgm2"] = json!([0.0, 0.0]);
    rejected(&b, "invalid-input", &["/system/inertias_kgm2"]).await;
}

#[tokio::test]
async fn shape_rules_are_422_with_their_pointers() {
    // N = 2m + p − 1 > 30: Bernstein conditioning (spec §6).
    let mut b = paper();
    b["motion"]["m"] = json!(6);
    b["motion"]["p"] = json!(20);
    let p = rejected(&b, "invalid-input", &["/motion/p"]).await;
    assert!(p.to_string().contains("N = 2m + p − 1"), "{p}");
    // The largest admissible degree, N = 30, is answered.
    b["motion"]["p"] = json!(19);
    assert_eq!(post_json(PATH, &b).await.status, 200);
    // γ of the wrong length, and one beyond 1e3·|Phi|.
    let mut b = paper();
    b["motion"]["gamma_rad"] = json!([1.0, 2.0]);
    rejected(&b, "invalid-input", &["/motion/gamma_rad"]).await;
    b["motion"]["gamma_rad"] = json!([1.0, 2.0e6, 3.0]);
    rejected(&b, "invalid-input", &["/motion/gamma_rad/1"]).await;
    // Both or neither of the alternatives.
    let mut b = paper();
    b["system"]["J_eq_kgm2"] = json!(2.81);
    rejected(&b, "invalid-input", &["/system/J_eq_kgm2"]).await;
    let mut b = paper();
    b["motion"].as_object_mut().expect("obj").remove("Phi_rev");
    rejected(&b, "invalid-input", &["/motion/Phi_rad"]).await;
    // Every offending field at once.
    let mut b = paper();
    b["system"]["k_Nm_per_rad"] = json!(-1.0);
    b["motion"]["T_s"] = json!(0.0);
    b["outputs"] = json!({"sensitivity": {"stiffness_factors": [1.0, 0.0]}});
    rejected(
        &b,
        "invalid-input",
        &[
            "/system/k_Nm_per_rad",
            "/motion/T_s",
            "/outputs/sensitivity/stiffness_factors/1",
        ],
    )
    .await;
}

#[tokio::test]
async fn wrong_types_and_unknown_fields_are_422() {
    post_json(PATH, &with("/motion/m", json!(-2)))
        .await
        .problem(422);
    post_json(PATH, &with("/mode", json!("integrate")))
        .await
        .problem(422);
    let mut b = paper();
    b["motion"]["q"] = json!(1);
    post_json(PATH, &b).await.problem(422);
}

#[tokio::test]
async fn too_fast_poles_are_typed_422s() {
    // ξ = 5e5: the GL path would need rho_max = 1e6 > 2e5.
    let body = json!({
        "mode": "simulate",
        "system": {"J_eq_kgm2": 1.0, "k_Nm_per_rad": 1.0, "c_Nms_per_rad": 1e6, "z": 1.0},
        "motion": {"Phi_rad": 1.0, "T_s": 1.0}
    });
    let p = rejected(&body, "too-large", &["/system/c_Nms_per_rad"]).await;
    assert_eq!(p["code"], "RHO_TOO_LARGE");
    // A stiff joint: fine in closed form, but a history would need > 2e5 sub-steps.
    let mut body = json!({
        "mode": "simulate",
        "system": {"J_eq_kgm2": 1.0, "k_Nm_per_rad": 1e13, "c_Nms_per_rad": 0.0, "z": 1.0},
        "motion": {"Phi_rad": 1.0, "T_s": 1.0}
    });
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    body["outputs"] = json!({"time_history": {"n_samples": 100}});
    let p = rejected(&body, "too-large", &["/outputs/time_history/n_samples"]).await;
    assert_eq!(p["code"], "HISTORY_TOO_LARGE");
}

#[tokio::test]
async fn non_oscillating_joint_omits_amplitudes_and_warns() {
    let body = json!({
        "mode": "optimize",
        "system": {"J_eq_kgm2": 1.0, "k_Nm_per_rad": 900.0, "c_Nms_per_rad": 90.0, "z": 1.0},
        "motion": {"Phi_rad": 1.0, "T_s": 0.3}
    });
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    assert!(
        crate::support::finite::all_numbers_finite(&b),
        "omitted, never null: {b}"
    );
    for (block, key) in [
        ("residual", "Q"),
        ("residual", "residual_amplitude_rad"),
        ("residual", "residual_accel_envelope_rad_s2"),
        ("system", "omega_d_rad_s"),
        ("system", "eta"),
    ] {
        assert!(
            b[block].get(key).is_none(),
            "{block}.{key} present at ξ = 1.5"
        );
    }
    let codes = common::warning_codes(&b);
    assert!(codes.contains(&"NOT_OSCILLATORY"), "{codes:?}");
}

#[tokio::test]
async fn robust_setting_in_simulate_is_ignored_with_a_warning() {
    let mut b = paper();
    b["optimize"] = json!({"robust_stiffness_rel": 0.1});
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200);
    let w = &r.json()["warnings"][0];
    assert_eq!(w["code"], "ROBUST_IGNORED");
    assert_eq!(w["pointer"], "/optimize/robust_stiffness_rel");
    b["optimize"] = json!({"robust_stiffness_rel": 0.6});
    rejected(&b, "invalid-input", &["/optimize/robust_stiffness_rel"]).await;
}

/// Issue 31: the shaper comparison's own 422s (empty list, a repeated shaper, `ei_tolerance`
/// outside [0, 0.5], an unknown shaper name) name their pointers; the api example's answer
/// carries one row per requested shaper and the Bezier row.
#[tokio::test]
async fn shaper_comparison_rules_and_answer() {
    let base = example("shaper_comparison_paper");
    let r = post_json(PATH, &base).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    let rows = b["shaper_comparison"]["rows"].as_array().expect("rows");
    let names: Vec<&str> = rows.iter().filter_map(|r| r["shaper"].as_str()).collect();
    assert_eq!(names, ["none", "zv", "zvd", "ei"]);
    assert!(b["shaper_comparison"]["bezier"]["E_T_J"].is_number());

    let mut v = base.clone();
    v["outputs"]["shaper_comparison"]["shapers"] = json!([]);
    post_json(PATH, &v)
        .await
        .assert_422_at(&["/outputs/shaper_comparison/shapers"]);
    let mut v = base.clone();
    v["outputs"]["shaper_comparison"]["shapers"] = json!(["zv", "ei", "zv"]);
    post_json(PATH, &v)
        .await
        .assert_422_at(&["/outputs/shaper_comparison/shapers/2"]);
    for bad in [-0.01, 0.6] {
        let mut v = base.clone();
        v["outputs"]["shaper_comparison"]["ei_tolerance"] = json!(bad);
        post_json(PATH, &v)
            .await
            .assert_422_at(&["/outputs/shaper_comparison/ei_tolerance"]);
    }
    let mut v = base.clone();
    v["outputs"]["shaper_comparison"]["shapers"] = json!(["mzv"]);
    assert_eq!(post_json(PATH, &v).await.status, 422);
}

// ---------------------------------------------------------------------------------------------
// Issue 26: the rules between fields are listed and reachable; `null` means absent.

/// The codes the document lists under this operation's `x-cross-field-rules`.
fn documented_rule_codes() -> Vec<String> {
    let doc = serde_json::to_value(mechcalc::http::openapi()).expect("openapi");
    doc.pointer("/paths/~1v1~1bezier-motion-law/post/x-cross-field-rules")
        .and_then(Value::as_array)
        .expect("x-cross-field-rules")
        .iter()
        .map(|r| r["code"].as_str().expect("code").to_owned())
        .collect()
}

/// Each rule between fields the operation lists is reachable: a request that passes every
/// per-field rule and breaks that one rule gets a 422 with the rule's code at the rule's pointer
/// (and so are the two size refusals of the computation).
#[tokio::test]
async fn every_cross_field_rule_is_reachable() {
    type Edit = fn(&mut Value);
    let cases: [(&str, &str, Edit); 9] = [
        ("INERTIA_SUM_ZERO", "/system/inertias_kgm2", |b| {
            b["system"]["inertias_kgm2"] = json!([0.0, 0.0]);
        }),
        ("ZERO_RATIO", "/system/z", |b| b["system"]["z"] = json!(0.0)),
        ("ZERO_ROTATION", "/motion/Phi_rev", |b| {
            b["motion"]["Phi_rev"] = json!(0.0);
        }),
        ("DEGREE_TOO_HIGH", "/motion/p", |b| {
            b["motion"]["m"] = json!(6);
            b["motion"]["p"] = json!(20);
        }),
        ("GAMMA_LENGTH", "/motion/gamma_rad", |b| {
            b["motion"]["gamma_rad"] = json!([1.0, 2.0]);
        }),
        ("GAMMA_OUT_OF_SCALE", "/motion/gamma_rad/1", |b| {
            b["motion"]["gamma_rad"] = json!([1.0, 2.0e6, 3.0]);
        }),
        (
            "SHAPER_REPEATED",
            "/outputs/shaper_comparison/shapers/2",
            |b| {
                b["outputs"] = json!({"shaper_comparison": {"shapers": ["zv", "ei", "zv"]}});
            },
        ),
        ("RHO_TOO_LARGE", "/system/c_Nms_per_rad", |b| {
            b["system"] =
                json!({"J_eq_kgm2": 1.0, "k_Nm_per_rad": 1.0, "c_Nms_per_rad": 1e6, "z": 1.0});
        }),
        (
            "HISTORY_TOO_LARGE",
            "/outputs/time_history/n_samples",
            |b| {
                b["system"] =
                    json!({"J_eq_kgm2": 1.0, "k_Nm_per_rad": 1e13, "c_Nms_per_rad": 0.0, "z": 1.0});
                b["outputs"] = json!({"time_history": {"n_samples": 100}});
            },
        ),
    ];
    for (code, pointer, edit) in cases {
        let mut b = paper();
        edit(&mut b);
        let r = post_json(PATH, &b).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{p}");
        assert_eq!(r.pointers(), [pointer], "{code}: {p}");
    }
    // Every listed code is one of these, or a failure of the computation that only extreme
    // inputs reach (an L2 Hessian without a Cholesky factor, an overflow, the time budget, the
    // answer's size).
    let computed = [
        "OBJECTIVE_SINGULAR",
        "NON_FINITE_RESULT",
        "DEADLINE_EXCEEDED",
        "RESPONSE_TOO_LARGE",
    ];
    let mut want: Vec<String> = cases
        .iter()
        .map(|c| c.0)
        .chain(computed)
        .map(str::to_owned)
        .collect();
    want.sort();
    let mut got = documented_rule_codes();
    got.sort();
    assert_eq!(got, want);
}

/// `null` for an optional field is the same as leaving it out, at every depth: the api example
/// with every optional field it omits set to `null` gets the example's answer, and `null` for an
/// optional field it gives gets the answer of that field's default.
#[tokio::test]
async fn null_means_absent() {
    let answer = |r: &common::Reply| {
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
        let mut v = r.json();
        v["report"]
            .as_object_mut()
            .expect("report")
            .retain(|k, _| k != "elapsed_ms");
        v
    };
    let base = example("optimize_paper");
    let plain = answer(&post_json(PATH, &base).await);
    let mut b = base.clone();
    b["time_limit_ms"] = Value::Null;
    b["system"]["J_eq_kgm2"] = Value::Null;
    b["motion"]["Phi_rad"] = Value::Null;
    b["motion"]["gamma_rad"] = Value::Null;
    b["optimize"]["robust_stiffness_rel"] = Value::Null;
    b["outputs"]["shaper_comparison"] = Value::Null;
    assert_eq!(answer(&post_json(PATH, &b).await), plain);

    // Null for every defaulted member it gives = each member absent (the example's values are
    // the defaults, except the time history's counts, which default to 0).
    let mut nulls = base.clone();
    let mut gone = base.clone();
    for p in [
        "/mode",
        "/motion/m",
        "/motion/p",
        "/optimize/objective",
        "/outputs/kinematic_peaks",
        "/outputs/time_history/n_samples",
        "/outputs/time_history/t_after_s",
    ] {
        *nulls.pointer_mut(p).expect(p) = Value::Null;
        let (parent, key) = p.rsplit_once('/').expect("pointer");
        gone.pointer_mut(parent)
            .and_then(Value::as_object_mut)
            .expect(parent)
            .remove(key);
    }
    let absent = answer(&post_json(PATH, &gone).await);
    assert_eq!(answer(&post_json(PATH, &nulls).await), absent);
    assert_ne!(
        absent, plain,
        "the time history's counts changed the answer"
    );

    // The shaper comparison's members: null = absent = the defaults the example gives.
    let shaped = example("shaper_comparison_paper");
    let plain = answer(&post_json(PATH, &shaped).await);
    let mut nulls = shaped.clone();
    for k in ["baseline", "shapers", "ei_tolerance"] {
        nulls["outputs"]["shaper_comparison"][k] = Value::Null;
    }
    assert_eq!(answer(&post_json(PATH, &nulls).await), plain);
    let mut gone = shaped.clone();
    gone["outputs"]["shaper_comparison"] = json!({});
    assert_eq!(answer(&post_json(PATH, &gone).await), plain);

    // Top-level optional objects as null = absent.
    let mut top = base.clone();
    let mut gone = base;
    for k in ["optimize", "outputs"] {
        top[k] = Value::Null;
        gone.as_object_mut().expect("request").remove(k);
    }
    assert_eq!(
        answer(&post_json(PATH, &top).await),
        answer(&post_json(PATH, &gone).await)
    );

    // A required member stays required: null is a 422 naming it.
    let r = post_json(PATH, &with("/motion/T_s", Value::Null)).await;
    r.problem(422);
    assert!(
        String::from_utf8_lossy(&r.bytes).contains("T_s"),
        "{}",
        String::from_utf8_lossy(&r.bytes)
    );
}
