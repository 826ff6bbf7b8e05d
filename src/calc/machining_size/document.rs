//! Reading model documents into a validated [`Model`]: our `machining-size-gbdt/1` JSON (spec §5)
//! and XGBoost JSON models (`learner.gradient_booster.model.trees`). A document is read from its
//! JSON value so that every defect, however deep, is reported with its exact JSON pointer; a
//! hostile document (child index out of range, a cycle, absurd depth, non-finite numbers,
//! a non-squared-error objective, too many nodes) is rejected, never followed.

use indexmap::IndexMap;

use super::doc_tree::{Doc, Item};

use super::model::{
    MAX_ABS_VALUE, MAX_TOTAL_NODES, Model, ModelSource, RawNames, RawTree, Routing, StructureIssue,
    Tree, build_tree,
};

/// The `format` string of our model documents.
pub const FORMAT: &str = "machining-size-gbdt/1";
/// The only objective of v1.
pub const OBJECTIVE: &str = "reg:squarederror";

/// Limits a model document must respect.
#[derive(Debug, Clone, Copy)]
pub struct DocLimits {
    /// Most trees.
    pub max_trees: usize,
    /// Most input features.
    pub max_features: usize,
}

type Res<T> = Result<T, StructureIssue>;

fn issue(pointer: impl Into<String>, detail: impl Into<String>) -> StructureIssue {
    StructureIssue {
        pointer: pointer.into(),
        detail: detail.into(),
    }
}

type Obj = IndexMap<String, Doc>;

fn object<'a>(v: &'a Doc, at: &str) -> Res<&'a Obj> {
    v.as_object()
        .ok_or_else(|| issue(at, format!("must be an object, got {}", v.kind())))
}

fn kind(v: &Item<'_>) -> &'static str {
    v.doc().map_or("a number", Doc::kind)
}

fn field<'a>(o: &'a Obj, key: &str, at: &str) -> Res<&'a Doc> {
    o.get(key)
        .ok_or_else(|| issue(format!("{at}/{key}"), format!("missing field `{key}`")))
}

/// The elements of an array.
fn items<'a>(v: &'a Doc, at: &str) -> Res<impl Iterator<Item = Item<'a>>> {
    let n = v
        .array_len()
        .ok_or_else(|| issue(at, format!("must be an array, got {}", v.kind())))?;
    Ok((0..n).filter_map(move |i| v.item(i)))
}

fn string<'a>(v: &'a Doc, at: &str) -> Res<&'a str> {
    match v {
        Doc::String(s) => Ok(s),
        _ => Err(issue(at, format!("must be a string, got {}", v.kind()))),
    }
}

fn number(v: &Item<'_>, at: &str) -> Res<f64> {
    v.number()
        .and_then(serde_json::Number::as_f64)
        .filter(|x| x.is_finite())
        .ok_or_else(|| issue(at, format!("must be a finite number, got {v}")))
}

fn integer(v: &Item<'_>, at: &str) -> Res<i64> {
    let n = v.number();
    n.and_then(serde_json::Number::as_i64)
        .or_else(|| {
            n.and_then(serde_json::Number::as_f64)
                .filter(|x| x.fract() == 0.0 && x.abs() < 9.0e15)
                .map(|x| x as i64)
        })
        .ok_or_else(|| issue(at, format!("must be an integer, got {v}")))
}

fn numbers(v: &Doc, at: &str) -> Res<Vec<f64>> {
    match v {
        // Numbers of the JSON text are finite (serde_json refuses an overflowing literal).
        Doc::Floats(xs) => Ok(xs.clone()),
        Doc::Ints(xs) => Ok(xs.iter().map(|&x| x as f64).collect()),
        _ => items(v, at)?
            .enumerate()
            .map(|(i, x)| number(&x, &format!("{at}/{i}")))
            .collect(),
    }
}

fn integers(v: &Doc, at: &str) -> Res<Vec<i64>> {
    match v {
        Doc::Ints(xs) => Ok(xs.clone()),
        _ => items(v, at)?
            .enumerate()
            .map(|(i, x)| integer(&x, &format!("{at}/{i}")))
            .collect(),
    }
}

/// Booleans, also written as 0/1 (XGBoost's `default_left`).
fn flags(v: &Doc, at: &str) -> Res<Vec<bool>> {
    items(v, at)?
        .enumerate()
        .map(|(i, x)| match x {
            Item::Doc(Doc::Bool(b)) => Ok(*b),
            _ => match integer(&x, &format!("{at}/{i}"))? {
                0 => Ok(false),
                1 => Ok(true),
                k => Err(issue(
                    format!("{at}/{i}"),
                    format!("must be 0 or 1, got {k}"),
                )),
            },
        })
        .collect()
}

