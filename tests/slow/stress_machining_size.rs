//! Stress tests near every hazard of machining_size (spec §8): constant columns, duplicated rows,
//! 1e12-scale targets (centring), huge and tiny learning rates, a 5000-tree model, extreme
//! feature values, zero covers and randomly mutated (hostile) model documents. Every request ends
//! in a typed 422 or an answer whose numbers are all finite. `STRESS_CASES=…` scales the random
//! document mutations (default 300).

use std::time::Duration;

use mechcalc::calc::machining_size::{
    AnalyzeRequest, PredictRequest, TrainRequest, TrainResponse, run_analyze, run_predict,
    run_train,
};
use mechcalc::calc::{CalcFailure, ProblemClass};
use mechcalc::numerics::{Budget, StopReason};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

use crate::support::finite::assert_finite;
use crate::support::proptest_cfg;

/// `STRESS_CASES`, default 300.
fn stress_cases() -> usize {
    proptest_cfg::stress_cases(300)
}

fn train(body: Value) -> Result<TrainResponse, CalcFailure> {
    let req: TrainRequest = serde_json::from_value(body).expect("request decodes");
    let r = run_train(req, &Budget::unlimited());
    if let Ok(t) = &r {
        assert_finite(t);
    }
    r
}

fn predict(body: Value) -> Result<mechcalc::calc::machining_size::PredictResponse, CalcFailure> {
    let req: PredictRequest = serde_json::from_value(body).expect("request decodes");
    let r = run_predict(req, &Budget::unlimited());
    if let Ok(p) = &r {
        assert_finite(p);
    }
    r
}

/// A data set of `n` rows: x0 on 5 levels, x1 on 3, x2 constant, y a step in x0 plus x1.
fn data(n: usize, offset: f64) -> Value {
    let rows: Vec<Value> = (0..n)
        .map(|i| json!([(i % 5) as f64, (i % 3) as f64, 7.0]))
        .collect();
    let y: Vec<f64> = (0..n)
        .map(|i| offset + if i % 5 >= 3 { 0.02 } else { 0.0 } + 0.01 * (i % 3) as f64)
        .collect();
    json!({"feature_names": ["a", "b", "c"], "rows": rows, "target": y,
           "params": {"n_estimators": 60, "max_depth": 3, "learning_rate": 0.3,
                      "reg_alpha": 0.0, "reg_lambda": 0.01, "colsample_bytree": 1.0},
           "validation": {"test_fraction": 0.2, "k_fold": 3},
           "outputs": ["importance", "shap_summary", "test_predictions"]})
}

fn predictions(t: &TrainResponse) -> Vec<f64> {
    t.test_predictions
        .as_ref()
        .expect("asked")
        .prediction
        .clone()
}

#[test]
fn constant_columns_and_duplicated_rows() {
    // Only x2 constant: dropped, never split on.
    let t = train(data(50, 20.0)).expect("trains");
    assert_eq!(t.preprocessing.dropped_constant, ["c"]);
    // Every feature constant: a typed 422 with drop_constant, the mean without it.
    let mut b = data(50, 20.0);
    b["rows"] = json!(vec![json!([1.0, 2.0, 3.0]); 50]);
    let e = train(b.clone()).expect_err("nothing to split on");
    assert_eq!(e.errors[0].pointer, "/rows");
    b["preprocessing"] = json!({"drop_constant": false});
    let t = train(b).expect("fits the mean");
    assert_eq!(t.effective_trees, 0);
    // Duplicated rows: two distinct rows, 25 copies each.
    let mut b = data(50, 0.0);
    b["rows"] = json!(
        (0..50)
            .map(|i| json!([(i % 2) as f64, 0.0, 1.0]))
            .collect::<Vec<_>>()
    );
    b["target"] = json!((0..50).map(|i| (i % 2) as f64).collect::<Vec<_>>());
    let t = train(b).expect("trains");
    assert!(t.metrics.train.rmse < 0.05, "{}", t.metrics.train.rmse);
}

