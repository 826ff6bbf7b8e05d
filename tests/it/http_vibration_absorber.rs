//! `POST /v1/vibration-absorber` over HTTP: the spec example comes back, optional outputs are
//! omitted unless asked, and every kind of invalid request gets a 422 problem+json with a pointer
//! per offending field and the module's code.

use crate::common;

use common::post_json;
use serde_json::{Value, json};

const PATH: &str = "/v1/vibration-absorber";

fn base() -> Value {
    json!({"control": {"mode": "active", "tuning_hz": 26.26},
           "absorber": {"passive_tuning_hz": 4.14}})
}

fn patched(patch: &Value) -> Value {
    let mut b = base();
    for (k, v) in patch.as_object().expect("object") {
        match (b.get_mut(k), v) {
            (Some(Value::Object(dst)), Value::Object(src)) => {
                for (kk, vv) in src {
                    dst.insert(kk.clone(), vv.clone());
                }
            }
            _ => b[k] = v.clone(),
        }
    }
    b
}

#[tokio::test]
async fn defaults_answer_with_modes_and_gains_only() {
    let r = post_json(PATH, &json!({})).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    assert_eq!(b["beam"]["beta_l"].as_array().map(Vec::len), Some(3));
    // Default tuning: the model's own f₂ (mode index), so K_p follows f₂ = 26.1805 Hz.
    let kp = b["gains"]["kp_v_m"].as_f64().expect("kp");
    assert!((kp - 602.0).abs() < 5.0, "kp {kp}");
    for k in [
        "natural_frequencies",
        "closed_loop",
        "ava_step",
        "ava_frequency_response",
        "frequency_response",
        "time_response",
    ] {
        assert!(b.get(k).is_none(), "{k} must be omitted unless asked");
    }
    assert_eq!(b["report"]["stop_reason"], "completed");
}

#[tokio::test]
async fn passive_configuration_has_no_gains_and_no_coil_outputs() {
    let body = json!({"control": {"mode": "passive"},
                      "outputs": {"time_response": {"t_end_s": 1.0, "dt_s": 0.001}}});
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200);
    let b = r.json();
    assert!(b.get("gains").is_none());
    let t = &b["time_response"];
    assert!(t.get("stroke_max_m").is_some());
    assert!(
        t.get("force_max_n").is_none()
            && t.get("current_max_a").is_none()
            && t.get("voltage_max_v").is_none()
    );
}