fn names(v: &Doc, at: &str) -> Res<Vec<String>> {
    items(v, at)?
        .enumerate()
        .map(|(i, x)| match x {
            Item::Doc(Doc::String(s)) => Ok(s.clone()),
            _ => Err(issue(
                format!("{at}/{i}"),
                format!("must be a string, got {}", kind(&x)),
            )),
        })
        .collect()
}

/// The trees of a model: an array of at most `limits.max_trees` elements.
fn trees<'a>(v: &'a Doc, at: &str, limits: DocLimits) -> Res<impl Iterator<Item = Item<'a>>> {
    let it = items(v, at)?;
    let n = v.array_len().unwrap_or(0);
    if n > limits.max_trees {
        return Err(issue(
            at,
            format!(
                "a model may have at most {} trees, got {n}",
                limits.max_trees,
            ),
        ));
    }
    Ok(it)
}

/// A tree of a model: an object.
fn tree_object<'a>(tv: &Item<'a>, at: &str) -> Res<&'a Obj> {
    match tv {
        Item::Doc(d) => object(d, at),
        Item::Number(_) => Err(issue(at, "must be an object, got a number")),
    }
}

fn check_nodes(total: &mut usize, add: usize, at: &str) -> Res<()> {
    *total += add;
    if *total > MAX_TOTAL_NODES {
        return Err(issue(
            at,
            format!("a model may have at most {MAX_TOTAL_NODES} nodes in all"),
        ));
    }
    Ok(())
}

const NATIVE_KEYS: [&str; 7] = [
    "format",
    "objective",
    "base_score",
    "feature_names",
    "n_features",
    "params",
    "trees",
];
const NATIVE_TREE_KEYS: [&str; 8] = [
    "left",
    "right",
    "feature",
    "threshold",
    "default_left",
    "value",
    "cover",
    "loss_change",
];

fn no_unknown(o: &Obj, known: &[&str], at: &str) -> Res<()> {
    match o.keys().find(|k| !known.contains(&k.as_str())) {
        Some(k) => Err(issue(
            format!("{at}/{k}"),
            format!("unknown field `{k}`, expected one of {}", known.join(", ")),
        )),
        None => Ok(()),
    }
}

/// Reads our model document (spec §5) at pointer `at`.
///
/// # Errors
/// The first defect, with its pointer.
pub fn read_native(v: &Doc, at: &str, limits: DocLimits) -> Res<Model> {
    let o = object(v, at)?;
    no_unknown(o, &NATIVE_KEYS, at)?;
    let format = string(field(o, "format", at)?, &format!("{at}/format"))?;
    if format != FORMAT {
        return Err(issue(
            format!("{at}/format"),
            format!("must be \"{FORMAT}\", got \"{format}\""),
        ));
    }
    let objective = string(field(o, "objective", at)?, &format!("{at}/objective"))?;
    if objective != OBJECTIVE {
        return Err(issue(
            format!("{at}/objective"),
            format!("only \"{OBJECTIVE}\" models are supported (v1), got \"{objective}\""),
        ));
    }
    let base_score = number(
        &Item::Doc(field(o, "base_score", at)?),
        &format!("{at}/base_score"),
    )?;
    if base_score.abs() > MAX_ABS_VALUE {
        return Err(issue(
            format!("{at}/base_score"),
            format!("must have magnitude ≤ 1e100, got {base_score}"),
        ));
    }
    let n_features = integer(
        &Item::Doc(field(o, "n_features", at)?),
        &format!("{at}/n_features"),
    )?;
    let n_features = usize::try_from(n_features)
        .ok()
        .filter(|&n| (1..=limits.max_features).contains(&n))
        .ok_or_else(|| {
            issue(
                format!("{at}/n_features"),
                format!(
                    "must be an integer in [1, {}], got {n_features}",
                    limits.max_features
                ),
            )
        })?;
    let feature_names = match o.get("feature_names") {
        Some(v) => names(v, &format!("{at}/feature_names"))?,
        None => Vec::new(),
    };
    if !feature_names.is_empty() && feature_names.len() != n_features {
        return Err(issue(
            format!("{at}/feature_names"),
            format!(
                "has {} names but n_features is {n_features}",
                feature_names.len()
            ),
        ));
    }
    let at_trees = format!("{at}/trees");
    let trees_v = field(o, "trees", at)?;
    let mut trees = Vec::with_capacity(trees_v.array_len().unwrap_or(0));
    let mut total = 0;
    for (t, tv) in self::trees(trees_v, &at_trees, limits)?.enumerate() {
        let at_t = format!("{at_trees}/{t}");
        let to = tree_object(&tv, &at_t)?;
        no_unknown(to, &NATIVE_TREE_KEYS, &at_t)?;
        let get = |k: &str| field(to, k, &at_t);
        let raw = RawTree {
            left: integers(get("left")?, &format!("{at_t}/left"))?,
            right: integers(get("right")?, &format!("{at_t}/right"))?,
            feature: integers(get("feature")?, &format!("{at_t}/feature"))?,
            threshold: numbers(get("threshold")?, &format!("{at_t}/threshold"))?,
            default_left: match to.get("default_left") {
                Some(v) => flags(v, &format!("{at_t}/default_left"))?,
                None => Vec::new(),
            },
            value: numbers(get("value")?, &format!("{at_t}/value"))?,
            cover: numbers(get("cover")?, &format!("{at_t}/cover"))?,
            loss_change: match to.get("loss_change") {
                Some(v) => numbers(v, &format!("{at_t}/loss_change"))?,
                None => Vec::new(),
            },
        };
        check_nodes(&mut total, raw.left.len(), &at_t)?;
        if let Some(i) = raw.value.iter().position(|v| v.abs() > MAX_ABS_VALUE) {
            return Err(issue(
                format!("{at_t}/value/{i}"),
                format!("must have magnitude ≤ 1e100, got {}", raw.value[i]),
            ));
        }
        trees.push(build_tree(&raw, RawNames::PLAIN, &at_t, n_features)?);
    }
    Ok(Model {
        base_score,
        n_features,
        feature_names,
        routing: Routing::F64,
        source: ModelSource::Native,
        trees,
    })
}

