//! `POST /v1/component-importance` over HTTP: the paper's machining center comes back with its
//! ranking, and every kind of bad request gets the right problem+json answer with pointers to
//! the offending fields (spec §2 rejections).

use crate::common;

use common::{post_json, post_json_to};
use mechcalc::AppState;
use mechcalc::config::ServiceConfig;
use serde_json::{Value, json};

const PATH: &str = "/v1/component-importance";

fn machining_center() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/api/component_importance/machining_center.json"
    );
    serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("json")
}

fn complete_digraph(n: usize) -> Value {
    let comps: Vec<Value> = (0..n)
        .map(|i| json!({"id": format!("n{i}"), "weibull": {"eta_h": 5000.0, "beta": 0.8}, "mode_sum": 0.3}))
        .collect();
    let mut edges = Vec::new();
    for i in 0..n {
        for j in 0..n {
            if i != j {
                edges.push(json!([format!("n{i}"), format!("n{j}")]));
            }
        }
    }
    json!({"components": comps, "edges": edges, "times_h": [500.0]})
}

#[tokio::test]
async fn ranks_the_machining_center() {
    let r = post_json(PATH, &machining_center()).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(r.content_type(), "application/json");
    let b = r.json();
    // Spec VC4 / paper Table 9 ranks.
    assert_eq!(
        b["results"][0]["rank"],
        json!([2, 9, 10, 3, 6, 1, 5, 4, 7, 8])
    );
    assert_eq!(
        b["results"][1]["rank"],
        json!([2, 9, 10, 3, 5, 1, 6, 4, 7, 8])
    );
    let v = b["results"][0]["ci"][5].as_f64().expect("CI of V");
    assert!((v - 0.285_037_590).abs() < 1e-9, "{v}");
    assert_eq!(b["meta"]["is_dag"], true);
    assert_eq!(b["warnings"], json!([]));
    assert!(b.get("centralities").is_none() && b.get("matrices").is_none());
}

#[tokio::test]
async fn documented_schema_example_is_valid() {
    let doc = serde_json::to_value(mechcalc::http::openapi()).expect("openapi");
    let example = doc
        .pointer("/components/schemas/component_importance.ComponentImportanceRequest/example")
        .expect("request example in the schema")
        .clone();
    let r = post_json(PATH, &example).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    // Spec VC5 (clean run): S first at 500 h, V first at 2000 h.
    let b = r.json();
    assert_eq!(b["results"][0]["rank"][0], 1);
    assert_eq!(b["results"][1]["rank"][5], 1);
}

#[tokio::test]
async fn optional_outputs_on_request() {
    let mut b = machining_center();
    b["outputs"] = json!({"matrices": true, "reliability": true, "centralities": true});
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let v = r.json();
    assert_eq!(
        v["matrices"]["edge_betweenness"][0],
        json!({"from": "S", "to": "M", "value": 3.5})
    );
    assert!(v["matrices"]["T"].is_array() && v["matrices"]["HE"].is_array());
    assert!(v["results"][0]["F"].is_array() && v["results"][0]["RI_per_h"].is_array());
    let tau = v["results"][1]["kendall_tau_b"]["out_degree"]
        .as_f64()
        .expect("τ_b");
    assert!((tau - 0.804_030).abs() < 5e-7, "{tau}");
}

#[tokio::test]
async fn wrong_type_and_unknown_field_are_422_with_pointers() {
    let mut b = machining_center();
    b["times_h"][1] = json!("late");
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/times_h/1"]);

    let mut b = machining_center();
    b["options"]["path_kap"] = json!(3);
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/options/path_kap"]);

    let mut b = machining_center();
    b["components"][2]["weibull"]["eta"] = json!(100.0);
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/components/2/weibull/eta"]);
}

#[tokio::test]
async fn every_bad_field_is_listed() {
    // Per-field rules (the door): every offending field in one 422.
    let mut b = machining_center();
    b["times_h"][0] = json!(-1.0);
    b["components"][1]["weibull"]["beta"] = json!(25.0);
    b["overrides"][1]["F"]["S"] = json!(1.5);
    let r = post_json(PATH, &b).await;
    r.invalid_input_at(&[
        "/times_h/0",
        "/components/1/weibull/beta",
        "/overrides/1/F/S",
    ]);

    // Rules between fields (after the door): every offending field in one 422, each issue with
    // its rule's code.
    let mut b = machining_center();
    b["edges"]
        .as_array_mut()
        .expect("edges")
        .push(json!(["S", "S"]));
    b["edges"]
        .as_array_mut()
        .expect("edges")
        .push(json!(["S", "X"]));
    b["options"]["q_in"] = json!(0.3);
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/invalid-input");
    assert_eq!(r.pointers(), ["/edges/16", "/edges/17/1", "/options/o_out"]);
    let details: Vec<&str> = p["errors"]
        .as_array()
        .expect("errors")
        .iter()
        .filter_map(|e| e["detail"].as_str())
        .collect();
    for (d, code) in details
        .iter()
        .zip(["SELF_LOOP", "UNKNOWN_COMPONENT_ID", "Q_PLUS_O"])
    {
        assert!(d.starts_with(&format!("{code}: ")), "{d}");
    }
}

