//! machining_size: the spec's validation cases (§7) at its tolerances, against real XGBoost 3.2.0
//! and shap 0.51.0 (committed fixtures from `tests/fixtures/machining_size/generate.py`), and
//! brute-force Shapley values as the independent check of TreeSHAP.

use mechcalc::calc::machining_size::boost::{BoostParams, Method};
use mechcalc::calc::machining_size::data::{Matrix, all_rows};
use mechcalc::calc::machining_size::doc_tree::Doc;
use mechcalc::calc::machining_size::document::{DocLimits, read_xgboost};
use mechcalc::calc::machining_size::model::Model;
use mechcalc::calc::machining_size::shap::{
    InterventionalWeights, PathBuffer, interactions, interventional, path_dependent,
};

use crate::support::machining_size::{
    brute_interventional, brute_path_dependent, fixture, max_abs_diff, nums, paper_data, rows,
    table2, train_on,
};

/// Spec §7.1: x = [1, 2, 3, 4], y = [1, 2, 3, 10], one feature, exact method.
fn tiny(params: &BoostParams) -> Model {
    let x = Matrix::from_rows(vec![vec![1.0], vec![2.0], vec![3.0], vec![4.0]], 1);
    let y = [1.0, 2.0, 3.0, 10.0];
    train_on(&x, &y, &all_rows(4), params, 1).into_model(1, Vec::new())
}

fn t1() -> BoostParams {
    BoostParams {
        learning_rate: 1.0,
        ..BoostParams::xgboost(1, 1)
    }
}

fn shap_of(m: &Model, x: f64) -> f64 {
    let mut phi = [0.0];
    path_dependent(m, &[x], &mut phi, &mut PathBuffer::for_depth(m.max_depth()));
    phi[0]
}

/// A row of the spec's §7.1 table: case, parameters, predictions, φ_1 per row, φ_0.
type TinyCase = (&'static str, BoostParams, [f64; 4], [f64; 4], f64);

/// Spec §7.1 table: (case, params, predictions, φ_1 per row, φ_0). Printed to 10 decimals:
/// tolerance 5e-11.
#[test]
fn spec_7_1_tiny_hand_checkable_cases() {
    let t2 = BoostParams {
        n_estimators: 2,
        max_depth: 2,
        learning_rate: 0.5,
        reg_lambda: 0.5,
        reg_alpha: 0.5,
        gamma: 3.0,
        ..t1()
    };
    let cases: [TinyCase; 4] = [
        (
            "T1",
            t1(),
            [2.5, 2.5, 2.5, 7.0],
            [-1.125, -1.125, -1.125, 3.375],
            3.625,
        ),
        (
            "T2",
            t2,
            [
                2.765_306_122_4,
                2.765_306_122_4,
                2.765_306_122_4,
                7.055_555_555_6,
            ],
            [
                -1.072_562_358_3,
                -1.072_562_358_3,
                -1.072_562_358_3,
                3.217_687_074_8,
            ],
            3.837_868_480_7,
        ),
        (
            "T3",
            BoostParams {
                gamma: 26.9,
                ..t1()
            },
            [2.5, 2.5, 2.5, 7.0],
            [-1.125, -1.125, -1.125, 3.375],
            3.625,
        ),
        (
            "T3'",
            BoostParams {
                gamma: 27.1,
                ..t1()
            },
            [4.0; 4],
            [0.0; 4],
            4.0,
        ),
    ];
    for (name, params, pred, phi, phi0) in cases {
        let m = tiny(&params);
        for (i, x) in [1.0, 2.0, 3.0, 4.0].into_iter().enumerate() {
            let p = m.predict_prepared(&[x]);
            assert!(
                (p - pred[i]).abs() < 5e-11,
                "{name} prediction {i}: {p} vs {}",
                pred[i]
            );
            let s = shap_of(&m, x);
            assert!(
                (s - phi[i]).abs() < 5e-11,
                "{name} φ {i}: {s} vs {}",
                phi[i]
            );
        }
        let e = m.expected_value();
        assert!((e - phi0).abs() < 5e-11, "{name} φ0: {e} vs {phi0}");
    }
    // T1's hand check: split at 3.5 with loss change 27 (g = [3, 2, 1, −6]).
    let m = tiny(&t1());
    let root = m.trees[0].nodes[0];
    assert_eq!((root.threshold, root.loss_change), (3.5, 27.0));
}

/// The centred-target training of the paper-shaped set (spec §7.2).
fn paper_training(method: Method, n: usize) -> (Model, Matrix, Vec<f64>) {
    let d = paper_data();
    let x = Matrix::from_rows(d.rows.clone(), d.names.len());
    let params = BoostParams {
        method,
        ..table2(n)
    };
    let b = train_on(&x, &d.centred, &d.train_rows, &params, 1);
    (b.into_model(d.names.len(), Vec::new()), x, d.centred)
}

fn case(name: &str) -> serde_json::Value {
    let t = fixture("training.json");
    t["cases"]
        .as_array()
        .expect("cases")
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("case {name}"))
        .clone()
}