/// A number of an XGBoost document, as the f32 XGBoost holds (decimal → f64 → f32 is exact for
/// the shortest f32 representations XGBoost writes).
fn as_f32(x: f64) -> f64 {
    let y = x as f32;
    f64::from(y)
}

/// XGBoost's `base_score`: `"[1.9962889E1]"` (≥ 3.0, a vector of one) or `"5E-1"` (2.x).
fn parse_base_score(s: &str, at: &str) -> Res<f64> {
    let inner = s.trim().trim_start_matches('[').trim_end_matches(']');
    let parts: Vec<&str> = inner.split(',').map(str::trim).collect();
    let [one] = parts.as_slice() else {
        return Err(issue(
            at,
            format!("expected one intercept (single-target model), got \"{s}\""),
        ));
    };
    one.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite() && x.abs() <= MAX_ABS_VALUE)
        .map(as_f32)
        .ok_or_else(|| issue(at, format!("is not a finite number: \"{s}\"")))
}

/// A string-or-number integer parameter of XGBoost's JSON (`"5"`).
fn param_int(o: &Obj, key: &str, at: &str) -> Res<Option<i64>> {
    match o.get(key) {
        None => Ok(None),
        Some(Doc::String(s)) => s.trim().parse::<i64>().map(Some).map_err(|_| {
            issue(
                format!("{at}/{key}"),
                format!("must be an integer, got \"{s}\""),
            )
        }),
        Some(v) => integer(&Item::Doc(v), &format!("{at}/{key}")).map(Some),
    }
}