/// Hazard 8.1: sizes at 1e12 train as well as at 0 because the target is centred in f64: the
/// predictions differ by the offset to within its rounding (ulp(1e12) = 1.2e-4).
#[test]
fn large_offset_targets_are_centred() {
    let a = train(data(200, 0.0)).expect("trains");
    let b = train(data(200, 1e12)).expect("trains");
    for (pa, pb) in predictions(&a).iter().zip(predictions(&b)) {
        assert!((pb - 1e12 - pa).abs() < 5e-4, "{pa} vs {}", pb - 1e12);
    }
    assert!((a.metrics.train.rmse - b.metrics.train.rmse).abs() < 5e-4);
    // Targets at the bound of the range (±1e100): gains ~1e200·rows stay finite.
    let mut big = data(200, 0.0);
    let y: Vec<f64> = big["target"]
        .as_array()
        .expect("target")
        .iter()
        .map(|v| v.as_f64().expect("number") * 2e101 - 1e100)
        .collect();
    big["target"] = json!(y);
    let c = train(big).expect("trains");
    assert!(c.metrics.train.rmse < 1e98, "{}", c.metrics.train.rmse);
}

#[test]
fn huge_and_tiny_learning_rates() {
    for (eta, lambda) in [
        (1.0, 0.0),
        (1.0, 1e6),
        (1e-12, 0.1),
        (f64::MIN_POSITIVE, 0.0),
    ] {
        let mut b = data(60, 19.96);
        b["params"]["learning_rate"] = json!(eta);
        b["params"]["reg_lambda"] = json!(lambda);
        let t = train(b).expect("trains");
        // η = 1, λ = 0 fits these data exactly in one round: later rounds are zero leaves.
        assert!(
            matches!(
                t.report.stop_reason,
                StopReason::Completed | StopReason::Converged
            ),
            "η {eta}, λ {lambda}: {:?}",
            t.report.stop_reason
        );
    }
}

#[test]
fn a_5000_tree_model_trains_predicts_and_explains() {
    let mut b = data(40, 5.0);
    b["params"]["n_estimators"] = json!(5000);
    b["params"]["colsample_bytree"] = json!(0.5);
    b["params"]["learning_rate"] = json!(0.01);
    b["validation"] = json!({"test_fraction": 0.0});
    b["outputs"] = json!([]);
    let t = train(b).expect("trains");
    assert_eq!(t.model.trees.len(), 5000);
    let rows: Vec<Vec<f64>> = (0..20)
        .map(|i| vec![(i % 5) as f64, (i % 3) as f64, 7.0])
        .collect();
    let p = predict(
        json!({"model": t.model, "rows": rows, "shap": "path_dependent",
                           "interactions": true}),
    )
    .expect("predicts");
    let shap = p.shap.expect("asked");
    assert!(
        shap.local_accuracy_max_abs < 1e-10,
        "{}",
        shap.local_accuracy_max_abs
    );
    let p = predict(
        json!({"model": t.model, "rows": rows, "shap": "interventional",
                           "background": rows}),
    )
    .expect("predicts");
    assert!(p.shap.expect("asked").local_accuracy_max_abs < 1e-10);
}

#[test]
fn extreme_feature_values() {
    for v in [1e300, -1e300, f64::MAX, -f64::MAX, 5e-324] {
        let mut b = data(30, 1.0);
        b["rows"][0][0] = json!(v);
        b["rows"][7][1] = json!(-v);
        let t = train(b.clone()).expect("trains");
        let p = predict(
            json!({"model": t.model, "rows": [[v, -v, 7.0], [0.0, 0.0, 7.0]],
                               "shap": "path_dependent"}),
        )
        .expect("predicts");
        assert!(p.predictions.iter().all(|x| x.is_finite()));
        let a: AnalyzeRequest = serde_json::from_value(json!({
            "feature_names": b["feature_names"], "rows": b["rows"], "target": b["target"],
            "pca": {"scores": true}, "gra": {"normalise": "none"},
            "smogn": {"relevance": [[1.0, 0.0], [1.03, 1.0]], "perturbation": 1.0}
        }))
        .expect("decodes");
        match run_analyze(a, &Budget::unlimited()) {
            Ok(r) => assert_finite(&r),
            Err(e) => assert_eq!(e.class, ProblemClass::Infeasible, "{e}"),
        }
    }
}