fn predictions(m: &Model, x: &Matrix) -> Vec<f64> {
    (0..x.n_rows())
        .map(|r| m.predict_prepared(&x.row(r)))
        .collect()
}

/// Spec §7.2: exact training on the centred target agrees with XGBoost 3.2.0 exact to its f32
/// precision (spec: 7.1e-9 max; tolerance 1e-7, a tenth of one f32 ulp of the 0.01 mm residuals'
/// sum scale), with the same number of trees that split.
#[test]
fn spec_7_2_exact_parity_with_xgboost() {
    let (m, x, _) = paper_training(Method::Exact, 400);
    let c = case("exact_table2_colsample1");
    let ours = predictions(&m, &x);
    let diff = max_abs_diff(&ours, &nums(&c["predictions"]));
    eprintln!("exact vs xgboost: max |Δprediction| = {diff:e}");
    assert!(diff < 1e-7, "max |Δ| = {diff:e}");
    assert_eq!(
        m.effective_trees() as u64,
        c["effective_trees"].as_u64().expect("count")
    );
}

/// Spec §7.2: hist = exact on these discrete features (same partitions, 0 difference on the
/// training rows) and hist agrees with XGBoost's hist.
#[test]
fn spec_7_2_hist_equals_exact_and_xgboost_hist() {
    let d = paper_data();
    let (exact, x, _) = paper_training(Method::Exact, 400);
    let (hist, _, _) = paper_training(Method::Hist { max_bin: 256 }, 400);
    let train: Vec<f64> = d
        .train_rows
        .iter()
        .map(|&r| {
            hist.predict_prepared(&x.row(r as usize)) - exact.predict_prepared(&x.row(r as usize))
        })
        .collect();
    let worst = train.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(worst < 1e-15, "hist vs exact on training rows: {worst:e}");
    let c = case("hist_table2_colsample1");
    let diff = max_abs_diff(&predictions(&hist, &x), &nums(&c["predictions"]));
    eprintln!("hist vs xgboost hist: max |Δprediction| = {diff:e}");
    assert!(diff < 1e-7, "max |Δ| = {diff:e}");
}

/// γ pruning with XGBoost's un-halved comparison on a real data set.
#[test]
fn gamma_pruning_matches_xgboost() {
    let d = paper_data();
    let x = Matrix::from_rows(d.rows.clone(), d.names.len());
    let params = BoostParams {
        max_depth: 3,
        learning_rate: 0.3,
        reg_alpha: 0.0,
        reg_lambda: 1.0,
        gamma: 2e-3,
        ..table2(60)
    };
    let m =
        train_on(&x, &d.centred, &d.train_rows, &params, 1).into_model(d.names.len(), Vec::new());
    let c = case("exact_depth3_gamma");
    let diff = max_abs_diff(&predictions(&m, &x), &nums(&c["predictions"]));
    eprintln!("gamma case vs xgboost: max |Δprediction| = {diff:e}");
    assert!(diff < 1e-7, "max |Δ| = {diff:e}");
    assert_eq!(
        m.effective_trees() as u64,
        c["effective_trees"].as_u64().expect("n")
    );
}