/// One 422 per case, with the offending pointer (and code when the module names one).
#[tokio::test]
async fn invalid_requests_point_at_the_field() {
    let cases: [(&str, Option<&str>, Value); 20] = [
        ("/beam/length_m", None, json!({"beam": {"length_m": 0.0}})),
        (
            "/beam/youngs_modulus_pa",
            None,
            json!({"beam": {"youngs_modulus_pa": -1.0}}),
        ),
        (
            "/beam/density_kg_m3",
            None,
            json!({"beam": {"density_kg_m3": 0.0}}),
        ),
        ("/beam/n_modes", None, json!({"beam": {"n_modes": 51}})),
        ("/beam/n_modes", None, json!({"beam": {"n_modes": 0}})),
        (
            "/beam/modal_damping_ratio",
            None,
            json!({"beam": {"modal_damping_ratio": 1.0}}),
        ),
        (
            "/beam/section",
            None,
            json!({"beam": {"section": {"width_m": 0.05, "thickness_m": 0.005}, "area_m2": 1e-4}}),
        ),
        (
            "/absorber/mass_kg",
            None,
            json!({"absorber": {"mass_kg": 0.0}}),
        ),
        (
            "/absorber/position_m",
            Some("POSITION_OUT_OF_BEAM"),
            json!({"absorber": {"position_m": 1.5}}),
        ),
        (
            "/absorber/position_m",
            None,
            json!({"absorber": {"position_m": 0.0}}),
        ),
        (
            "/excitation/position_m",
            Some("POSITION_OUT_OF_BEAM"),
            json!({"excitation": {"position_m": 2.0}}),
        ),
        (
            "/actuator/resistance_ohm",
            None,
            json!({"actuator": {"resistance_ohm": 0.0}}),
        ),
        (
            "/actuator/inductance_h",
            None,
            json!({"actuator": {"inductance_h": 0.0}}),
        ),
        (
            "/actuator/force_constant_n_a",
            Some("ZERO_FORCE_CONSTANT"),
            json!({"actuator": {"force_constant_n_a": 0.0}}),
        ),
        (
            "/control/tuning_mode",
            Some("MODE_OUT_OF_RANGE"),
            json!({"control": {"mode": "active", "tuning_mode": 4}}),
        ),
        (
            "/excitation/resonance_of_mode",
            Some("MODE_OUT_OF_RANGE"),
            json!({"excitation": {"resonance_of_mode": 9}}),
        ),
        (
            "/outputs/time_response/dt_s",
            Some("TOO_MANY_SAMPLES"),
            json!({"outputs": {"time_response": {"t_end_s": 100.0, "dt_s": 1e-5}}}),
        ),
        (
            "/outputs/time_response/t_end_s",
            None,
            json!({"outputs": {"time_response": {"t_end_s": 0.0, "dt_s": 1e-3}}}),
        ),
        (
            "/outputs/frequency_response/f_max_hz",
            None,
            json!({"outputs": {"frequency_response": {"f_min_hz": 10.0, "f_max_hz": 5.0, "n_points": 10}}}),
        ),
        (
            "/outputs/frequency_response/points_m/1",
            Some("POSITION_OUT_OF_BEAM"),
            json!({"outputs": {"frequency_response": {"f_min_hz": 1.0, "f_max_hz": 5.0, "n_points": 10, "points_m": [0.5, 1.2]}}}),
        ),
    ];
    for (pointer, code, patch) in cases {
        let body =
            if patch.get("control").is_some() && patch["control"].get("tuning_mode").is_some() {
                json!({"control": patch["control"]})
            } else {
                patched(&patch)
            };
        let r = post_json(PATH, &body).await;
        assert_eq!(
            r.status,
            422,
            "{pointer}: {}",
            String::from_utf8_lossy(&r.bytes)
        );
        assert!(
            r.pointers().contains(&pointer.to_owned()),
            "{pointer}: got {:?}",
            r.pointers()
        );
        if let Some(code) = code {
            assert_eq!(r.json()["code"], code, "{pointer}");
        }
    }
}

#[tokio::test]
async fn every_offending_field_is_listed_at_once() {
    let body =
        json!({"beam": {"length_m": -1.0, "density_kg_m3": 0.0}, "absorber": {"mass_kg": -2.0}});
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 422);
    let p = r.pointers();
    for want in ["/beam/length_m", "/beam/density_kg_m3", "/absorber/mass_kg"] {
        assert!(p.contains(&want.to_owned()), "{want} missing from {p:?}");
    }
}

#[tokio::test]
async fn unknown_members_and_bad_enums_are_rejected_with_their_path() {
    for (body, pointer) in [
        (json!({"beam": {"lenght_m": 1.0}}), "/beam"),
        (json!({"control": {"mode": "semi_active"}}), "/control/mode"),
        (json!({"excitation": {"type": "chirp"}}), "/excitation/type"),
    ] {
        let r = post_json(PATH, &body).await;
        assert_eq!(r.status, 422, "{body}");
        assert!(
            r.pointers().iter().any(|p| p.starts_with(pointer)),
            "{body}: {:?}",
            r.pointers()
        );
    }
}

