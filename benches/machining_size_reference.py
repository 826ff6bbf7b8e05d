#!/usr/bin/env python3
"""XGBoost and shap reference timings for `benches/machining_size.rs` (same data, same parameters).

Pinned: xgboost==3.2.0, shap==0.51.0 (the virtualenv of tests/fixtures/machining_size/generate.py).
Run `cargo bench --bench machining_size sweep` once (it writes the data sets to
target/machining_size_bench/), then

    /tmp/venv-ms/bin/python benches/machining_size_reference.py

which writes target/machining_size_bench/reference.json and paper_xgb_model.json; the next
bench run prints the XGBoost/shap columns from it. Not run in CI.

`--shap-only` re-times only the SHAP part and keeps the rest of an existing reference.json;
`--large-only` re-times only the scaling rows (`sweep_large`: 10^4, 10^5, 2*10^5 rows x 20, exact
and hist, train time on all rows and test RMSE on fold 0 after training on folds 1-4).

Timings: `xgb.train` on a prebuilt DMatrix (tree_method exact, nthread 1 or 2) and the
scikit-learn-style fit including the DMatrix; median of repeated runs (1 run on 100 000 × 20).
SHAP, all with one thread: shap.TreeExplainer(booster) (path-dependent; shap hands the work to
the booster's own C++ `predict(pred_contribs=True)`, which runs with the booster's `nthread`, so
the booster is set to nthread 1), interventional with a background of |B| rows (shap's own C++,
single-threaded), interaction values (again the booster's `pred_interactions`); XGBoost
pred_contribs with nthread 1. Microseconds per explained row.

Background size: `TreeExplainer(model, data=array)` wraps the array in
`shap.maskers.Independent(data)`, whose `max_samples=100` default subsamples any larger background
to 100 rows (shap 0.51.0 shap/maskers/_tabular.py `Tabular.__init__`: `if data.shape[0] >
max_samples: data = utils.sample(data, max_samples)`; shap/explainers/_explainer.py wraps the
array; shap/explainers/_tree.py then uses `self.masker.data`). So `data=bg` with |B| = 1000
explains against 100 rows. The like-for-like timing passes
`maskers.Independent(bg, max_samples=len(bg))` (key `interventional_<B>_us`); the default,
capped call is kept as `interventional_<B>_capped_us`.
"""

import json
import os
import statistics
import sys
import time

import numpy as np
import shap
import xgboost as xgb

if xgb.__version__ != "3.2.0" or shap.__version__ != "0.51.0":
    sys.exit(f"pinned xgboost 3.2.0 / shap 0.51.0, found {xgb.__version__} / {shap.__version__}")

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
DIR = os.path.join(ROOT, "target", "machining_size_bench")


def load(name):
    meta = json.load(open(os.path.join(DIR, f"{name}.json")))
    n, d = meta["n"], meta["d"]
    x = np.fromfile(os.path.join(DIR, f"{name}.x.f64"), dtype="<f8").reshape(n, d)
    y = np.fromfile(os.path.join(DIR, f"{name}.y.f64"), dtype="<f8")
    fold = np.fromfile(os.path.join(DIR, f"{name}.fold.u8"), dtype=np.uint8)
    return x, y, fold


def table2(**kw):
    p = {"objective": "reg:squarederror", "tree_method": "exact", "max_depth": 6, "eta": 0.05,
         "lambda": 0.1, "alpha": 0.05, "gamma": 0.0, "min_child_weight": 1.0,
         "colsample_bytree": 1.0, "subsample": 1.0, "seed": 0, "nthread": 2}
    p.update(kw)
    return p


def timed(f, runs):
    f()  # warm-up
    ts = []
    for _ in range(runs):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts) * 1e3, max(ts) * 1e3


def main():
    shap_only = "--shap-only" in sys.argv[1:]
    if "--large-only" in sys.argv[1:]:
        # Re-times only the bench's `sweep_large` rows; keeps the rest of reference.json.
        out = os.path.join(DIR, "reference.json")
        ref = json.load(open(out)) if os.path.exists(out) else {}
        large_reference(ref)
        json.dump(ref, open(out, "w"), indent=1)
        print("written", out)
        return
    out = os.path.join(DIR, "reference.json")
    ref = {"xgboost": xgb.__version__, "shap": shap.__version__, "paper": {}, "big": {},
           "grid": {}, "shap": {}}
    if shap_only:
        ref = json.load(open(out))
    x, y, fold = load("paper")
    # Drop the constant columns as the bench does (trees never split on them anyway).
    keep = [j for j in range(x.shape[1]) if np.ptp(x[:, j]) > 0]
    xk = x[:, keep]
    dtrain = xgb.DMatrix(xk, label=y)
    if not shap_only:
        train_reference(ref, x, y, fold, xk, dtrain)
    shap_reference(ref, x, y, keep, xk, dtrain)
    if not shap_only:
        big_reference(ref)
        large_reference(ref)
    json.dump(ref, open(out, "w"), indent=1)
    print("written", out)