/// Spec §7.3: SHAP of our 400-tree model equals XGBoost's pred_contribs of its own model (the two
/// models agree to 1e-7 above, so the SHAP values agree to the same order) and brute-force
/// enumeration of the cover-weighted game (5e-18 in the spec; tolerance 1e-12).
#[test]
fn spec_7_3_shap_of_the_trained_model() {
    let (m, x, _) = paper_training(Method::Exact, 400);
    let c = case("exact_table2_colsample1");
    let idx: Vec<usize> = c["contrib_rows"]
        .as_array()
        .expect("rows")
        .iter()
        .map(|v| usize::try_from(v.as_u64().expect("i")).expect("usize"))
        .collect();
    let contribs = rows(&c["pred_contribs"]);
    let mut buf = PathBuffer::for_depth(m.max_depth());
    let (mut worst_xgb, mut worst_brute, mut worst_local) = (0.0f64, 0.0f64, 0.0f64);
    for (k, &r) in idx.iter().enumerate() {
        let row = x.row(r);
        let mut phi = vec![0.0; m.n_features];
        path_dependent(&m, &row, &mut phi, &mut buf);
        let d = contribs[k].len() - 1;
        worst_xgb = worst_xgb.max(max_abs_diff(&phi, &contribs[k][..d]));
        let local = m.expected_value() + phi.iter().sum::<f64>() - m.predict_prepared(&row);
        worst_local = worst_local.max(local.abs());
        if k < 5 {
            worst_brute = worst_brute.max(max_abs_diff(&phi, &brute_path_dependent(&m, &row)));
        }
    }
    eprintln!(
        "SHAP vs xgboost pred_contribs {worst_xgb:e}, vs brute force {worst_brute:e}, local \
         accuracy {worst_local:e}"
    );
    assert!(worst_xgb < 1e-7, "{worst_xgb:e}");
    assert!(worst_brute < 1e-12, "{worst_brute:e}");
    assert!(worst_local < 1e-13, "{worst_local:e}");
}

fn imported() -> (Model, serde_json::Value) {
    let s = fixture("shap_model.json");
    let limits = DocLimits {
        max_trees: 5000,
        max_features: 200,
    };
    let doc = <Doc as serde::Deserialize>::deserialize(&s["xgboost_json"]).expect("a JSON tree");
    let m = read_xgboost(&doc, "/model/xgboost_json", limits).expect("reads");
    (m, s)
}

/// An imported XGBoost model predicts as xgboost does (f32 routing; the sums differ by xgboost's
/// f32 accumulation only: rel 1e-6).
#[test]
fn imported_xgboost_model_predicts_as_xgboost() {
    let (m, s) = imported();
    let expected = nums(&s["predictions"]);
    for (r, e) in rows(&s["rows"]).iter().zip(expected) {
        let p = m.predict_prepared(&m.prepare_row(r));
        assert!((p - e).abs() <= 1e-6 * e.abs(), "{p} vs {e}");
    }
}

