//! Benchmarks of `machining_size` (spec §9).
//!
//! Tables (printed before criterion, only under `cargo bench`; a name filter must contain
//! `sweep` to run them):
//! * training time against XGBoost 3.2.0 (same data, same parameters, exact, 2 threads): the
//!   paper-sized set (850 rows × 8 features, 400 trees);
//! * training at scale (`sweep_large`): 10⁴, 10⁵ and 2·10⁵ rows × 20, exact and hist, time per
//!   row and test RMSE against XGBoost's (same data, parameters and folds, 2 threads);
//! * the thread knob of the level search and the CV folds (1 vs 2 threads by size);
//! * the accuracy-vs-cost grid n_estimators × max_depth with fixed 5 folds: fit time and mean test
//!   RMSE against XGBoost's on the same folds;
//! * TreeSHAP time per row (path-dependent, interventional |B| ∈ {10, 100, 1000}, interactions)
//!   against shap's TreeExplainer on the same XGBoost model.
//!
//! The data sets are seeded and written to `target/machining_size_bench/` (raw little-endian
//! f64); `benches/machining_size_reference.py` (run from the virtualenv of
//! `tests/fixtures/machining_size/generate.py`) times XGBoost and shap on exactly those files and
//! writes `reference.json` there, which a second bench run reads. Without it the XGBoost columns
//! say "—".
#![allow(missing_docs)] // criterion macros generate undocumented items
#![allow(clippy::unwrap_used)] // benchmarks: a panic is the failure report

#[path = "support/mod.rs"]
mod support;

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use mechcalc::calc::machining_size::boost::{
    BoostParams, Boosted, Method, SplitIndex, TrainData, boost,
};
use mechcalc::calc::machining_size::data::{Matrix, all_rows, complement, metrics};
use mechcalc::calc::machining_size::doc_tree::Doc;
use mechcalc::calc::machining_size::document::{DocLimits, read_xgboost};
use mechcalc::calc::machining_size::model::Model;
use mechcalc::calc::machining_size::rng;
use mechcalc::calc::machining_size::shap::{
    InterventionalTables, InterventionalWeights, PathBuffer, ShapForest,
};
use mechcalc::calc::machining_size::{TrainRequest, run_train};
use mechcalc::numerics::Budget;
use serde_json::{Value, json};
use support::{Timing, time_for, time_runs};

fn dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/machining_size_bench");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A data set: row-major features, targets, and a fold id per row (5 folds).
struct Set {
    name: &'static str,
    n: usize,
    d: usize,
    rows: Vec<Vec<f64>>,
    y: Vec<f64>,
    fold: Vec<u8>,
}

impl Set {
    fn matrix(&self) -> Matrix {
        Matrix::from_rows(self.rows.clone(), self.d)
    }

    /// Writes `<name>.x.f64`, `<name>.y.f64` and `<name>.fold.u8` for the Python reference.
    fn dump(&self) {
        let x: Vec<u8> = self
            .rows
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let y: Vec<u8> = self.y.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(dir().join(format!("{}.x.f64", self.name)), x).unwrap();
        std::fs::write(dir().join(format!("{}.y.f64", self.name)), y).unwrap();
        std::fs::write(dir().join(format!("{}.fold.u8", self.name)), &self.fold).unwrap();
        std::fs::write(
            dir().join(format!("{}.json", self.name)),
            json!({"n": self.n, "d": self.d}).to_string(),
        )
        .unwrap();
    }
}

fn folds(n: usize) -> Vec<u8> {
    let mut r = rng::stream(11, 99);
    let perm = rng::permutation(&mut r, n);
    let mut f = vec![0u8; n];
    for (k, &i) in perm.iter().enumerate() {
        f[i as usize] = u8::try_from(k * 5 / n).unwrap();
    }
    f
}

