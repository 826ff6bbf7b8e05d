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

/// `(endpoint, code, request, pointer)`: a request the schema accepts (the door passes it) that
/// breaks one rule between fields.
#[expect(clippy::too_many_lines, reason = "one table of cases, one rule each")]
fn cross_rule_cases() -> Vec<(&'static str, &'static str, Value, &'static str)> {
    let train = |patch: &dyn Fn(&mut Value)| {
        let mut b = small_train();
        patch(&mut b);
        b
    };
    let smogn = |relevance: Value| {
        train(&|b: &mut Value| {
            b["preprocessing"] = json!({"smogn": {"relevance": relevance.clone()}});
        })
    };
    let predict = |patch: &dyn Fn(&mut Value)| {
        let mut b = example("predict_xgboost.json");
        patch(&mut b);
        b
    };
    let analyze = |patch: &dyn Fn(&mut Value)| {
        let mut b = example("analyze_synthetic.json");
        patch(&mut b);
        b
    };
    let five = |n: usize| json!(vec![json!([1.0, 2.0, 3.0, 4.0, 5.0]); n]);
    vec![
        (
            TRAIN,
            "FEATURE_NAME_EMPTY",
            train(&|b| b["feature_names"] = json!(["a", " "])),
            "/feature_names/1",
        ),
        (
            TRAIN,
            "FEATURE_NAME_DUPLICATE",
            train(&|b| b["feature_names"] = json!(["a", "a"])),
            "/feature_names/1",
        ),
        (
            TRAIN,
            "ROW_WIDTH",
            train(&|b| b["rows"][3] = json!([1.0])),
            "/rows/3",
        ),
        (
            TRAIN,
            "TARGET_LENGTH",
            train(&|b| b["target"] = json!([1.0, 2.0])),
            "/target",
        ),
        (
            TRAIN,
            "CONSTANT_TARGET",
            train(&|b| b["target"] = json!(vec![3.5; 30])),
            "/target",
        ),
        (
            TRAIN,
            "REG_LAMBDA_ZERO",
            train(&|b| {
                b["params"]["reg_lambda"] = json!(0.0);
                b["params"]["min_child_weight"] = json!(0.0);
            }),
            "/params/reg_lambda",
        ),
        (
            TRAIN,
            "TRAINING_ROWS",
            train(&|b| b["params"]["min_child_weight"] = json!(20.0)),
            "/params/min_child_weight",
        ),
        (
            TRAIN,
            "FOLD_ROWS",
            train(&|b| {
                b["params"]["min_child_weight"] = json!(8.0);
                b["validation"]["k_fold"] = json!(2);
            }),
            "/validation/k_fold",
        ),
        (
            TRAIN,
            "ALL_FEATURES_CONSTANT",
            train(&|b| b["rows"] = json!(vec![json!([1.0, 2.0]); 30])),
            "/rows",
        ),
        (
            TRAIN,
            "COLSAMPLE_NO_FEATURE",
            train(&|b| b["params"]["colsample_bytree"] = json!(0.4)),
            "/params/colsample_bytree",
        ),
        (
            TRAIN,
            "SHARD_INDEX_BELOW_COUNT",
            train(&|b| {
                b["validation"]["k_fold"] = json!(3);
                b["shard"] = json!({"index": 3, "count": 2});
            }),
            "/shard/index",
        ),
        (
            TRAIN,
            "SHARD_NOT_APPLICABLE",
            train(&|b| b["shard"] = json!({"index": 0, "count": 2})),
            "/shard",
        ),
        (
            TRAIN,
            "RELEVANCE_PHI",
            smogn(json!([[0.0, 0.0], [1.0, 1.5]])),
            "/preprocessing/smogn/relevance/1/1",
        ),
        (
            TRAIN,
            "RELEVANCE_ORDER",
            smogn(json!([[1.0, 0.0], [0.5, 1.0]])),
            "/preprocessing/smogn/relevance/1/0",
        ),
        (
            TRAIN,
            "SMOGN_DEGENERATE_RELEVANCE",
            smogn(json!([[-10.0, 1.0], [10.0, 1.0]])),
            "/preprocessing/smogn/relevance",
        ),
        (
            PREDICT,
            "MODEL_INVALID",
            predict(&|b| {
                b["model"]["xgboost_json"]["learner"]["gradient_booster"]["model"]["trees"][1]["right_children"]
                    [0] = json!(999);
            }),
            "/model/xgboost_json/learner/gradient_booster/model/trees/1/right_children/0",
        ),
        (
            PREDICT,
            "UNSUPPORTED_MODEL",
            predict(&|b| {
                b["model"]["xgboost_json"]["learner"]["objective"]["name"] =
                    json!("reg:pseudohubererror");
            }),
            "/model/xgboost_json/learner/objective/name",
        ),
        (
            PREDICT,
            "ROW_WIDTH",
            predict(&|b| b["rows"][1] = json!([1.0, 2.0])),
            "/rows/1",
        ),
        (
            PREDICT,
            "ROW_WIDTH",
            predict(&|b| {
                b["shap"] = json!("interventional");
                b["background"] = json!([[1.0, 2.0]]);
            }),
            "/background/0",
        ),
        (
            PREDICT,
            "FEATURE_NAMES_MISMATCH",
            predict(&|b| b["feature_names"][0] = json!("overhang")),
            "/feature_names/0",
        ),
        (
            PREDICT,
            "BACKGROUND_REQUIRED",
            predict(&|b| b["shap"] = json!("interventional")),
            "/background",
        ),
        (
            PREDICT,
            "TOO_LARGE",
            predict(&|b| {
                b["rows"] = five(1001);
                b["interactions"] = json!(true);
            }),
            "/interactions",
        ),
        (
            ANALYZE,
            "FEATURE_NAME_EMPTY",
            analyze(&|b| b["feature_names"][2] = json!("")),
            "/feature_names/2",
        ),
        (
            ANALYZE,
            "FEATURE_NAME_DUPLICATE",
            analyze(&|b| b["feature_names"][2] = b["feature_names"][0].clone()),
            "/feature_names/2",
        ),
        (
            ANALYZE,
            "ROW_WIDTH",
            analyze(&|b| b["rows"][5] = json!([1.0])),
            "/rows/5",
        ),
        (
            ANALYZE,
            "TARGET_LENGTH",
            analyze(&|b| b["target"] = json!([1.0])),
            "/target",
        ),
        (
            ANALYZE,
            "RELEVANCE_PHI",
            analyze(&|b| b["smogn"]["relevance"][0][1] = json!(-0.5)),
            "/smogn/relevance/0/1",
        ),
        (
            ANALYZE,
            "RELEVANCE_ORDER",
            analyze(&|b| {
                let y0 = b["smogn"]["relevance"][0][0].clone();
                b["smogn"]["relevance"][1][0] = y0;
            }),
            "/smogn/relevance/1/0",
        ),
        (
            ANALYZE,
            "SMOGN_DEGENERATE_RELEVANCE",
            analyze(&|b| {
                b["smogn"]["relevance"] = json!([[-1e9, 1.0], [1e9, 1.0]]);
            }),
            "/smogn/relevance",
        ),
        (
            ANALYZE,
            "GRA_ZERO_MEAN",
            analyze(&|b| {
                let n = b["rows"].as_array().map_or(0, Vec::len);
                for (i, r) in b["rows"]
                    .as_array_mut()
                    .expect("rows")
                    .iter_mut()
                    .enumerate()
                {
                    r[0] = json!(if i < n / 2 { -1.0 } else { 1.0 });
                }
            }),
            "/gra/normalise",
        ),
    ]
}