#[tokio::test]
async fn undamped_resonance_on_the_grid_is_null_with_a_warning() {
    // Bare undamped beam, a one-point grid exactly at the model's f₁.
    let f1 = post_json(PATH, &json!({"control": {"mode": "none"}}))
        .await
        .json()["beam"]["natural_frequencies_hz"][0]
        .as_f64()
        .expect("f1");
    let body = json!({"control": {"mode": "none"},
        "outputs": {"frequency_response": {"f_min_hz": f1, "f_max_hz": f1, "n_points": 1}}});
    let r = post_json(PATH, &body).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let b = r.json();
    assert!(b["frequency_response"]["points"][0]["magnitude_m_per_n"][0].is_null());
    assert!(
        b["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .any(|w| w["code"] == "UNDAMPED_RESONANCE")
    );
}

/// Several harmonics (spec §3.D.4): the list form answers with one frequency per component; it
/// excludes the single-harmonic members, needs `type = harmonic` and checks every component.
#[tokio::test]
async fn harmonics_list_is_validated_per_component() {
    let ok = json!({"excitation": {"harmonics": [
            {"amplitude_n": 1.0, "resonance_of_mode": 1},
            {"amplitude_n": 0.5, "frequency_hz": 10.0, "phase_rad": 0.3}]},
        "outputs": {"time_response": {"t_end_s": 0.5, "dt_s": 0.001}}});
    let r = post_json(PATH, &ok).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let t = &r.json()["time_response"];
    assert!(t.get("excitation_frequency_hz").is_none());
    let f = t["excitation_frequencies_hz"]
        .as_array()
        .expect("per component");
    assert_eq!(f.len(), 2);
    assert_eq!(f[1], 10.0);

    let one = json!([{"amplitude_n": 1.0, "frequency_hz": 5.0}]);
    let cases: [(&str, Option<&str>, Value); 9] = [
        (
            "/excitation/amplitude_n",
            Some("HARMONICS_CONFLICT"),
            json!({"amplitude_n": 2.0, "harmonics": one}),
        ),
        (
            "/excitation/frequency_hz",
            Some("HARMONICS_CONFLICT"),
            json!({"frequency_hz": 5.0, "harmonics": one}),
        ),
        (
            "/excitation/resonance_of_mode",
            Some("HARMONICS_CONFLICT"),
            json!({"resonance_of_mode": 1, "harmonics": one}),
        ),
        (
            "/excitation/phase_rad",
            Some("HARMONICS_CONFLICT"),
            json!({"phase_rad": 0.1, "harmonics": one}),
        ),
        (
            "/excitation/harmonics",
            None,
            json!({"type": "step", "harmonics": one}),
        ),
        ("/excitation/harmonics", None, json!({"harmonics": []})),
        (
            "/excitation/harmonics/1/resonance_of_mode",
            None,
            json!({"harmonics": [{"amplitude_n": 1.0, "frequency_hz": 5.0},
                                 {"amplitude_n": 1.0, "frequency_hz": 5.0, "resonance_of_mode": 1}]}),
        ),
        (
            "/excitation/harmonics/0/frequency_hz",
            None,
            json!({"harmonics": [{"amplitude_n": 1.0, "phase_rad": 0.0}]}),
        ),
        (
            "/excitation/harmonics/1/resonance_of_mode",
            Some("MODE_OUT_OF_RANGE"),
            json!({"harmonics": [{"amplitude_n": 1.0, "frequency_hz": 5.0},
                                 {"amplitude_n": 1.0, "resonance_of_mode": 4}]}),
        ),
    ];
    for (pointer, code, excitation) in cases {
        let r = post_json(PATH, &json!({"excitation": excitation})).await;
        assert_eq!(
            r.status,
            422,
            "{pointer}: {}",
            String::from_utf8_lossy(&r.bytes)
        );
        assert!(
            r.pointers().contains(&pointer.to_owned()),
            "{pointer}: got {:?}",
            r.pointers()
        );
        if let Some(code) = code {
            assert_eq!(r.json()["code"], code, "{pointer}");
        }
    }
    // 17 components: one more than the exosystem cap.
    let many: Vec<Value> = (0..17)
        .map(|j| json!({"amplitude_n": 1.0, "frequency_hz": 1.0 + f64::from(j)}))
        .collect();
    let r = post_json(PATH, &json!({"excitation": {"harmonics": many}})).await;
    assert_eq!(r.status, 422);
    assert!(r.pointers().contains(&"/excitation/harmonics".to_owned()));
}

/// Found by the contract fuzzer: every field in range, but a subnormal thickness makes w·t³/12
/// underflow to 0, so the beam has no natural frequency. The answer is a typed 422, not a 500.
#[tokio::test]
async fn a_section_whose_second_moment_underflows_is_refused_not_a_500() {
    let tiny = json!({
        "beam": {"youngs_modulus_pa": 7_880_847_593_003.108,
                 "section": {"width_m": 89.653_966_131_005_42, "thickness_m": 2.225_073_858_5e-313}},
        "control": {}, "excitation": {}
    });
    // Refused at the door: section sizes are documented at least 1e-30 (below it EI underflows).
    let r = post_json("/v1/vibration-absorber", &tiny).await;
    assert_eq!(r.status.as_u16(), 422, "{}", r.json());
    assert!(
        r.pointers()
            .iter()
            .any(|p| p == "/beam/section/thickness_m"),
        "{}",
        r.json()
    );
    // Extreme but representable sections still answer.
    for (w, t) in [(1e-6, 1e-6), (1e2, 1e2), (1e-6, 1e2)] {
        let body = json!({"beam": {"section": {"width_m": w, "thickness_m": t}}});
        let r = post_json("/v1/vibration-absorber", &body).await;
        assert!(
            matches!(r.status.as_u16(), 200 | 422),
            "w = {w}, t = {t}: {} {}",
            r.status,
            r.json()
        );
    }
}

/// The document's `x-cross-field-rules` of this operation: their codes.
fn documented_rule_codes() -> Vec<String> {
    let doc = serde_json::to_value(mechcalc::http::openapi()).expect("openapi");
    let rules = doc
        .pointer("/paths/~1v1~1vibration-absorber/post/x-cross-field-rules")
        .and_then(Value::as_array)
        .expect("x-cross-field-rules");
    rules
        .iter()
        .map(|r| r["code"].as_str().expect("code").to_owned())
        .collect()
}

/// Each rule between fields the operation lists is reachable: a request that passes every
/// per-field rule and breaks that one rule gets a 422 with the rule's code at the rule's pointer.
#[tokio::test]
async fn every_cross_field_rule_is_reachable() {
    let one = json!([{"amplitude_n": 1.0, "frequency_hz": 5.0}]);
    let grid = |lo: f64, hi: f64| json!({"f_min_hz": lo, "f_max_hz": hi, "n_points": 10});
    let cases: [(&str, &str, Value); 16] = [
        (
            "SECTION_CONFLICT",
            "/beam/section",
            json!({"beam": {"section": {"width_m": 0.05, "thickness_m": 0.005}, "area_m2": 1e-4}}),
        ),
        (
            "SECTION_PAIR",
            "/beam/second_moment_m4",
            json!({"beam": {"area_m2": 1e-4}}),
        ),
        (
            "SECTION_PAIR",
            "/beam/area_m2",
            json!({"beam": {"second_moment_m4": 1e-9}}),
        ),
        (
            "STIFFNESS_CONFLICT",
            "/absorber/stiffness_n_m",
            json!({"absorber": {"stiffness_n_m": 30.0}}),
        ),
        (
            "MODE_OUT_OF_RANGE",
            "/absorber/passive_tuning_mode",
            json!({"absorber": {"passive_tuning_hz": null, "passive_tuning_mode": 4}}),
        ),
        (
            "MODE_OUT_OF_RANGE",
            "/control/tuning_mode",
            json!({"control": {"tuning_hz": null, "tuning_mode": 4}}),
        ),
        (
            "POSITION_OUT_OF_BEAM",
            "/outputs/time_response/points_m/0",
            json!({"beam": {"length_m": 0.8},
                   "outputs": {"time_response": {"t_end_s": 0.1, "dt_s": 0.01, "points_m": [0.9]}}}),
        ),
        (
            "ZERO_FORCE_CONSTANT",
            "/actuator/force_constant_n_a",
            json!({"actuator": {"force_constant_n_a": 0.0}}),
        ),
        (
            "TUNING_CONFLICT",
            "/control/tuning_mode",
            json!({"control": {"tuning_mode": 2}}),
        ),
        (
            "GAIN_PAIR",
            "/control/kd_v_s_m",
            json!({"control": {"kp_v_m": 600.0}}),
        ),
        (
            "FREQUENCY_CONFLICT",
            "/excitation/resonance_of_mode",
            json!({"excitation": {"frequency_hz": 5.0, "resonance_of_mode": 1}}),
        ),
        (
            "HARMONICS_CONFLICT",
            "/excitation/phase_rad",
            json!({"excitation": {"phase_rad": 0.1, "harmonics": one}}),
        ),
        (
            "HARMONICS_TYPE",
            "/excitation/harmonics",
            json!({"excitation": {"type": "impulse", "harmonics": one}}),
        ),
        (
            "GRID_ORDER",
            "/outputs/ava_frequency_response/f_max_hz",
            json!({"outputs": {"ava_frequency_response": grid(10.0, 5.0)}}),
        ),
        (
            "TOO_MANY_SAMPLES",
            "/outputs/time_response/dt_s",
            json!({"outputs": {"time_response": {"t_end_s": 100.0, "dt_s": 1e-5}}}),
        ),
        (
            "RESPONSE_TOO_LARGE",
            "/outputs/time_response/decimate",
            json!({"outputs": {"time_response": {"t_end_s": 2000.0, "dt_s": 1e-3,
                                                 "return_series": true}}}),
        ),
    ];
    for (code, pointer, patch) in &cases {
        let r = post_json(PATH, &patched(patch)).await;
        let p = r.problem(422);
        assert_eq!(p["code"], *code, "{p}");
        assert_eq!(r.pointers(), [*pointer], "{code}: {p}");
    }
    // Every listed code is one of these, or a failure of the computation: NON_FINITE_RESPONSE
    // (reached by `a_section_whose_second_moment_underflows_is_refused_not_a_500`), a failed
    // eigen-iteration and a spent time budget.
    let computed = [
        "NON_FINITE_RESPONSE",
        "EIGEN_NOT_CONVERGED",
        "DEADLINE_EXCEEDED",
    ];
    let mut want: Vec<String> = cases
        .iter()
        .map(|c| c.0)
        .chain(computed)
        .map(str::to_owned)
        .collect();
    want.sort();
    want.dedup();
    let mut got = documented_rule_codes();
    got.sort();
    assert_eq!(got, want);
}

/// Set every optional member of `obj` that is absent to `null`.
fn null_absent(obj: &mut Value, keys: &[&str]) {
    let o = obj.as_object_mut().expect("object");
    for k in keys {
        o.entry(*k).or_insert(Value::Null);
    }
}

/// The answer without its timing.
fn untimed(r: &common::Reply) -> Value {
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let mut v = r.json();
    v["report"]
        .as_object_mut()
        .expect("report")
        .remove("elapsed_ms");
    v
}

/// `null` for an optional field is the same as leaving it out, at every depth: each `api/`
/// example with every optional member it omits set to `null` gets the example's answer, and
/// `null` for a whole optional object answers as its defaults.
#[tokio::test]
async fn null_means_absent() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/api/vibration_absorber");
    for name in ["paper_case", "frequency_sweep", "two_harmonics"] {
        let text = std::fs::read_to_string(format!("{dir}/{name}.json")).expect("example");
        let example: Value = serde_json::from_str(&text).expect("JSON");
        let plain = untimed(&post_json(PATH, &example).await);

        let mut b = example.clone();
        null_absent(&mut b, &["time_limit_ms", "actuator"]);
        null_absent(
            &mut b["beam"],
            &[
                "length_m",
                "youngs_modulus_pa",
                "density_kg_m3",
                "area_m2",
                "second_moment_m4",
                "section",
                "n_modes",
                "modal_damping_ratio",
            ],
        );
        null_absent(
            &mut b["absorber"],
            &[
                "mass_kg",
                "stiffness_n_m",
                "passive_tuning_hz",
                "passive_tuning_mode",
                "damping_n_s_m",
                "position_m",
            ],
        );
        if b["actuator"].is_object() {
            null_absent(
                &mut b["actuator"],
                &[
                    "resistance_ohm",
                    "inductance_h",
                    "force_constant_n_a",
                    "back_emf_v_s_m",
                ],
            );
        }
        null_absent(
            &mut b["control"],
            &["mode", "tuning_hz", "tuning_mode", "kp_v_m", "kd_v_s_m"],
        );
        null_absent(
            &mut b["excitation"],
            &[
                "type",
                "position_m",
                "amplitude_n",
                "frequency_hz",
                "resonance_of_mode",
                "phase_rad",
                "harmonics",
            ],
        );
        if let Some(list) = b["excitation"]["harmonics"].as_array_mut() {
            for h in list {
                null_absent(h, &["frequency_hz", "resonance_of_mode", "phase_rad"]);
            }
        }
        null_absent(
            &mut b["outputs"],
            &[
                "natural_frequencies",
                "eigenvalues",
                "ava_step",
                "ava_step_series",
                "ava_frequency_response",
                "frequency_response",
                "time_response",
                "mode_shapes",
            ],
        );
        if b["outputs"]["frequency_response"].is_object() {
            null_absent(
                &mut b["outputs"]["frequency_response"],
                &["log", "points_m"],
            );
        }
        if b["outputs"]["time_response"].is_object() {
            null_absent(
                &mut b["outputs"]["time_response"],
                &["points_m", "return_series", "decimate"],
            );
        }
        assert_ne!(b, example, "{name}: nothing was set to null");
        assert_eq!(untimed(&post_json(PATH, &b).await), plain, "{name}");
    }

    // A whole optional object as null is its defaults, the same as leaving it out.
    let mut nulls = json!({});
    let mut empty = json!({});
    for k in [
        "beam",
        "absorber",
        "actuator",
        "control",
        "excitation",
        "outputs",
    ] {
        nulls[k] = Value::Null;
        empty[k] = json!({});
    }
    let defaults = untimed(&post_json(PATH, &json!({})).await);
    assert_eq!(untimed(&post_json(PATH, &nulls).await), defaults);
    assert_eq!(untimed(&post_json(PATH, &empty).await), defaults);
}

/// A beam so soft (E·I near 1e-300) that its static compliance leaves f64: a typed 422
/// (`/problems/infeasible`, `NON_FINITE_ANSWER` naming the number), never a `null` or a 500;
/// E = 1e-200 Pa still answers with finite numbers.
#[tokio::test]
async fn results_beyond_f64_are_refused_by_name() {
    let r = post_json(
        PATH,
        &patched(&json!({"beam": {"youngs_modulus_pa": 1e-300}})),
    )
    .await;
    assert_eq!(r.status, 422, "{}", String::from_utf8_lossy(&r.bytes));
    let p = r.json();
    assert_eq!(p["code"], "NON_FINITE_ANSWER");
    assert_eq!(p["type"], "/problems/infeasible");
    assert!(
        p["detail"]
            .as_str()
            .is_some_and(|d| d.contains("/beam/static_compliance_m_per_n")),
        "{p}"
    );
    let r = post_json(
        PATH,
        &patched(&json!({"beam": {"youngs_modulus_pa": 1e-200}})),
    )
    .await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
}