/// Spec §7.5's generator: 850 rows, 5 varying factors on 4 levels and 3 constant ones, the size
/// rounded to 0.01 mm (centred here: the paper-shaped target minus 19.962).
fn paper_set() -> Set {
    let n = 850;
    let mut r = rng::stream(20_251_121, 7);
    let pick = |r: &mut rand_chacha::ChaCha8Rng, levels: [f64; 4]| levels[rng::index(r, 4)];
    let a_o = |v: f64| match v as i64 {
        50 => 0.016,
        60 => 0.009,
        70 => -0.011,
        _ => -0.014,
    };
    let a_w = |v: f64| match v as i64 {
        2 => 0.018,
        3 => -0.004,
        4 => -0.006,
        _ => -0.008,
    };
    let mut rows = Vec::with_capacity(n);
    let mut y = Vec::with_capacity(n);
    for _ in 0..n {
        let o = pick(&mut r, [50.0, 60.0, 70.0, 80.0]);
        let s = pick(&mut r, [3000.0, 4000.0, 5000.0, 6000.0]);
        let f = pick(&mut r, [300.0, 400.0, 500.0, 600.0]);
        let w = pick(&mut r, [2.0, 3.0, 4.0, 5.0]);
        let dp = pick(&mut r, [0.5, 1.0, 1.5, 2.0]);
        let v = 19.962 + a_o(o) + a_w(w) - 0.004 * (f - 450.0) / 150.0 - 0.003 * (dp - 1.25) / 0.75
            + 0.002 * (s - 4500.0) / 1500.0
            + if o >= 70.0 && w >= 4.0 { 0.002 } else { 0.0 }
            + 0.014 * rng::normal(&mut r);
        y.push(((v.clamp(19.90, 20.00) * 100.0).round() / 100.0) - 19.962);
        rows.push(vec![o, s, f, w, dp, 7.0, 1.0, 3.0]);
    }
    Set {
        name: "paper",
        n,
        d: 8,
        rows,
        y,
        fold: folds(n),
    }
}

/// `n` × 20 continuous features, a smooth nonlinear target with noise (the first rows of a
/// larger set are the rows of a smaller one).
fn big_set(name: &'static str, n: usize) -> Set {
    let d = 20;
    let mut r = rng::stream(77, 7);
    let mut rows = Vec::with_capacity(n);
    let mut y = Vec::with_capacity(n);
    for _ in 0..n {
        let x: Vec<f64> = (0..d).map(|_| rng::uniform(&mut r)).collect();
        let v = (std::f64::consts::TAU * x[0]).sin()
            + 2.0 * x[1] * x[2]
            + if x[3] > 0.5 { 1.0 } else { 0.0 }
            + 0.5 * x[4]
            - x[5] * x[5]
            + 0.1 * rng::normal(&mut r);
        rows.push(x);
        y.push(v);
    }
    Set {
        name,
        n,
        d,
        rows,
        y,
        fold: folds(n),
    }
}

fn table2(n_estimators: usize, colsample: f64) -> BoostParams {
    BoostParams {
        learning_rate: 0.05,
        reg_lambda: 0.1,
        reg_alpha: 0.05,
        colsample_bytree: colsample,
        ..BoostParams::xgboost(n_estimators, 6)
    }
}

/// Index build + boosting of `p` on `rows` of `x` with `threads`: what XGBoost's `train` does
/// after its DMatrix exists.
fn fit(x: &Matrix, y: &[f64], rows: &[u32], p: &BoostParams, threads: usize) -> Boosted {
    let features: Vec<usize> = (0..x.n_cols()).filter(|&f| !x.is_constant(f)).collect();
    let index = SplitIndex::build(p.method, x, rows, &features, threads);
    let data = TrainData {
        x,
        y,
        rows,
        features: &features,
        index: &index,
    };
    boost(
        &data,
        p,
        &Budget::unlimited().with_threads(threads),
        threads,
    )
}

fn reference() -> Option<Value> {
    let s = std::fs::read_to_string(dir().join("reference.json")).ok()?;
    serde_json::from_str(&s).ok()
}