/// Every code each machining-size operation lists under `x-cross-field-rules` is reachable: a
/// request the schema accepts (the door passes it) that breaks the rule gets a 422 with that
/// code, pointing at the field the rule names. The work limits that need large bodies or a
/// spent budget are reached through the same conversion without HTTP.
#[tokio::test]
async fn every_listed_cross_field_rule_is_reachable() {
    use mechcalc::calc::machining_size::{
        self as ms, AnalyzeRequest, PredictRequest, TrainRequest,
    };
    use mechcalc::numerics::Budget;
    use std::collections::{BTreeMap, BTreeSet};
    let listed = |path: &str| -> BTreeSet<String> {
        mechcalc::http::openapi::document()["paths"][path]["post"]["x-cross-field-rules"]
            .as_array()
            .expect("the operation lists its cross-field rules")
            .iter()
            .filter_map(|r| r["code"].as_str().map(str::to_owned))
            .collect()
    };
    let mut reached: BTreeMap<&str, BTreeSet<String>> = BTreeMap::new();
    for (path, code, body, pointer) in cross_rule_cases() {
        let r = post_json(path, &body).await;
        let p = r.problem(422);
        assert_eq!(p["code"], code, "{path}: {p}");
        assert!(listed(path).contains(code), "{path}: {code} is not listed");
        assert!(
            r.pointers().iter().any(|q| q == pointer),
            "{path} {code}: {pointer} missing from {:?}",
            r.pointers()
        );
        reached.entry(path).or_default().insert(code.to_owned());
    }
    // The SHAP cells and interventional pairs of /predict, the PCA score cells of /analyze.
    let mut b = example("predict_xgboost.json");
    b["rows"] = json!(vec![json!([1.0, 2.0, 3.0, 4.0, 5.0]); 2000]);
    b["shap"] = json!("interventional");
    b["background"] = json!(vec![json!([1.0, 2.0, 3.0, 4.0, 5.0]); 501]);
    rejects(PREDICT, &b, "/background", Some("TOO_LARGE")).await;
    let mut b: AnalyzeRequest =
        serde_json::from_value(example("analyze_synthetic.json")).expect("request");
    b.rows = vec![b.rows[0].clone(); 100_000];
    b.target = (0..100_000).map(f64::from).collect();
    b.pca = serde_json::from_value(json!({"components": 41, "scores": true})).expect("pca");
    let e = ms::run_analyze(b, &Budget::unlimited()).expect_err("too many scores");
    assert_eq!(
        (e.code, e.errors[0].pointer.as_str()),
        ("TOO_LARGE", "/pca/scores")
    );
    // A spent budget before answers that cannot be partial.
    let spent = Budget::new(std::time::Duration::from_micros(1));
    std::thread::sleep(std::time::Duration::from_millis(2));
    let mut t = small_train();
    t["preprocessing"] =
        json!({"smogn": {"relevance": [[0.0, 0.0], [1.0, 1.0]], "threshold": 0.6}});
    let t: TrainRequest = serde_json::from_value(t).expect("request");
    let e = ms::run_train(t, &spent).expect_err("SMOGN cannot be partial");
    assert_eq!(e.code, "DEADLINE_EXCEEDED", "{e}");
    let p: PredictRequest =
        serde_json::from_value(example("predict_xgboost.json")).expect("request");
    let e = ms::run_predict(p, &spent).expect_err("SHAP cannot be partial");
    assert_eq!(e.code, "DEADLINE_EXCEEDED", "{e}");
    let a: AnalyzeRequest =
        serde_json::from_value(example("analyze_synthetic.json")).expect("request");
    let e = ms::run_analyze(a, &spent).expect_err("an analysis cannot be partial");
    assert_eq!(e.code, "DEADLINE_EXCEEDED", "{e}");
    for path in [TRAIN, PREDICT, ANALYZE] {
        let set = reached.entry(path).or_default();
        set.insert("DEADLINE_EXCEEDED".to_owned());
        if path != TRAIN {
            set.insert("TOO_LARGE".to_owned());
        }
    }
    // Answers over the service's --max-response-bytes.
    let small = mechcalc::AppState::new(mechcalc::config::ServiceConfig {
        max_response_bytes: 600,
        ..common::config()
    });
    for (path, body) in [
        (TRAIN, small_train()),
        (PREDICT, example("predict_xgboost.json")),
        (ANALYZE, example("analyze_synthetic.json")),
    ] {
        let r = common::post_json_to(small.clone(), path, &body).await;
        let p = r.problem(422);
        assert_eq!(p["code"], "RESPONSE_TOO_LARGE", "{path}: {p}");
        reached
            .entry(path)
            .or_default()
            .insert("RESPONSE_TOO_LARGE".to_owned());
    }
    for path in [TRAIN, PREDICT, ANALYZE] {
        let missing: Vec<String> = listed(path).difference(&reached[path]).cloned().collect();
        assert!(
            missing.is_empty(),
            "{path}: listed but not reached: {missing:?}"
        );
    }
}

