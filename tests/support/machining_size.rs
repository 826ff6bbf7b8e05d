//! Shared by the machining_size tests and bench: the committed XGBoost/shap fixtures
//! (`tests/fixtures/machining_size/`, made by its `generate.py`), brute-force Shapley values (the
//! independent check of TreeSHAP: 2^d coalitions, exact game values), and small builders.

use mechcalc::calc::machining_size::boost::{BoostParams, Boosted, SplitIndex, TrainData, boost};
use mechcalc::calc::machining_size::data::Matrix;
use mechcalc::calc::machining_size::model::{Model, Tree, cover_fraction};
use mechcalc::numerics::Budget;
use serde_json::Value;

/// A fixture file as JSON.
pub fn fixture(name: &str) -> Value {
    let path = format!(
        "{}/tests/fixtures/machining_size/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}")))
        .unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// A JSON array of numbers.
pub fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// A JSON array of arrays of numbers.
pub fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().expect("array").iter().map(nums).collect()
}

/// The paper-shaped data set of `data.json`: (names, rows, target, centred f32 target, train rows).
pub struct PaperData {
    pub names: Vec<String>,
    pub rows: Vec<Vec<f64>>,
    pub target: Vec<f64>,
    pub centred: Vec<f64>,
    pub train_rows: Vec<u32>,
}

pub fn paper_data() -> PaperData {
    let d = fixture("data.json");
    PaperData {
        names: d["feature_names"]
            .as_array()
            .expect("names")
            .iter()
            .map(|s| s.as_str().expect("name").to_owned())
            .collect(),
        rows: rows(&d["rows"]),
        target: nums(&d["target"]),
        centred: nums(&d["target_centred_f32"]),
        train_rows: d["train_rows"]
            .as_array()
            .expect("train rows")
            .iter()
            .map(|i| u32::try_from(i.as_u64().expect("index")).expect("u32"))
            .collect(),
    }
}

/// The paper's Table-2 parameters with colsample 1.0 (spec §7.2), base score 0 (centred target).
pub fn table2(n_estimators: usize) -> BoostParams {
    BoostParams {
        learning_rate: 0.05,
        reg_lambda: 0.1,
        reg_alpha: 0.05,
        base_score: Some(0.0),
        ..BoostParams::xgboost(n_estimators, 6)
    }
}

/// Trains `params` on `rows` of the matrix with targets `y` (every column a candidate).
pub fn train_on(
    x: &Matrix,
    y: &[f64],
    rows: &[u32],
    params: &BoostParams,
    threads: usize,
) -> Boosted {
    let features: Vec<usize> = (0..x.n_cols()).collect();
    let index = SplitIndex::build(params.method, x, rows, &features, threads);
    let data = TrainData {
        x,
        y,
        rows,
        features: &features,
        index: &index,
    };
    boost(&data, params, &Budget::unlimited(), threads)
}

/// E[tree | x_S] with the cover weighting of path-dependent TreeSHAP: follow x on features in S,
/// average the children by cover fraction otherwise.
fn cond_expectation(tree: &Tree, node: usize, x: &[f64], in_s: &[bool]) -> f64 {
    let n = &tree.nodes[node];
    if n.is_leaf() {
        return n.value;
    }
    let f = n.feature as usize;
    let (l, r) = (n.left as usize, n.right as usize);
    if in_s[f] {
        let c = if x[f] < n.threshold { l } else { r };
        cond_expectation(tree, c, x, in_s)
    } else {
        cover_fraction(tree.nodes[l].cover, n.cover) * cond_expectation(tree, l, x, in_s)
            + cover_fraction(tree.nodes[r].cover, n.cover) * cond_expectation(tree, r, x, in_s)
    }
}

/// Shapley values of the game `v` over `d` players by enumerating all 2^d coalitions.
pub fn shapley(d: usize, v: impl Fn(&[bool]) -> f64) -> Vec<f64> {
    let values: Vec<f64> = (0..1usize << d)
        .map(|mask| {
            let s: Vec<bool> = (0..d).map(|i| mask >> i & 1 == 1).collect();
            v(&s)
        })
        .collect();
    let fact = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
    let mut phi = vec![0.0; d];
    for (i, p) in phi.iter_mut().enumerate() {
        for mask in 0..1usize << d {
            if mask >> i & 1 == 1 {
                continue;
            }
            let s = mask.count_ones() as usize;
            let w = fact(s) * fact(d - s - 1) / fact(d);
            *p += w * (values[mask | 1 << i] - values[mask]);
        }
    }
    phi
}

/// Brute-force path-dependent SHAP values of a prepared row.
pub fn brute_path_dependent(model: &Model, x: &[f64]) -> Vec<f64> {
    shapley(model.n_features, |s| {
        model
            .trees
            .iter()
            .map(|t| cond_expectation(t, 0, x, s))
            .sum()
    })
}

/// Brute-force interventional SHAP values: v(S) = mean over the background of f(x_S, r_~S).
pub fn brute_interventional(model: &Model, x: &[f64], background: &[Vec<f64>]) -> Vec<f64> {
    shapley(model.n_features, |s| {
        background
            .iter()
            .map(|r| {
                let z: Vec<f64> = (0..x.len())
                    .map(|i| if s[i] { x[i] } else { r[i] })
                    .collect();
                model.predict_prepared(&z)
            })
            .sum::<f64>()
            / background.len() as f64
    })
}

/// Largest absolute difference of two equally long slices.
pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