fn refnum(r: Option<&Value>, path: &str) -> Option<f64> {
    r.and_then(|v| v.pointer(path)).and_then(Value::as_f64)
}

fn ms(t: &Timing) -> String {
    format!("{:.1} / {:.1}", t.median_ms(), t.worst_ms())
}

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or("—".to_owned(), |v| format!("{v:.digits$}"))
}

fn sweep_training(paper: &Set, reference: Option<&Value>) {
    println!("\n### Training time against XGBoost 3.2.0 (exact, same data and parameters)\n");
    println!(
        "| data set | parameters | threads | ours: index + boosting, median / worst ms | ours: whole `run_train` ms | XGBoost `train` median ms | XGBoost `fit` incl. DMatrix ms | ratio XGBoost/ours |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let x = paper.matrix();
    let rows = all_rows(paper.n);
    for (colsample, label) in [
        (1.0, "Table 2, colsample 1.0"),
        (0.8, "Table 2 (colsample 0.8)"),
    ] {
        for threads in [1usize, 2] {
            let p = table2(400, colsample);
            let (t, b) = time_for(Duration::from_secs(3), 30, || {
                fit(&x, &paper.y, &rows, &p, threads)
            });
            let req = paper_request(paper, colsample);
            let (tr, _) = time_runs(5, || {
                run_train(req.clone(), &Budget::unlimited().with_threads(threads)).unwrap()
            });
            let key = format!("/paper/colsample_{colsample}/threads_{threads}");
            let xt = refnum(reference, &format!("{key}/train_ms"));
            let xf = refnum(reference, &format!("{key}/fit_ms"));
            println!(
                "| paper-sized 850 × 8 | {label}, 400 trees ({} effective, digest {:016x}) | {threads} | {} | {:.1} | {} | {} | {} |",
                b.trees.iter().filter(|t| t.n_splits() > 0).count(),
                digest(&b),
                ms(&t),
                tr.median_ms(),
                opt(xt, 1),
                opt(xf, 1),
                opt(xt.map(|v| v / t.median_ms()), 2)
            );
        }
    }
}

/// A digest of every bit of a model's trees (node links, features, thresholds, values, covers,
/// loss changes): equal digests from two builds of the trainer mean byte-identical models.
fn digest(b: &Boosted) -> u64 {
    use std::hash::{DefaultHasher, Hash, Hasher};
    let mut h = DefaultHasher::new();
    b.base_score.to_bits().hash(&mut h);
    for n in b.trees.iter().flat_map(|t| t.nodes.iter()) {
        (n.left, n.right, n.feature).hash(&mut h);
        for v in [n.threshold, n.value, n.cover, n.loss_change] {
            v.to_bits().hash(&mut h);
        }
    }
    h.finish()
}

/// Training time and test RMSE at 10⁴, 10⁵ and 2·10⁵ rows × 20 continuous features against
/// XGBoost 3.2 (Table 2 with colsample 1.0, 400 trees, 2 threads each; no XGBoost exact at 2·10⁵):
/// index + boosting on all rows (median of 3 runs at 10⁴, one run above), and the test RMSE on
/// fold 0 of a model trained on folds 1–4. `hist_only` skips the exact rows.
fn sweep_large(sets: &[&Set], reference: Option<&Value>, hist_only: bool) {
    let load = || std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "\n### Training at scale against XGBoost 3.2.0 (Table 2, colsample 1.0, 400 trees, 2 threads)\n"
    );
    println!("load average at start: {}", load().trim());
    println!(
        "| rows × features | method | ours ms (all rows) | ours µs/row | XGBoost `train` ms | XGBoost µs/row | ratio XGBoost/ours | ours test RMSE (fold 0) | XGBoost test RMSE | RMSE ours/XGBoost − 1 | model digest (all rows) | trees built | ours µs per row and tree |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for s in sets {
        let x = s.matrix();
        let all = all_rows(s.n);
        let split = |test: bool| -> Vec<u32> {
            all.iter()
                .copied()
                .filter(|&r| (s.fold[r as usize] == 0) == test)
                .collect()
        };
        let (train, test) = (split(false), split(true));
        for (method, key) in [
            (Method::Exact, "exact"),
            (Method::Hist { max_bin: 256 }, "hist"),
        ] {
            if method == Method::Exact && hist_only {
                continue;
            }
            let p = BoostParams {
                method,
                ..table2(400, 1.0)
            };
            let runs = if s.n <= 10_000 { 3 } else { 1 };
            let (t, full) = time_runs(runs, || fit(&x, &s.y, &all, &p, 2));
            let m = fit(&x, &s.y, &train, &p, 2).into_model(s.d, Vec::new());
            let pred: Vec<f64> = test
                .iter()
                .map(|&r| m.predict_prepared(&x.row(r as usize)))
                .collect();
            let yt: Vec<f64> = test.iter().map(|&r| s.y[r as usize]).collect();
            let rmse = metrics(&pred, &yt).rmse;
            let k = format!("/large/{}/{key}", s.name);
            let xt = refnum(reference, &format!("{k}/train_ms"));
            let xr = refnum(reference, &format!("{k}/rmse"));
            let per_row = |ms: f64| ms * 1e3 / s.n as f64;
            println!(
                "| {} × {} | {key} | {:.0} | {:.1} | {} | {} | {} | {rmse:.6} | {} | {} | {:016x} | {} | {:.3} |",
                s.n,
                s.d,
                t.median_ms(),
                per_row(t.median_ms()),
                opt(xt, 0),
                opt(xt.map(per_row), 1),
                opt(xt.map(|v| v / t.median_ms()), 2),
                opt(xr, 6),
                xr.map_or("—".to_owned(), |v| format!(
                    "{:+.2} %",
                    (rmse / v - 1.0) * 100.0
                )),
                digest(&full),
                full.trees.len(),
                per_row(t.median_ms()) / full.trees.len().max(1) as f64,
            );
        }
    }
    println!("\nload average at end: {}", load().trim());
}

