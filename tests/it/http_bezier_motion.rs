//! `POST /v1/bezier-motion-law` over HTTP: the api/ examples are answered, optional outputs only
//! when asked, and bad requests get problem+json with a JSON pointer per offending field (400
//! malformed, 415 content type, 422 out of range).

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