fn native() -> Value {
    json!({
        "format": "machining-size-gbdt/1", "objective": "reg:squarederror", "base_score": 1.0,
        "feature_names": ["a", "b"], "n_features": 2,
        "trees": [
            {"left": [1, 3, -1, -1, -1], "right": [2, 4, -1, -1, -1], "feature": [0, 1, -1, -1, -1],
             "threshold": [0.5, 2.0, 0.0, 0.0, 0.0], "value": [0.0, 0.0, 1.0, -2.0, 3.0],
             "cover": [10.0, 6.0, 4.0, 2.0, 4.0], "loss_change": [1.0, 0.5, 0.0, 0.0, 0.0]},
            {"left": [1, -1, -1], "right": [2, -1, -1], "feature": [1, -1, -1],
             "threshold": [1.0, 0.0, 0.0], "value": [0.0, -0.5, 0.5],
             "cover": [10.0, 0.0, 10.0], "loss_change": [0.3, 0.0, 0.0]}
        ]
    })
}

/// Zero covers (possible in imported models, hazard 9): fractions 0 instead of 0/0, φ finite and
/// locally accurate.
#[test]
fn zero_covers_are_safe() {
    let mut m = native();
    m["trees"][0]["cover"] = json!([0.0, 0.0, 0.0, 0.0, 0.0]);
    let rows = json!([[0.0, 0.0], [1.0, 5.0], [0.2, 3.0]]);
    for shap in ["path_dependent", "interventional"] {
        let p = predict(
            json!({"model": m, "rows": rows, "shap": shap, "background": rows,
                               "interactions": true}),
        )
        .expect("predicts");
        assert!(p.shap.expect("asked").local_accuracy_max_abs < 1e-12);
    }
}

/// Random mutations of a valid document: every answer is a typed 422 (invalid input) or finite.
#[test]
fn mutated_model_documents_never_panic_or_produce_nan() {
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let arrays = [
        "left",
        "right",
        "feature",
        "threshold",
        "value",
        "cover",
        "loss_change",
    ];
    let extremes = [
        json!(-1),
        json!(0),
        json!(1),
        json!(4),
        json!(-2),
        json!(2_147_483_647),
        json!(1e308),
        json!(-1e308),
        json!(1e-320),
        json!(0.5),
        json!("x"),
        json!(null),
    ];
    let (mut ok, mut rejected) = (0, 0);
    for _ in 0..stress_cases() {
        let mut m = native();
        for _ in 0..rng.random_range(1..4) {
            let t = rng.random_range(0..2usize);
            let a = arrays[rng.random_range(0..arrays.len())];
            let len = m["trees"][t][a].as_array().map_or(0, Vec::len);
            if len == 0 {
                continue;
            }
            let i = rng.random_range(0..len);
            m["trees"][t][a][i] = extremes[rng.random_range(0..extremes.len())].clone();
        }
        let body = json!({"model": m, "rows": [[0.3, 1.0], [0.9, 3.0]],
                          "shap": "path_dependent", "interactions": true});
        match predict(body.clone()) {
            Ok(_) => ok += 1,
            Err(e) => {
                assert_eq!(e.class, ProblemClass::InvalidInput, "{e}");
                assert!(e.errors[0].pointer.starts_with("/model"), "{e}");
                rejected += 1;
            }
        }
        let mut b = body;
        b["shap"] = json!("interventional");
        b["background"] = json!([[0.0, 0.0], [1.0, 9.0]]);
        b["interactions"] = json!(false);
        let _ = predict(b);
    }
    eprintln!("mutated documents: {ok} answered, {rejected} rejected");
    assert!(ok > 0 && rejected > 0);
}

/// The deadline of a SHAP answer (which is never partial) is a typed 422.
#[test]
fn spent_budget_is_typed() {
    let mut b = data(40, 5.0);
    b["params"]["n_estimators"] = json!(2000);
    b["params"]["colsample_bytree"] = json!(0.5);
    b["validation"] = json!({"test_fraction": 0.0});
    let t = train(b).expect("trains");
    let rows: Vec<Vec<f64>> = (0..1000)
        .map(|i| vec![(i % 5) as f64, (i % 3) as f64, 7.0])
        .collect();
    let req: PredictRequest = serde_json::from_value(json!({
        "model": t.model, "rows": rows, "shap": "interventional", "background": rows[..1000].to_vec()
    }))
    .expect("decodes");
    // 1 ms: the interventional SHAP here (2000 trees, 1000 rows, 1000 background rows) takes
    // about 20 ms on the 2-core CI machine, so the deadline falls inside it (a 20-ms deadline
    // was sometimes met).
    let budget = Budget::new(Duration::from_millis(1));
    let e = run_predict(req, &budget).expect_err("budget spent");
    assert_eq!(e.code, "DEADLINE_EXCEEDED");
    assert_eq!(e.class, ProblemClass::TooLarge);
}