fn paper_request(paper: &Set, colsample: f64) -> TrainRequest {
    serde_json::from_value(json!({
        "feature_names": (0..paper.d).map(|i| format!("f{i}")).collect::<Vec<_>>(),
        "rows": paper.rows, "target": paper.y,
        "params": {"colsample_bytree": colsample},
        "validation": {"test_fraction": 0.0}, "outputs": []
    }))
    .unwrap()
}

/// The thread knob: one level search in parallel pays above ~60 000 scanned cells per level.
fn sweep_threads(paper: &Set, big: &Set) {
    println!("\n### Threads of the split search (exact, depth 6, 20 trees, colsample 1.0)\n");
    println!("| data set | cells per level | 1 thread ms | 2 threads ms | speed-up |");
    println!("|---|---|---|---|---|");
    let sub = |n: usize, d: usize| Set {
        name: "sub",
        n,
        d,
        rows: big.rows[..n].iter().map(|r| r[..d].to_vec()).collect(),
        y: big.y[..n].to_vec(),
        fold: Vec::new(),
    };
    let paper_sub = Set {
        name: "paper",
        n: paper.n,
        d: paper.d,
        rows: paper.rows.clone(),
        y: paper.y.clone(),
        fold: Vec::new(),
    };
    for s in [
        paper_sub,
        sub(2000, 10),
        sub(5000, 12),
        sub(10_000, 20),
        sub(100_000, 20),
    ] {
        let x = s.matrix();
        let rows = all_rows(s.n);
        let p = BoostParams {
            reg_alpha: 0.0,
            ..table2(20, 1.0)
        };
        let runs = if s.n > 50_000 { 2 } else { 5 };
        let (t1, _) = time_runs(runs, || fit(&x, &s.y, &rows, &p, 1));
        let (t2, _) = time_runs(runs, || fit(&x, &s.y, &rows, &p, 2));
        println!(
            "| {} × {} | {} | {:.2} | {:.2} | {:.2} |",
            s.n,
            s.d,
            s.n * s.d,
            t1.median_ms(),
            t2.median_ms(),
            t1.median_ms() / t2.median_ms()
        );
    }
}