/// The document's `x-cross-field-rules` of this operation: their codes.
fn documented_rule_codes() -> Vec<String> {
    let doc = serde_json::to_value(mechcalc::http::openapi()).expect("openapi");
    let rules = doc
        .pointer("/paths/~1v1~1component-importance/post/x-cross-field-rules")
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
    type Edit = fn(&mut Value);
    let cases: [(&str, &str, Edit); 12] = [
        ("DUPLICATE_ID", "/components/10/id", |b| {
            b["components"].as_array_mut().expect("components").push(
                json!({"id": "S", "weibull": {"eta_h": 1000.0, "beta": 1.0}, "mode_sum": 0.2}),
            );
        }),
        ("UNKNOWN_COMPONENT_ID", "/overrides/0/F/X", |b| {
            b["overrides"][0]["F"]["X"] = json!(0.5);
        }),
        ("SELF_LOOP", "/edges/16", |b| {
            b["edges"]
                .as_array_mut()
                .expect("edges")
                .push(json!(["K", "K"]));
        }),
        ("DUPLICATE_EDGE", "/edges/16", |b| {
            b["edges"]
                .as_array_mut()
                .expect("edges")
                .push(json!(["S", "M"]));
        }),
        ("OVERRIDE_TIME", "/overrides/1/time_h", |b| {
            b["overrides"][1]["time_h"] = json!(500.0);
        }),
        ("WEIBULL_REQUIRED", "/components/2/weibull", |b| {
            b["components"][2]
                .as_object_mut()
                .expect("component")
                .remove("weibull");
        }),
        ("MODE_DATA_REQUIRED", "/components/2/failure_modes", |b| {
            b["components"][2]
                .as_object_mut()
                .expect("component")
                .remove("failure_modes");
        }),
        ("MODE_DATA_CONFLICT", "/components/2/mode_sum", |b| {
            b["components"][2]["mode_sum"] = json!(0.2);
        }),
        ("MODE_SUM_OVERFLOW", "/components/2/failure_modes", |b| {
            b["components"][2]["failure_modes"] =
                json!([{"alpha": 1.0, "impact": 1e308}, {"alpha": 1.0, "impact": 1e308}]);
        }),
        ("Q_PLUS_O", "/options/o_out", |b| {
            b["options"]["o_out"] = json!(0.7);
        }),
        ("WEIGHT_SUM", "/options/constant_weights/subjective", |b| {
            b["options"]["constant_weights"] =
                json!({"subjective": [0.5, 0.6], "entropy_at_h": 500});
        }),
        (
            "ENTROPY_TIME",
            "/options/constant_weights/entropy_at_h",
            |b| {
                b["options"]["constant_weights"] =
                    json!({"subjective": [0.5, 0.5], "entropy_at_h": 1000});
            },
        ),
    ];
    for (code, pointer, edit) in cases {
        let mut b = machining_center();
        edit(&mut b);
        let r = post_json(PATH, &b).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{p}");
        assert_eq!(r.pointers(), [pointer], "{code}: {p}");
    }
    // Every listed code is one of these, or a failure of the computation that the tests above
    // reach (budgets, hazard rate) or a backstop (non-finite result, answer size).
    let computed = [
        "SIMPLE_PATH_BUDGET_EXCEEDED",
        "PROPAGATION_PATH_BUDGET_EXCEEDED",
        "BUDGET_EXHAUSTED",
        "HAZARD_RATE_OVERFLOW",
        "NUMERICAL_FAILURE",
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

/// `null` for an optional field is the same as leaving it out, at every depth: the example with
/// every optional field it omits set to `null` gets the example's answer, and `null` for an
/// optional object it gives gets the answer of that object's defaults.
#[tokio::test]
async fn null_means_absent() {
    let answer = |r: &common::Reply| {
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
        let mut v = r.json();
        v["meta"]
            .as_object_mut()
            .expect("meta")
            .retain(|k, _| k != "elapsed_ms" && k != "report");
        v
    };
    let plain = answer(&post_json(PATH, &machining_center()).await);
    let mut b = machining_center();
    b["time_limit_ms"] = Value::Null;
    b["options"]["max_simple_paths"] = Value::Null;
    for c in b["components"].as_array_mut().expect("components") {
        for k in ["mode_sum", "efficiency_override", "level_override"] {
            c.as_object_mut()
                .expect("component")
                .entry(k)
                .or_insert(Value::Null);
        }
    }
    for o in b["overrides"].as_array_mut().expect("overrides") {
        o["RI"] = Value::Null;
    }
    assert_eq!(answer(&post_json(PATH, &b).await), plain);

    // Every option and output given as null = every one absent = the defaults; and null for the
    // top-level optional members is the same as leaving them out.
    let mut nulls = machining_center();
    for k in [
        "q_in",
        "o_out",
        "constant_weights",
        "path_cap",
        "path_method",
        "levels",
        "betweenness",
    ] {
        nulls["options"][k] = Value::Null;
    }
    for k in ["matrices", "indices", "reliability", "centralities"] {
        nulls["outputs"][k] = Value::Null;
    }
    let mut absent = machining_center();
    absent["options"] = json!({});
    absent["outputs"] = json!({});
    let defaults = answer(&post_json(PATH, &absent).await);
    assert_eq!(answer(&post_json(PATH, &nulls).await), defaults);
    // The example's options and outputs are the defaults.
    assert_eq!(defaults, plain);
    let mut top = machining_center();
    for k in ["overrides", "options", "outputs"] {
        top[k] = Value::Null;
    }
    let mut gone = machining_center();
    for k in ["overrides", "options", "outputs"] {
        gone.as_object_mut().expect("request").remove(k);
    }
    assert_eq!(
        answer(&post_json(PATH, &top).await),
        answer(&post_json(PATH, &gone).await)
    );
}

#[tokio::test]
async fn override_time_must_be_requested() {
    let mut b = machining_center();
    b["overrides"][1]["time_h"] = json!(1999.0);
    let r = post_json(PATH, &b).await;
    r.assert_422_at(&["/overrides/1/time_h"]);
}

#[tokio::test]
async fn cyclic_graph_over_the_enumeration_budget_is_too_large() {
    let r = post_json(PATH, &complete_digraph(10)).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/too-large");
    assert_eq!(p["code"], "SIMPLE_PATH_BUDGET_EXCEEDED");
    assert!(
        p["detail"]
            .as_str()
            .is_some_and(|d| d.contains("\"shortest_paths\"")),
        "{p}"
    );
    assert_eq!(r.pointers(), vec!["/options/betweenness"]);

    let mut b = complete_digraph(10);
    b["options"] = json!({"betweenness": "shortest_paths"});
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert_eq!(
        r.json()["meta"]["betweenness_algorithm"],
        "brandes_shortest_paths"
    );
}

#[tokio::test]
async fn exact_propagation_over_budget_suggests_walks() {
    let mut b = complete_digraph(30);
    b["options"] = json!({"betweenness": "shortest_paths", "path_cap": 5});
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "PROPAGATION_PATH_BUDGET_EXCEEDED");
    assert!(
        p["detail"]
            .as_str()
            .is_some_and(|d| d.contains("\"walks\"")),
        "{p}"
    );
}

#[tokio::test]
async fn hazard_rate_overflow_is_422_on_the_component() {
    let mut b = machining_center();
    b["overrides"] = json!([]);
    b["times_h"] = json!([1e300]);
    b["components"][3]["weibull"] = json!({"eta_h": 1e-300, "beta": 20.0});
    let r = post_json(PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "HAZARD_RATE_OVERFLOW");
    assert_eq!(r.pointers(), vec!["/components/3/weibull"]);
}

#[tokio::test]
async fn warnings_come_back_with_200() {
    let mut b = machining_center();
    b["components"].as_array_mut().expect("components").push(
        json!({"id": "Z", "weibull": {"eta_h": 1000.0, "beta": 1.0}, "failure_modes": [{"alpha": 0.5, "impact": 0.2}]}),
    );
    let r = post_json(PATH, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let w = r.json()["warnings"].to_string();
    assert!(
        w.contains("ALPHA_SUM") && w.contains("ISOLATED_COMPONENTS"),
        "{w}"
    );
}

#[tokio::test]
async fn exhausted_server_budget_is_too_large() {
    let config = ServiceConfig {
        max_time_budget_ms: 1,
        ..common::config()
    };
    let mut b = complete_digraph(9);
    b["options"] = json!({"max_simple_paths": 1e8});
    let r = post_json_to(AppState::new(config), PATH, &b).await;
    let p = r.problem(422);
    assert_eq!(p["type"], "/problems/too-large");
    assert_eq!(p["code"], "BUDGET_EXHAUSTED");
}