/// The answer without the fields that measure time.
fn untimed(mut v: Value) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(o) => {
                o.remove("elapsed_ms");
                o.remove("timing_ms");
                o.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

/// Sets each `(parent pointer, key)` the request does not give to `null`.
fn with_nulls(mut b: Value, fields: &[(&str, &[&str])]) -> Value {
    for (parent, keys) in fields {
        let o = b
            .pointer_mut(parent)
            .and_then(Value::as_object_mut)
            .expect("object");
        for k in *keys {
            assert!(!o.contains_key(*k), "{parent}/{k} is given");
            o.insert((*k).to_owned(), Value::Null);
        }
    }
    b
}

/// `null` for an optional field means absent, at every depth: each endpoint's example (and a
/// small training request whose optional objects are absent) with every optional field it
/// omits sent as `null` gives exactly the answer of the plain request.
#[tokio::test]
async fn null_optional_fields_read_as_absent() {
    let params: &[&str] = &[
        "reg_lambda",
        "reg_alpha",
        "gamma",
        "min_child_weight",
        "subsample",
        "base_score",
        "max_bin",
    ];
    let cases = [
        (
            TRAIN,
            example("train_synthetic.json"),
            vec![
                ("", &["shard"][..]),
                ("/params", params),
                ("/preprocessing", &["smogn"][..]),
            ],
        ),
        (
            TRAIN,
            small_train(),
            vec![
                (
                    "",
                    &["preprocessing", "outputs", "time_limit_ms", "shard"][..],
                ),
                (
                    "/params",
                    &[
                        "reg_lambda",
                        "gamma",
                        "min_child_weight",
                        "subsample",
                        "seed",
                        "base_score",
                        "tree_method",
                        "max_bin",
                    ][..],
                ),
                ("/validation", &["k_fold", "seed"][..]),
            ],
        ),
        (
            PREDICT,
            example("predict_xgboost.json"),
            vec![("", &["background", "interactions", "time_limit_ms"][..])],
        ),
        (
            ANALYZE,
            example("analyze_synthetic.json"),
            vec![
                ("", &["time_limit_ms"][..]),
                ("/pca", &["scores"][..]),
                ("/smogn", &["include_data"][..]),
            ],
        ),
    ];
    for (path, plain, fields) in cases {
        let nulls = with_nulls(plain.clone(), &fields);
        let (a, b) = (post_json(path, &plain).await, post_json(path, &nulls).await);
        assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
        assert_eq!(b.status, 200, "{}", String::from_utf8_lossy(&b.bytes));
        assert_eq!(untimed(a.json()), untimed(b.json()), "{path}");
    }
    // Optional objects and their fields with struct defaults, sent as null.
    let mut plain = small_train();
    plain.as_object_mut().map(|o| o.remove("params"));
    let mut nulls = plain.clone();
    nulls["params"] = Value::Null;
    nulls["validation"] = json!({"test_fraction": null, "k_fold": null, "seed": null});
    plain["validation"] = json!({});
    let (a, b) = (
        post_json(TRAIN, &plain).await,
        post_json(TRAIN, &nulls).await,
    );
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
    assert_eq!(untimed(a.json()), untimed(b.json()));
    let mut analyze = example("analyze_synthetic.json");
    analyze["gra"] = json!({});
    analyze["smogn"] = json!({"relevance": analyze["smogn"]["relevance"].clone()});
    let mut nulls = analyze.clone();
    nulls["gra"] = json!({"rho": null, "normalise": null});
    nulls["pca"] = json!({"components": null, "scores": null});
    analyze["pca"] = json!({});
    for k in ["threshold", "k", "perturbation", "seed", "include_data"] {
        nulls["smogn"][k] = Value::Null;
    }
    let (a, b) = (
        post_json(ANALYZE, &analyze).await,
        post_json(ANALYZE, &nulls).await,
    );
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.bytes));
    assert_eq!(untimed(a.json()), untimed(b.json()));
    // A required field stays required: null is a 422 naming it.
    let mut b = small_train();
    b["target"] = Value::Null;
    post_json(TRAIN, &b).await.assert_422_at(&["/target"]);
}