/// Spec §9 grid: n_estimators × max_depth with the 5 fixed folds: fit time per fold and mean
/// test RMSE, against XGBoost exact on the same folds (colsample = subsample = 1).
fn sweep_grid(paper: &Set, reference: Option<&Value>) {
    println!(
        "\n### Accuracy vs cost: n_estimators × max_depth, 5 fixed folds (paper-sized set, exact, colsample 1)\n"
    );
    println!(
        "| n_estimators | max_depth | fit ms per fold (median / worst) | effective trees (fold 0) | mean test RMSE | XGBoost RMSE | |Δ RMSE| |"
    );
    println!("|---|---|---|---|---|---|---|");
    let x = paper.matrix();
    let n = paper.n;
    for &depth in &[2usize, 4, 6, 8] {
        for &trees in &[25usize, 50, 100, 200, 400, 800] {
            let p = BoostParams {
                max_depth: depth,
                ..table2(trees, 1.0)
            };
            let mut rmse = Vec::new();
            let mut times = Vec::new();
            let mut effective = 0;
            for k in 0..5u8 {
                let test: Vec<u32> = (0..n)
                    .filter(|&i| paper.fold[i] == k)
                    .map(|i| u32::try_from(i).unwrap())
                    .collect();
                let train = complement(n, &test);
                let (t, b) = time_runs(3, || fit(&x, &paper.y, &train, &p, 1));
                times.push(t);
                if k == 0 {
                    effective = b.trees.iter().filter(|t| t.n_splits() > 0).count();
                }
                let m = b.into_model(paper.d, Vec::new());
                let pred: Vec<f64> = test
                    .iter()
                    .map(|&r| m.predict_prepared(&x.row(r as usize)))
                    .collect();
                let y: Vec<f64> = test.iter().map(|&r| paper.y[r as usize]).collect();
                rmse.push(metrics(&pred, &y).rmse);
            }
            let mean = rmse.iter().sum::<f64>() / 5.0;
            times.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
            let worst = times.iter().map(|t| t.worst_ms()).fold(0.0, f64::max);
            let xr = refnum(reference, &format!("/grid/{trees}_{depth}/rmse"));
            let mark = if trees == 400 && depth == 6 {
                " **(default)**"
            } else {
                ""
            };
            println!(
                "| {trees}{mark} | {depth} | {:.2} / {worst:.2} | {effective} | {mean:.6} | {} | {} |",
                times[2].median_ms(),
                opt(xr, 6),
                xr.map_or("—".to_owned(), |v| format!("{:.1e}", (v - mean).abs()))
            );
        }
    }
}