/// Spec §7.3 on an imported model: path-dependent SHAP = xgboost pred_contribs = shap
/// TreeExplainer (≤ 1e-6, spec §9); interventional = shap interventional (≤ 1e-6); interaction
/// values = shap and xgboost (≤ 1e-6); local accuracy in f64; brute force for both games.
#[test]
fn spec_7_3_shap_of_an_imported_model() {
    let (m, s) = imported();
    let x: Vec<Vec<f64>> = rows(&s["rows"]).iter().map(|r| m.prepare_row(r)).collect();
    let bg: Vec<Vec<f64>> = rows(&s["background"])
        .iter()
        .map(|r| m.prepare_row(r))
        .collect();
    let contribs = rows(&s["pred_contribs"]);
    let shap_pd = rows(&s["shap_values"]);
    let shap_iv = rows(&s["shap_interventional_values"]);
    let d = m.n_features;
    let mut buf = PathBuffer::for_depth(m.max_depth());
    let wt = InterventionalWeights::new(m.max_depth());
    let phi0_bg = bg.iter().map(|r| m.predict_prepared(r)).sum::<f64>() / bg.len() as f64;
    let ev = s["shap_expected_value"].as_f64().expect("ev");
    assert!(
        (m.expected_value() - ev).abs() < 1e-5,
        "{} vs {ev}",
        m.expected_value()
    );
    let ev_iv = s["shap_interventional_expected_value"]
        .as_f64()
        .expect("ev");
    assert!((phi0_bg - ev_iv).abs() < 1e-5, "{phi0_bg} vs {ev_iv}");
    let mut worst = [0.0f64; 6];
    for (k, row) in x.iter().enumerate() {
        let mut phi = vec![0.0; d];
        path_dependent(&m, row, &mut phi, &mut buf);
        worst[0] = worst[0].max(max_abs_diff(&phi, &contribs[k][..d]));
        worst[1] = worst[1].max(max_abs_diff(&phi, &shap_pd[k]));
        let f = m.predict_prepared(row);
        worst[2] = worst[2].max((m.expected_value() + phi.iter().sum::<f64>() - f).abs());
        let mut iv = vec![0.0; d];
        interventional(&m, row, &bg, &wt, &mut iv);
        worst[3] = worst[3].max(max_abs_diff(&iv, &shap_iv[k]));
        worst[4] = worst[4].max((phi0_bg + iv.iter().sum::<f64>() - f).abs());
        if k < 3 {
            worst[5] = worst[5]
                .max(max_abs_diff(&phi, &brute_path_dependent(&m, row)))
                .max(max_abs_diff(&iv, &brute_interventional(&m, row, &bg)));
        }
    }
    eprintln!(
        "imported: vs pred_contribs {:e}, vs shap {:e}, local {:e}, interventional vs shap {:e}, \
         local {:e}, vs brute force {:e}",
        worst[0], worst[1], worst[2], worst[3], worst[4], worst[5]
    );
    assert!(
        worst[0] < 1e-6 && worst[1] < 1e-6 && worst[3] < 1e-6,
        "{worst:?}"
    );
    assert!(
        worst[2] < 1e-12 && worst[4] < 1e-12 && worst[5] < 1e-12,
        "{worst:?}"
    );
    // Interaction values: shap's d × d and xgboost's (d+1) × (d+1) with the bias last.
    let shap_int = s["shap_interaction_values"].as_array().expect("array");
    let xgb_int = s["pred_interactions"].as_array().expect("array");
    let mut scratch = [vec![0.0; d], vec![0.0; d]];
    let (mut w_shap, mut w_xgb) = (0.0f64, 0.0f64);
    for (k, (si, xi)) in shap_int.iter().zip(xgb_int).enumerate() {
        let mut phi = vec![0.0; d];
        let mut out = vec![0.0; d * d];
        interactions(&m, &x[k], &mut phi, &mut out, &mut buf, &mut scratch);
        let (si, xi) = (rows(si), rows(xi));
        for i in 0..d {
            w_shap = w_shap.max(max_abs_diff(&out[i * d..(i + 1) * d], &si[i]));
            w_xgb = w_xgb.max(max_abs_diff(&out[i * d..(i + 1) * d], &xi[i][..d]));
        }
    }
    eprintln!("interactions vs shap {w_shap:e}, vs xgboost {w_xgb:e}");
    assert!(w_shap < 1e-6 && w_xgb < 1e-6, "{w_shap:e} {w_xgb:e}");
}
