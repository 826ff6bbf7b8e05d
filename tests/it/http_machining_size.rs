//! `POST /v1/machining-size/{train,predict,analyze}` over HTTP: answers, optional outputs only
//! when asked, every rejection of spec §2.5 as a 422 with its pointer, hostile model documents
//! rejected (never followed), and training that reports how it stopped.

use crate::common;

use common::post_json;
use serde_json::{Value, json};

const TRAIN: &str = "/v1/machining-size/train";
const PREDICT: &str = "/v1/machining-size/predict";
const ANALYZE: &str = "/v1/machining-size/analyze";

fn example(name: &str) -> Value {
    let path = format!("{}/api/machining_size/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("JSON")
}

/// A small training request: 30 rows, 2 features, y = step in x0 plus a little of x1.
fn small_train() -> Value {
    let rows: Vec<Value> = (0..30)
        .map(|i| json!([f64::from(i % 5), f64::from(i % 3)]))
        .collect();
    let target: Vec<f64> = (0..30)
        .map(|i| if i % 5 >= 3 { 1.0 } else { 0.0 } + 0.1 * f64::from(i % 3))
        .collect();
    json!({
        "feature_names": ["a", "b"],
        "rows": rows,
        "target": target,
        "params": {"n_estimators": 20, "max_depth": 2, "learning_rate": 0.3, "reg_alpha": 0.0,
                   "colsample_bytree": 1.0},
        "validation": {"test_fraction": 0.2}
    })
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

/// Sends `body` and asserts a 422 naming `pointer`, with `code` when given.
async fn rejects(path: &str, body: &Value, pointer: &str, code: Option<&str>) {
    let r = post_json(path, body).await;
    let p = r.problem(422);
    assert!(
        r.pointers().iter().any(|q| q == pointer),
        "expected pointer {pointer}, got {p}"
    );
    if let Some(code) = code {
        assert_eq!(p["code"], code, "{p}");
    }
}

#[tokio::test]
async fn trains_and_predicts_round_trip() {
    let mut body = small_train();
    body["outputs"] = json!(["test_predictions"]);
    let r = post_json(TRAIN, &body).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let t = r.json();
    assert!(t.get("importance").is_none() && t.get("shap_summary").is_none());
    assert_eq!(t["model"]["format"], "machining-size-gbdt/1");
    assert_eq!(t["report"]["stop_reason"], "completed");
    let tp = &t["test_predictions"];
    let idx: Vec<usize> = tp["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(|v| usize::try_from(v.as_u64().expect("i")).expect("usize"))
        .collect();
    let rows: Vec<Value> = idx.iter().map(|&i| body["rows"][i].clone()).collect();
    let p = post_json(
        PREDICT,
        &json!({"model": t["model"], "rows": rows, "shap": "path_dependent", "interactions": true}),
    )
    .await;
    assert_eq!(p.status, 200, "{}", String::from_utf8_lossy(&p.bytes));
    let p = p.json();
    for (a, b) in p["predictions"]
        .as_array()
        .expect("predictions")
        .iter()
        .zip(tp["prediction"].as_array().expect("predictions"))
    {
        assert_eq!(
            num(a).to_bits(),
            num(b).to_bits(),
            "predict = train's test predictions"
        );
    }
    assert!(num(&p["shap"]["local_accuracy_max_abs"]) < 1e-14);
    let inter = &p["interactions"][0];
    for i in 0..2 {
        let row_sum: f64 = inter[i].as_array().expect("row").iter().map(num).sum();
        assert!((row_sum - num(&p["shap"]["values"][0][i])).abs() < 1e-14);
    }
    assert_eq!(p["model_summary"]["routing"], "f64");
}

#[tokio::test]
async fn optional_outputs_only_when_asked() {
    let r = post_json(TRAIN, &small_train()).await;
    let t = r.json();
    assert!(
        t["importance"].is_array(),
        "importance is the default output"
    );
    assert!(t.get("shap_summary").is_none() && t.get("test_predictions").is_none());
    assert!(t["metrics"].get("cv").is_none());
    let p = post_json(PREDICT, &json!({"model": t["model"], "rows": [[1.0, 2.0]]})).await;
    let p = p.json();
    assert!(p.get("shap").is_none() && p.get("interactions").is_none());
}

#[tokio::test]
async fn spec_2_5_rejections_of_train() {
    let base = small_train();
    let mut cases: Vec<(Value, &str)> = Vec::new();
    let mut b = base.clone();
    b["rows"][3] = json!([1.0]);
    cases.push((b, "/rows/3"));
    let mut b = base.clone();
    b["target"] = json!([1.0, 2.0]);
    cases.push((b, "/target"));
    let mut b = base.clone();
    b["feature_names"] = json!(["a", "a"]);
    cases.push((b, "/feature_names/1"));
    let mut b = base.clone();
    b["params"]["min_child_weight"] = json!(20.0);
    cases.push((b, "/params/min_child_weight"));
    let mut b = base.clone();
    b["target"] = json!(vec![3.5; 30]);
    cases.push((b, "/target"));
    let mut b = base.clone();
    b["params"]["n_estimators"] = json!(5001);
    cases.push((b, "/params/n_estimators"));
    let mut b = base.clone();
    b["params"]["colsample_bytree"] = json!(0.4);
    cases.push((b, "/params/colsample_bytree"));
    let mut b = base.clone();
    b["params"]["reg_lambda"] = json!(0.0);
    b["params"]["min_child_weight"] = json!(0.0);
    cases.push((b, "/params/reg_lambda"));
    let mut b = base.clone();
    b["preprocessing"] = json!({"smogn": {"relevance": [[0.0, 0.0], [1.0, 1.5]]}});
    cases.push((b, "/preprocessing/smogn/relevance/1/1"));
    let mut b = base.clone();
    b["preprocessing"] = json!({"smogn": {"relevance": [[0.0, 0.0]]}});
    cases.push((b, "/preprocessing/smogn/relevance"));
    let mut b = base.clone();
    b["rows"] = json!(vec![json!([1.0, 2.0]); 30]);
    cases.push((b, "/rows"));
    let mut b = base.clone();
    b["target"][4] = json!(1e101);
    cases.push((b, "/target/4"));
    let mut b = base.clone();
    b["rows"] = json!(vec![json!([1.0, 2.0]); 5]);
    b["target"] = json!([1.0, 2.0, 3.0, 4.0, 5.0]);
    cases.push((b, "/rows"));
    let mut b = base.clone();
    b["feature_names"] = json!((0..201).map(|i| format!("f{i}")).collect::<Vec<_>>());
    cases.push((b, "/feature_names"));
    for (body, pointer) in &cases {
        rejects(TRAIN, body, pointer, None).await;
    }
}

#[tokio::test]
async fn more_than_100000_rows_is_rejected() {
    let mut b = small_train();
    b["rows"] = json!(vec![json!([1.0, 2.0]); 100_001]);
    b["target"] = json!(vec![1.0; 100_001]);
    rejects(TRAIN, &b, "/rows", Some("TOO_LARGE")).await;
}

#[tokio::test]
async fn degenerate_smogn_relevance_is_infeasible() {
    let mut b = small_train();
    b["preprocessing"] = json!({"smogn": {"relevance": [[-10.0, 1.0], [10.0, 1.0]]}});
    let r = post_json(TRAIN, &b).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "SMOGN_DEGENERATE_RELEVANCE");
    assert_eq!(p["type"], "/problems/infeasible");
    assert_eq!(r.pointers(), ["/preprocessing/smogn/relevance"]);
}

#[tokio::test]
async fn training_reports_how_it_stopped() {
    let mut b = small_train();
    b["params"]["n_estimators"] = json!(5000);
    b["params"]["max_depth"] = json!(12);
    b["params"]["colsample_bytree"] = json!(0.5);
    b["time_limit_ms"] = json!(1);
    let r = post_json(TRAIN, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let t = r.json();
    assert_eq!(t["report"]["stop_reason"], "deadline");
    assert!(t["report"]["iterations"].as_u64().expect("n") < 5000);
    assert!(
        t["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .any(|w| w["code"] == "TRAINING_STOPPED")
    );
    // A data set whose rounds stop changing: a zero leaf with every feature in use.
    let mut b = small_train();
    b["params"]["reg_alpha"] = json!(1e6);
    let t = post_json(TRAIN, &b).await.json();
    assert_eq!(t["report"]["stop_reason"], "converged");
    assert_eq!(t["report"]["iterations"], 1);
    assert_eq!(t["effective_trees"], 0);
}

fn native_model() -> Value {
    json!({
        "format": "machining-size-gbdt/1", "objective": "reg:squarederror", "base_score": 4.0,
        "feature_names": ["x"], "n_features": 1,
        "trees": [{"left": [1, -1, -1], "right": [2, -1, -1], "feature": [0, -1, -1],
                   "threshold": [3.5, 0.0, 0.0], "value": [0.0, -1.5, 3.0],
                   "cover": [4.0, 3.0, 1.0], "loss_change": [27.0, 0.0, 0.0]}]
    })
}

#[tokio::test]
async fn predicts_t1_from_a_native_document() {
    let r = post_json(
        PREDICT,
        &json!({"model": native_model(), "rows": [[1.0], [4.0]], "shap": "path_dependent"}),
    )
    .await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    let p = r.json();
    assert_eq!(p["predictions"], json!([2.5, 7.0]));
    assert_eq!(p["shap"]["expected_value"], json!(3.625));
    assert_eq!(p["shap"]["values"], json!([[-1.125], [3.375]]));
}

#[tokio::test]
async fn hostile_model_documents_are_rejected_with_a_pointer() {
    let rows = json!([[1.0]]);
    let with = |f: &dyn Fn(&mut Value)| {
        let mut m = native_model();
        f(&mut m);
        json!({"model": m, "rows": rows})
    };
    let cases: Vec<(Value, &str, &str)> = vec![
        (
            with(&|m| m["trees"][0]["left"][0] = json!(7)),
            "/model/trees/0/left/0",
            "MODEL_INVALID",
        ),
        (
            with(&|m| {
                m["trees"][0]["left"] = json!([1, 0, -1]);
                m["trees"][0]["right"] = json!([2, 2, -1]);
            }),
            "/model/trees/0/left/1",
            "MODEL_INVALID",
        ),
        (
            with(&|m| m["trees"][0]["left"][0] = json!(-2)),
            "/model/trees/0/left/0",
            "MODEL_INVALID",
        ),
        (
            with(&|m| m["trees"][0]["feature"][0] = json!(3)),
            "/model/trees/0/feature/0",
            "MODEL_INVALID",
        ),
        (
            with(&|m| m["trees"][0]["value"][1] = json!(1e300)),
            "/model/trees/0/value/1",
            "MODEL_INVALID",
        ),
        (
            with(&|m| m["trees"][0]["cover"][2] = json!(-1.0)),
            "/model/trees/0/cover/2",
            "MODEL_INVALID",
        ),
        (
            with(&|m| m["objective"] = json!("reg:absoluteerror")),
            "/model/objective",
            "UNSUPPORTED_MODEL",
        ),
        (
            with(&|m| m["trees"] = json!(vec![m["trees"][0].clone(); 5001])),
            "/model/trees",
            "MODEL_INVALID",
        ),
        (
            // An unknown member fails the published shape, which the service checks before
            // the module reads the document: the service-wide code.
            with(&|m| m["extra"] = json!(1)),
            "/model/extra",
            "INVALID_INPUT",
        ),
    ];
    for (body, pointer, code) in &cases {
        rejects(PREDICT, body, pointer, Some(code)).await;
    }
    // Absurd depth: a chain of 70 splits.
    let n = 141;
    let (mut left, mut right) = (vec![-1i64; n], vec![-1i64; n]);
    for i in 0..70 {
        left[2 * i] = (2 * i + 1) as i64;
        right[2 * i] = (2 * i + 2) as i64;
    }
    let mut m = native_model();
    m["trees"] = json!([{"left": left, "right": right, "feature": vec![0; n],
                         "threshold": vec![0.5; n], "value": vec![0.0; n], "cover": vec![1.0; n]}]);
    let r = post_json(PREDICT, &json!({"model": m, "rows": rows})).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "MODEL_INVALID");
    assert!(
        p["detail"].as_str().expect("detail").contains("deeper"),
        "{p}"
    );
}

#[tokio::test]
async fn xgboost_documents_outside_v1_are_rejected() {
    let mut req = example("predict_xgboost.json");
    req["model"]["xgboost_json"]["learner"]["objective"]["name"] = json!("reg:pseudohubererror");
    rejects(
        PREDICT,
        &req,
        "/model/xgboost_json/learner/objective/name",
        Some("UNSUPPORTED_MODEL"),
    )
    .await;
    let mut req = example("predict_xgboost.json");
    req["model"]["xgboost_json"]["learner"]["gradient_booster"]["model"]["trees"][1]["right_children"]
        [0] = json!(999);
    rejects(
        PREDICT,
        &req,
        "/model/xgboost_json/learner/gradient_booster/model/trees/1/right_children/0",
        Some("MODEL_INVALID"),
    )
    .await;
    let mut req = example("predict_xgboost.json");
    req["model"]["other"] = json!(1);
    rejects(PREDICT, &req, "/model/other", None).await;
}

#[tokio::test]
async fn predict_request_rules() {
    let req = example("predict_xgboost.json");
    let mut b = req.clone();
    b["shap"] = json!("interventional");
    rejects(PREDICT, &b, "/background", None).await;
    let mut b = req.clone();
    b["rows"][1] = json!([1.0, 2.0]);
    rejects(PREDICT, &b, "/rows/1", None).await;
    let mut b = req.clone();
    b["feature_names"][0] = json!("overhang");
    rejects(PREDICT, &b, "/feature_names/0", None).await;
    let mut b = req.clone();
    b["rows"] = json!(vec![json!([1.0, 2.0, 3.0, 4.0, 5.0]); 1001]);
    b["interactions"] = json!(true);
    rejects(PREDICT, &b, "/interactions", Some("TOO_LARGE")).await;
    let mut b = req.clone();
    b["rows"] = json!(vec![json!([1.0, 2.0, 3.0, 4.0, 5.0]); 2000]);
    b["shap"] = json!("interventional");
    b["background"] = json!(vec![json!([1.0, 2.0, 3.0, 4.0, 5.0]); 501]);
    rejects(PREDICT, &b, "/background", Some("TOO_LARGE")).await;
    // Interventional with a background is locally accurate on the XGBoost model.
    let mut b = req.clone();
    b["shap"] = json!("interventional");
    b["background"] = json!([
        [50.0, 3000.0, 300.0, 2.0, 0.5],
        [70.0, 5000.0, 500.0, 4.0, 1.5]
    ]);
    let r = post_json(PREDICT, &b).await;
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.bytes));
    assert!(num(&r.json()["shap"]["local_accuracy_max_abs"]) < 1e-12);
}

#[tokio::test]
async fn analyze_rules() {
    let req = example("analyze_synthetic.json");
    let mut b = req.clone();
    b["gra"] = json!({"normalise": "mean"});
    // Column 0 becomes −1 for the first half of the rows and +1 for the rest: mean 0.
    let n = b["rows"].as_array().expect("rows").len();
    for (i, r) in b["rows"]
        .as_array_mut()
        .expect("rows")
        .iter_mut()
        .enumerate()
    {
        r[0] = json!(if i < n / 2 { -1.0 } else { 1.0 });
    }
    let r = post_json(ANALYZE, &b).await;
    let p = r.problem(422);
    assert_eq!(p["code"], "GRA_ZERO_MEAN");
    assert_eq!(r.pointers(), ["/gra/normalise"]);
    b["gra"]["normalise"] = json!("none");
    assert_eq!(post_json(ANALYZE, &b).await.status, 200);
    let mut b = req.clone();
    b["pca"]["components"] = json!(0);
    rejects(ANALYZE, &b, "/pca/components", None).await;
    let mut b = req.clone();
    b["smogn"]["relevance"] = json!([[19.99, 0.0], [19.98, 1.0]]);
    rejects(ANALYZE, &b, "/smogn/relevance/1/0", None).await;
    let mut b = req;
    b["pca"] = json!({"components": 9});
    let a = post_json(ANALYZE, &b).await.json();
    assert!(
        a["warnings"]
            .as_array()
            .expect("warnings")
            .iter()
            .any(|w| w["code"] == "PCA_COMPONENTS_CLAMPED")
    );
    let rates: f64 = a["pca"]["contribution_rates"]
        .as_array()
        .expect("rates")
        .iter()
        .map(num)
        .sum();
    assert!((rates - 100.0).abs() < 1e-9);
}