def train_reference(ref, x, y, fold, xk, dtrain):
    for colsample in (1.0, 0.8):
        ref["paper"][f"colsample_{colsample}"] = {}
        for threads in (1, 2):
            p = table2(colsample_bytree=colsample, nthread=threads)
            train_ms, train_worst = timed(lambda: xgb.train(p, dtrain, 400), 7)
            fit_ms, _ = timed(lambda: xgb.train(p, xgb.DMatrix(xk, label=y), 400), 7)
            ref["paper"][f"colsample_{colsample}"][f"threads_{threads}"] = {
                "train_ms": train_ms, "train_worst_ms": train_worst, "fit_ms": fit_ms}
            print(f"paper colsample {colsample} threads {threads}: train {train_ms:.1f} ms, "
                  f"fit {fit_ms:.1f} ms")
    # Spec §9 grid with the bench's 5 folds (colsample = subsample = 1).
    for depth in (2, 4, 6, 8):
        for trees in (25, 50, 100, 200, 400, 800):
            rmse = []
            for k in range(5):
                tr, te = fold != k, fold == k
                b = xgb.train(table2(max_depth=depth, nthread=1),
                              xgb.DMatrix(xk[tr], label=y[tr]), trees)
                pred = b.predict(xgb.DMatrix(xk[te])).astype(np.float64)
                rmse.append(float(np.sqrt(np.mean((pred - y[te]) ** 2))))
            ref["grid"][f"{trees}_{depth}"] = {"rmse": float(np.mean(rmse))}
    print("grid done")


def shap_reference(ref, x, y, keep, xk, dtrain):
    # SHAP on the 400-tree Table-2 model (colsample 1.0).
    b = xgb.train(table2(nthread=2), dtrain, 400)
    model = json.loads(b.save_raw("json"))
    # The bench imports the model with all 8 columns: map the kept columns back.
    for t in model["learner"]["gradient_booster"]["model"]["trees"]:
        t["split_indices"] = [keep[i] if i < len(keep) else i for i in t["split_indices"]]
    model["learner"]["learner_model_param"]["num_feature"] = str(x.shape[1])
    model["learner"]["feature_names"] = []
    model["learner"]["feature_types"] = []
    json.dump(model, open(os.path.join(DIR, "paper_xgb_model.json"), "w"))
    s = {}
    # shap's path-dependent values and interactions are the booster's own predict: one thread.
    b.set_param({"nthread": 1})
    explainer = shap.TreeExplainer(b)
    ms, _ = timed(lambda: explainer.shap_values(xk), 5)
    s["path_dependent_us"] = ms * 1e3 / len(y)
    ms, _ = timed(lambda: explainer.shap_values(xk, check_additivity=False), 5)
    s["path_dependent_no_additivity_us"] = ms * 1e3 / len(y)
    b1 = xgb.train(table2(nthread=1), dtrain, 400)
    dx = xgb.DMatrix(xk)
    ms, _ = timed(lambda: b1.predict(dx, pred_contribs=True), 5)
    s["pred_contribs_us_1t"] = ms * 1e3 / len(y)
    for nb in (10, 100, 1000):
        bg = xk[:: max(1, len(y) // nb)][:nb]
        rows = 5 if nb >= 1000 else 40
        full = shap.maskers.Independent(bg, max_samples=len(bg))
        for key, data in ((f"interventional_{nb}_us", full),
                          (f"interventional_{nb}_capped_us", bg)):
            ex = shap.TreeExplainer(b, data=data, feature_perturbation="interventional")
            ms, _ = timed(lambda: ex.shap_values(xk[:rows], check_additivity=False), 3)
            s[key] = ms * 1e3 / rows
            s[key.replace("_us", "_background_rows")] = int(ex.data.shape[0])
    ms, _ = timed(lambda: explainer.shap_interaction_values(xk[:40]), 3)
    s["interactions_us"] = ms * 1e3 / 40
    ref["shap"]["xgb400"] = s
    print("shap", s)


def big_reference(ref):
    # 100 000 × 20, 400 trees, 2 threads: one run each.
    xb, yb, _ = load("big")
    db = xgb.DMatrix(xb, label=yb)
    for method in ("exact", "hist"):
        p = table2(tree_method=method, max_bin=256, nthread=2)
        t = time.perf_counter()
        xgb.train(p, db, 400)
        ref["big"][method] = {"train_ms": (time.perf_counter() - t) * 1e3}
        print(f"big {method}: {ref['big'][method]['train_ms']:.0f} ms")


def large_reference(ref):
    """The bench's `sweep_large`: 10^4, 10^5, 2*10^5 rows x 20 (exact up to 10^5), Table 2 with
    colsample 1.0, 400 trees, nthread 2: `train` time on all rows (median of 3 runs at 10^4, one
    run above) and the test RMSE on fold 0 of a model trained on folds 1-4."""
    ref["large"] = {}
    print("load average", os.getloadavg())
    for name in ("big10k", "big", "big200k"):
        x, y, fold = load(name)
        d = xgb.DMatrix(x, label=y)
        tr, te = fold != 0, fold == 0
        dtr, dte = xgb.DMatrix(x[tr], label=y[tr]), xgb.DMatrix(x[te])
        ref["large"][name] = {}
        for method in ("exact", "hist"):
            if method == "exact" and len(y) > 100_000:
                continue
            p = table2(tree_method=method, max_bin=256, nthread=2)
            runs = 3 if len(y) <= 10_000 else 1
            ts = []
            for _ in range(runs):
                t = time.perf_counter()
                xgb.train(p, d, 400)
                ts.append(time.perf_counter() - t)
            b = xgb.train(p, dtr, 400)
            pred = b.predict(dte).astype(np.float64)
            rmse = float(np.sqrt(np.mean((pred - y[te]) ** 2)))
            ref["large"][name][method] = {"train_ms": statistics.median(ts) * 1e3, "rmse": rmse}
            print(f"{name} {method}: train {statistics.median(ts) * 1e3:.0f} ms, RMSE {rmse:.6f}")
    print("load average", os.getloadavg())


if __name__ == "__main__":
    main()