/// TreeSHAP time per row against shap's TreeExplainer on the same XGBoost model.
#[expect(
    clippy::too_many_lines,
    reason = "prints the TreeSHAP timing table of benches/RESULTS.md, one row per model and method, against the shap and XGBoost reference timings"
)]
fn sweep_shap(paper: &Set, reference: Option<&Value>) {
    println!("\n### TreeSHAP time per row (1 thread) against shap 0.51 / XGBoost 3.2.0\n");
    println!(
        "| model | leaves | method | ours µs/row (median / worst) | shap µs/row | XGBoost pred_contribs µs/row (1 thread) | ratio shap/ours |"
    );
    println!("|---|---|---|---|---|---|---|");
    let x = paper.matrix();
    let rows: Vec<Vec<f64>> = (0..paper.n).map(|r| x.row(r)).collect();
    let mut models: Vec<(String, Model, &str)> = Vec::new();
    if let Ok(s) = std::fs::read_to_string(dir().join("paper_xgb_model.json")) {
        let v: Doc = serde_json::from_str(&s).unwrap();
        let limits = DocLimits {
            max_trees: 5000,
            max_features: 200,
        };
        models.push((
            "XGBoost 400 trees, depth 6 (imported)".to_owned(),
            read_xgboost(&v, "", limits).unwrap(),
            "/shap/xgb400",
        ));
    }
    for depth in [4usize, 6, 8] {
        let p = BoostParams {
            max_depth: depth,
            reg_alpha: 0.0,
            ..table2(400, 1.0)
        };
        let m = fit(&x, &paper.y, &all_rows(paper.n), &p, 2).into_model(paper.d, Vec::new());
        models.push((format!("ours 400 trees, depth {depth}, α 0"), m, ""));
    }
    for (label, m, key) in &models {
        let prepared: Vec<Vec<f64>> = rows.iter().map(|r| m.prepare_row(r)).collect();
        let leaves = m.n_leaves();
        let mut buf = PathBuffer::for_depth(m.max_depth());
        // The layout is built per request: inside the timed loop.
        let (t, _) = time_for(Duration::from_secs(2), 20, || {
            let forest = ShapForest::new(m);
            let mut acc = 0.0;
            for r in &prepared {
                let mut phi = vec![0.0; m.n_features];
                forest.path_dependent(r, &mut phi, &mut buf);
                acc += phi[0];
            }
            black_box(acc)
        });
        let per = |t: &Timing, rows: usize| {
            format!(
                "{:.1} / {:.1}",
                t.median_us() / rows as f64,
                t.worst_us() / rows as f64
            )
        };
        let ours = t.median_us() / prepared.len() as f64;
        let shap_pd = refnum(reference, &format!("{key}/path_dependent_us"));
        if let Some(v) = refnum(reference, &format!("{key}/path_dependent_no_additivity_us"))
            && !key.is_empty()
        {
            println!(
                "| {label} | {leaves} | (shap path-dependent without its additivity check) | — | {v:.1} | — | {:.2} |",
                v / ours
            );
        }
        let xgb_pd = refnum(reference, &format!("{key}/pred_contribs_us_1t"));
        println!(
            "| {label} | {leaves} | path-dependent | {} | {} | {} | {} |",
            per(&t, prepared.len()),
            opt(if key.is_empty() { None } else { shap_pd }, 1),
            opt(if key.is_empty() { None } else { xgb_pd }, 1),
            opt(
                if key.is_empty() {
                    None
                } else {
                    shap_pd.map(|s| s / ours)
                },
                2
            )
        );
        for nb in [10usize, 100, 1000] {
            let bg: Vec<Vec<f64>> = prepared
                .iter()
                .step_by(paper.n / nb.min(paper.n))
                .take(nb)
                .cloned()
                .collect();
            // As many rows as the shap reference explains; the tables (built once per request)
            // are inside the timed loop and their build is also timed alone.
            let nrows = if nb >= 1000 { 5 } else { 40 };
            let wt = InterventionalWeights::new(m.max_depth());
            let unlimited = Budget::unlimited();
            let (tb, _) = time_runs(3, || {
                black_box(InterventionalTables::new(m, &bg, &wt, &unlimited).unwrap());
            });
            let (t, _) = time_runs(5, || {
                let tables = InterventionalTables::new(m, &bg, &wt, &unlimited).unwrap();
                let mut acc = 0.0;
                for r in &prepared[..nrows] {
                    let mut phi = vec![0.0; m.n_features];
                    tables.shap(r, &mut phi);
                    acc += phi[0];
                }
                black_box(acc)
            });
            let ours = t.median_us() / nrows as f64;
            let s = refnum(reference, &format!("{key}/interventional_{nb}_us"));
            let s = if key.is_empty() { None } else { s };
            let asked = if bg.len() == nb {
                String::new()
            } else {
                format!(" ({nb} asked, the set has {})", bg.len())
            };
            println!(
                "| {label} | {leaves} | interventional, |B| = {}{asked}, {nrows} rows, tables {:.2} ms | {} | {} | — | {} |",
                bg.len(),
                tb.median_ms(),
                per(&t, nrows),
                opt(s, 1),
                opt(s.map(|v| v / ours), 2)
            );
            if let Some(c) = refnum(reference, &format!("{key}/interventional_{nb}_capped_us"))
                && !key.is_empty()
            {
                let rows = refnum(
                    reference,
                    &format!("{key}/interventional_{nb}_capped_background_rows"),
                )
                .unwrap_or(f64::NAN);
                println!(
                    "| {label} | {leaves} | (shap's default `data=` masker, subsampled to {rows} rows) | — | {c:.1} | — | — |"
                );
            }
        }
        let d = m.n_features;
        let mut scratch = [vec![0.0; d], vec![0.0; d]];
        let (t, _) = time_runs(3, || {
            let forest = ShapForest::new(m);
            let mut acc = 0.0;
            for r in &prepared[..40] {
                let mut phi = vec![0.0; d];
                let mut out = vec![0.0; d * d];
                forest.interactions(r, &mut phi, &mut out, &mut buf, &mut scratch);
                acc += out[0];
            }
            black_box(acc)
        });
        let ours = t.median_us() / 40.0;
        let s = refnum(reference, &format!("{key}/interactions_us"));
        let s = if key.is_empty() { None } else { s };
        println!(
            "| {label} | {leaves} | interactions | {} | {} | — | {} |",
            per(&t, 40),
            opt(s, 1),
            opt(s.map(|v| v / ours), 2)
        );
    }
}

