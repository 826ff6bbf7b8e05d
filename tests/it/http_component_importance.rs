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
    b["times_h"][0] = json!(-1.0);
    b["components"][1]["weibull"]["beta"] = json!(25.0);
    b["overrides"][1]["F"]["S"] = json!(1.5);
    let r = post_json(PATH, &b).await;
    r.invalid_input_at(&[
        "/edges/16",
        "/edges/17/1",
        "/options/o_out",
        "/times_h/0",
        "/components/1/weibull/beta",
        "/overrides/1/F/S",
    ]);
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