/// Reads an XGBoost JSON model (the value of `xgboost_json`, at pointer `at`).
///
/// # Errors
/// The first defect, with its pointer: not a `gbtree` booster, an objective other than
/// `reg:squarederror`, multi-target or multi-class models, categorical splits, vector leaves,
/// and every structural defect of [`build_tree`].
pub fn read_xgboost(v: &Doc, at: &str, limits: DocLimits) -> Res<Model> {
    let root = object(v, at)?;
    let at_l = format!("{at}/learner");
    let learner = object(field(root, "learner", at)?, &at_l)?;
    let at_obj = format!("{at_l}/objective");
    let objective = object(field(learner, "objective", &at_l)?, &at_obj)?;
    let name = string(
        field(objective, "name", &at_obj)?,
        &format!("{at_obj}/name"),
    )?;
    if name != OBJECTIVE {
        return Err(issue(
            format!("{at_obj}/name"),
            format!("only \"{OBJECTIVE}\" models are supported (v1), got \"{name}\""),
        ));
    }
    let at_p = format!("{at_l}/learner_model_param");
    let lmp = object(field(learner, "learner_model_param", &at_l)?, &at_p)?;
    let base_score = parse_base_score(
        string(
            field(lmp, "base_score", &at_p)?,
            &format!("{at_p}/base_score"),
        )?,
        &format!("{at_p}/base_score"),
    )?;
    for (key, allowed) in [("num_target", 1), ("num_class", 0)] {
        if let Some(k) = param_int(lmp, key, &at_p)?
            && k != allowed
            && !(key == "num_target" && k == 0)
        {
            return Err(issue(
                format!("{at_p}/{key}"),
                format!("only single-output regression models are supported, got {key} = {k}"),
            ));
        }
    }
    let n_features = param_int(lmp, "num_feature", &at_p)?
        .ok_or_else(|| issue(format!("{at_p}/num_feature"), "missing field `num_feature`"))?;
    let n_features = usize::try_from(n_features)
        .ok()
        .filter(|&n| (1..=limits.max_features).contains(&n))
        .ok_or_else(|| {
            issue(
                format!("{at_p}/num_feature"),
                format!("must be in [1, {}], got {n_features}", limits.max_features),
            )
        })?;
    let feature_names = match learner.get("feature_names") {
        Some(v) => names(v, &format!("{at_l}/feature_names"))?,
        None => Vec::new(),
    };
    if !feature_names.is_empty() && feature_names.len() != n_features {
        return Err(issue(
            format!("{at_l}/feature_names"),
            format!(
                "has {} names but num_feature is {n_features}",
                feature_names.len()
            ),
        ));
    }
    let at_gb = format!("{at_l}/gradient_booster");
    let gb = object(field(learner, "gradient_booster", &at_l)?, &at_gb)?;
    let booster = string(field(gb, "name", &at_gb)?, &format!("{at_gb}/name"))?;
    if booster != "gbtree" {
        return Err(issue(
            format!("{at_gb}/name"),
            format!("only \"gbtree\" boosters are supported, got \"{booster}\""),
        ));
    }
    let at_m = format!("{at_gb}/model");
    let model = object(field(gb, "model", &at_gb)?, &at_m)?;
    if let Some(info) = model.get("tree_info") {
        let info = integers(info, &format!("{at_m}/tree_info"))?;
        if let Some(i) = info.iter().position(|&g| g != 0) {
            return Err(issue(
                format!("{at_m}/tree_info/{i}"),
                "only single-output models are supported (all trees in group 0)",
            ));
        }
    }
    let at_trees = format!("{at_m}/trees");
    let trees_v = field(model, "trees", &at_m)?;
    let mut trees = Vec::with_capacity(trees_v.array_len().unwrap_or(0));
    let mut total = 0;
    for (t, tv) in self::trees(trees_v, &at_trees, limits)?.enumerate() {
        let at_t = format!("{at_trees}/{t}");
        let tree = read_xgb_tree(tree_object(&tv, &at_t)?, &at_t, n_features, &mut total)?;
        trees.push(tree);
    }
    Ok(Model {
        base_score,
        n_features,
        feature_names,
        routing: Routing::F32,
        source: ModelSource::Xgboost,
        trees,
    })
}