fn sweeps(_: &mut Criterion) {
    let Some(filters) = support::sweep_filters("sweep") else {
        return;
    };
    let paper = paper_set();
    paper.dump();
    let big = big_set("big", 100_000);
    big.dump();
    let (big10k, big200k) = (big_set("big10k", 10_000), big_set("big200k", 200_000));
    big10k.dump();
    big200k.dump();
    let reference = reference();
    if reference.is_none() {
        println!(
            "(no target/machining_size_bench/reference.json: run benches/machining_size_reference.py \
             for the XGBoost and shap columns)"
        );
    }
    println!("\n## machining_size sweeps (bench profile)");
    let want = |name: &str| filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()));
    if want("sweep_train") {
        sweep_training(&paper, reference.as_ref());
    }
    // `sweep_large_hist` runs the hist rows of `sweep_large` only.
    let hist_only = filters.iter().any(|f| f.contains("sweep_large_hist"));
    if want("sweep_large") || hist_only {
        sweep_large(&[&big10k, &big, &big200k], reference.as_ref(), hist_only);
    }
    if want("sweep_threads") {
        sweep_threads(&paper, &big);
    }
    if want("sweep_grid") {
        sweep_grid(&paper, reference.as_ref());
    }
    if want("sweep_shap") {
        sweep_shap(&paper, reference.as_ref());
    }
}

fn bench_core(c: &mut Criterion) {
    let paper = paper_set();
    let x = paper.matrix();
    let rows = all_rows(paper.n);
    let p = table2(400, 0.8);
    c.bench_function(
        "machining_size/train paper-sized 400 trees (2 threads)",
        |b| {
            b.iter(|| fit(&x, &paper.y, &rows, &p, 2));
        },
    );
    let m = fit(&x, &paper.y, &rows, &table2(400, 1.0), 2).into_model(paper.d, Vec::new());
    let row = x.row(3);
    let mut buf = PathBuffer::for_depth(m.max_depth());
    let forest = ShapForest::new(&m);
    c.bench_function("machining_size/path-dependent SHAP, one row", |b| {
        b.iter(|| {
            let mut phi = vec![0.0; m.n_features];
            forest.path_dependent(black_box(&row), &mut phi, &mut buf);
            phi
        });
    });
    c.bench_function("machining_size/predict, one row", |b| {
        b.iter(|| m.predict_prepared(black_box(&row)));
    });
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = sweeps, bench_core
}
criterion_main!(benches);