fn read_xgb_tree(to: &Obj, at_t: &str, n_features: usize, total: &mut usize) -> Res<Tree> {
    if let Some(tp) = to.get("tree_param") {
        let at_tp = format!("{at_t}/tree_param");
        let tp = object(tp, &at_tp)?;
        if let Some(k) = param_int(tp, "size_leaf_vector", &at_tp)?
            && k > 1
        {
            return Err(issue(
                format!("{at_tp}/size_leaf_vector"),
                format!("vector leaves (multi-target trees) are not supported, got {k}"),
            ));
        }
    }
    let get = |k: &str| field(to, k, at_t);
    let conditions = numbers(
        get("split_conditions")?,
        &format!("{at_t}/split_conditions"),
    )?;
    let conditions: Vec<f64> = conditions.into_iter().map(as_f32).collect();
    let raw = RawTree {
        left: integers(get("left_children")?, &format!("{at_t}/left_children"))?,
        right: integers(get("right_children")?, &format!("{at_t}/right_children"))?,
        feature: integers(get("split_indices")?, &format!("{at_t}/split_indices"))?,
        threshold: conditions.clone(),
        default_left: match to.get("default_left") {
            Some(v) => flags(v, &format!("{at_t}/default_left"))?,
            None => Vec::new(),
        },
        value: conditions,
        cover: numbers(get("sum_hessian")?, &format!("{at_t}/sum_hessian"))?,
        loss_change: match to.get("loss_changes") {
            Some(v) => numbers(v, &format!("{at_t}/loss_changes"))?,
            None => Vec::new(),
        },
    };
    check_nodes(total, raw.left.len(), at_t)?;
    if let Some(st) = to.get("split_type") {
        let st = integers(st, &format!("{at_t}/split_type"))?;
        if let Some(i) = st
            .iter()
            .enumerate()
            .position(|(i, &s)| s != 0 && raw.left.get(i).is_some_and(|&l| l != -1))
        {
            return Err(issue(
                format!("{at_t}/split_type/{i}"),
                "categorical splits are not supported (v1)",
            ));
        }
    }
    let names = RawNames {
        left: "left_children",
        right: "right_children",
        feature: "split_indices",
        threshold: "split_conditions",
        value: "split_conditions",
        cover: "sum_hessian",
    };
    build_tree(&raw, names, at_t, n_features)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;
    use serde_json::{Value, json};

    fn doc(v: &Value) -> Doc {
        Doc::deserialize(v).unwrap()
    }

    const LIMITS: DocLimits = DocLimits {
        max_trees: 5000,
        max_features: 200,
    };

    fn xgb_t1() -> Value {
        json!({"learner": {
            "feature_names": [],
            "gradient_booster": {"name": "gbtree", "model": {"tree_info": [0], "trees": [{
                "base_weights": [-0.0, -1.5, 3.0], "default_left": [1, 0, 0], "id": 0,
                "left_children": [1, -1, -1], "loss_changes": [27.0, 0.0, 0.0],
                "parents": [2147483647, 0, 0], "right_children": [2, -1, -1],
                "split_conditions": [3.5, -1.5, 3.0], "split_indices": [0, 0, 0],
                "split_type": [0, 0, 0], "sum_hessian": [4.0, 3.0, 1.0],
                "tree_param": {"num_deleted": "0", "num_feature": "1", "num_nodes": "3",
                               "size_leaf_vector": "1"}}]}},
            "learner_model_param": {"base_score": "[4E0]", "num_class": "0",
                                    "num_feature": "1", "num_target": "1"},
            "objective": {"name": "reg:squarederror"}},
            "version": [3, 2, 0]})
    }

    #[test]
    fn reads_xgboost_t1() {
        let m = read_xgboost(&doc(&xgb_t1()), "/m", LIMITS).unwrap();
        assert_eq!((m.base_score).to_bits(), f64::to_bits(4.0));
        assert_eq!((m.predict_prepared(&[1.0])).to_bits(), f64::to_bits(2.5));
        assert_eq!((m.predict_prepared(&[4.0])).to_bits(), f64::to_bits(7.0));
    }

    #[test]
    fn rejects_hostile_xgboost_documents() {
        let mut v = xgb_t1();
        v["learner"]["objective"]["name"] = json!("reg:pseudohubererror");
        let e = read_xgboost(&doc(&v), "/m", LIMITS).unwrap_err();
        assert_eq!(e.pointer, "/m/learner/objective/name");
        let mut v = xgb_t1();
        v["learner"]["gradient_booster"]["model"]["trees"][0]["left_children"] = json!([1, 0, -1]);
        v["learner"]["gradient_booster"]["model"]["trees"][0]["right_children"] = json!([2, 2, -1]);
        let e = read_xgboost(&doc(&v), "/m", LIMITS).unwrap_err();
        assert!(e.detail.contains("reached twice"), "{e:?}");
        assert!(e.pointer.ends_with("/left_children/1"), "{e:?}");
        let mut v = xgb_t1();
        v["learner"]["gradient_booster"]["model"]["trees"][0]["right_children"] =
            json!([99, -1, -1]);
        let e = read_xgboost(&doc(&v), "/m", LIMITS).unwrap_err();
        assert!(e.pointer.ends_with("/right_children/0"), "{e:?}");
    }

    #[test]
    fn base_score_forms() {
        assert_eq!(
            parse_base_score("[1.9962889E1]", "/b").unwrap().to_bits(),
            f64::from(19.962_889_f32).to_bits()
        );
        assert_eq!(
            (parse_base_score("5E-1", "/b").unwrap()).to_bits(),
            f64::to_bits(0.5)
        );
        assert!(parse_base_score("[1,2]", "/b").is_err());
        assert!(parse_base_score("nan", "/b").is_err());
    }
}
