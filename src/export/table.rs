//! The tables of each endpoint's answer (`Accept: text/csv`): which arrays of the JSON answer form
//! a table, their column names, and each column's unit from the field's doc.
//!
//! A table only rearranges the answer: every cell is a number, string or boolean of the JSON
//! answer, written as the JSON answer writes it (numbers in the shortest form that reads back to
//! the same `f64`, as `serde_json` writes them), so a CSV value and the JSON value are the same
//! number. An endpoint's first table that its answer carries is its main table; `?table=NAME`
//! selects another.

use serde_json::Value;

use super::schema::{Schemas, unit_of};

/// One column: its name and the unit its field's doc names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Column {
    /// Name (the answer's field name, dotted for nested fields, `.0` for an array item).
    pub name: String,
    /// Unit from the field's doc, without brackets.
    pub unit: Option<String>,
}

impl Column {
    /// The CSV header cell: `name [unit]`.
    #[must_use]
    pub fn header(&self) -> String {
        match &self.unit {
            Some(u) => format!("{} [{u}]", self.name),
            None => self.name.clone(),
        }
    }
}

/// A table: columns and rows of JSON scalars (`Null` is an empty cell).
#[derive(Debug, Clone, Default)]
pub struct Grid {
    /// Columns.
    pub columns: Vec<Column>,
    /// Rows, each as long as `columns`.
    pub rows: Vec<Vec<Value>>,
}

/// What a table builder reads.
pub struct Ctx<'a> {
    /// The request as sent.
    pub request: &'a Value,
    /// The JSON answer.
    pub answer: &'a Value,
    /// The operation's schemas (units).
    pub schemas: &'a Schemas<'a>,
}

impl Ctx<'_> {
    fn column(&self, name: impl Into<String>, schema_path: &[&str]) -> Column {
        Column {
            name: name.into(),
            unit: self
                .schemas
                .answer_doc(schema_path)
                .and_then(unit_of)
                .map(str::to_owned),
        }
    }
}

/// One named table of an endpoint.
pub struct TableDef {
    /// Name for `?table=NAME`.
    pub name: &'static str,
    /// What a row is.
    pub doc: &'static str,
    /// The table of an answer, `None` when the answer does not carry it.
    pub build: fn(&Ctx<'_>) -> Option<Grid>,
}

/// The tables of every endpoint, main table first.
pub const TABLES: &[(&str, &[TableDef])] = &[
    (
        "/v1/cam-law/evaluate",
        &[TableDef {
            name: "curves",
            doc: "one row per abscissa sample: x and the requested derivatives",
            build: |c| columns(c, &["curves"]),
        }],
    ),
    (
        "/v1/fit-cam-law",
        &[
            TableDef {
                name: "segments",
                doc: "one row per segment of the fitted law: duration and coefficient",
                build: |c| parallel(c, &[], &["durations", "coefficients"], Some("segment")),
            },
            TableDef {
                name: "curves",
                doc: "one row per sample of the fitted law (`outputs.curves`)",
                build: |c| columns(c, &["curves"]),
            },
        ],
    ),
    (
        "/v1/cognates",
        &[
            TableDef {
                name: "mechanisms",
                doc: "one row per mechanism (original and both cognates): pivots, links, \
                      Grashof class, input range and the snapshot pose",
                build: |c| records(c, &["mechanisms"]),
            },
            TableDef {
                name: "curves",
                doc: "one row per coupler-curve point of every mechanism and circuit \
                      (`options.curves`)",
                build: cognate_curves,
            },
        ],
    ),
    (
        "/v1/component-importance",
        &[TableDef {
            name: "ranking",
            doc: "one row per operating time × component: importance, rank and its parts",
            build: ranking,
        }],
    ),
    (
        "/v1/bus-fuel-economy",
        &[TableDef {
            name: "results",
            doc: "one row per motor × drive cycle: distance, energies, economy, loss breakdown",
            build: |c| records(c, &["results"]),
        }],
    ),
    (
        "/v1/bus-fuel-economy/motor-map",
        &[
            TableDef {
                name: "map",
                doc: "one row per (speed, torque) grid point: loss, efficiency and loss components",
                build: motor_map,
            },
            TableDef {
                name: "envelope",
                doc: "one row per speed: the torque envelope",
                build: |c| parallel(c, &[], &["speed_rpm", "t_max_nm"], None),
            },
        ],
    ),
    (
        "/v1/irefc-stress",
        &[
            TableDef {
                name: "records",
                doc: "one row per design of the sweep (mode `sweep`)",
                build: |c| records(c, &["records"]),
            },
            TableDef {
                name: "elements",
                doc: "one row per rolling element at the evaluated pose (`include.elements`)",
                build: |c| records(c, &["elements"]),
            },
            TableDef {
                name: "curves",
                doc: "one row per element angle φ2 of the mesh cycle (`include.curves`)",
                build: |c| columns(c, &["curves"]),
            },
        ],
    ),
    (
        "/v1/irefc-efficiency",
        &[TableDef {
            name: "elements",
            doc: "one row per rolling element: angle, lever arms, force, sliding losses",
            build: |c| records(c, &["elements"]),
        }],
    ),
    (
        "/v1/continuum-workspace",
        &[
            TableDef {
                name: "nodes",
                doc: "one row per grid node of every wave (mode `workspace`, `return_nodes`)",
                build: workspace_nodes,
            },
            TableDef {
                name: "solutions",
                doc: "one row per assembly mode found (mode `assembly_modes`)",
                build: |c| records(c, &["solutions"]),
            },
            TableDef {
                name: "rods",
                doc: "one row per rod at the solved pose (mode `fk`)",
                build: |c| records(c, &["rods"]),
            },
        ],
    ),
    (
        "/v1/machining-size/train",
        &[
            TableDef {
                name: "test_predictions",
                doc: "one row per test row: target and prediction",
                build: |c| columns(c, &["test_predictions"]),
            },
            TableDef {
                name: "importance",
                doc: "one row per feature: split count, gain and cover",
                build: |c| records(c, &["importance"]),
            },
            TableDef {
                name: "shap_summary",
                doc: "one row per feature: mean |SHAP| and mean SHAP (`outputs: shap_summary`)",
                build: |c| records(c, &["shap_summary", "features"]),
            },
            TableDef {
                name: "cv_folds",
                doc: "one row per cross-validation fold: its metrics",
                build: |c| records(c, &["metrics", "cv", "folds"]),
            },
        ],
    ),
    (
        "/v1/machining-size/predict",
        &[TableDef {
            name: "predictions",
            doc: "one row per input row: prediction and, with `shap`, one SHAP value per feature",
            build: predictions,
        }],
    ),
    (
        "/v1/machining-size/analyze",
        &[
            TableDef {
                name: "grades",
                doc: "one row per feature: grey relational grade and rank (`gra`)",
                build: |c| records(c, &["gra", "grades"]),
            },
            TableDef {
                name: "pca",
                doc: "one row per principal component: eigenvalue and contribution rates (`pca`)",
                build: |c| {
                    parallel(
                        c,
                        &["pca"],
                        &["eigenvalues", "contribution_rates", "cumulative_rates"],
                        Some("component"),
                    )
                },
            },
        ],
    ),
    (
        "/v1/spatial-coupling",
        &[TableDef {
            name: "series",
            doc: "one row per input angle θ1 of the sweep (`outputs.series`)",
            build: |c| records(c, &["series"]),
        }],
    ),
    (
        "/v1/vibration-absorber",
        &[
            TableDef {
                name: "frf",
                doc: "one row per frequency: magnitude and phase at every output abscissa \
                      (`outputs.frequency_response`)",
                build: |c| with_points(c, &["frequency_response"], "frequencies_hz"),
            },
            TableDef {
                name: "time_response",
                doc: "one row per time sample: deflection at every output abscissa, stroke, \
                      force, current, voltage (`outputs.time_response.return_series`)",
                build: |c| with_points(c, &["time_response"], "t_s"),
            },
            TableDef {
                name: "eigenvalues",
                doc: "one row per closed-loop eigenvalue (`outputs.closed_loop`)",
                build: |c| records(c, &["closed_loop", "eigenvalues"]),
            },
        ],
    ),
    (
        "/v1/bezier-motion-law",
        &[
            TableDef {
                name: "time_history",
                doc: "one row per time sample of the move and after it (`outputs.time_history`)",
                build: |c| columns(c, &["time_history"]),
            },
            TableDef {
                name: "sensitivity",
                doc: "one row per stiffness factor of the sensitivity study",
                build: |c| records(c, &["sensitivity"]),
            },
        ],
    ),
];

/// The tables of `route` (empty when it has none).
#[must_use]
pub fn tables(route: &str) -> &'static [TableDef] {
    TABLES
        .iter()
        .find(|(r, _)| *r == route)
        .map_or(&[], |(_, t)| *t)
}

/// The value at `path` (object keys) below `v`.
fn at<'a>(v: &'a Value, path: &[&str]) -> Option<&'a Value> {
    path.iter().try_fold(v, |v, k| v.get(*k))
}

fn is_scalar(v: &Value) -> bool {
    !(v.is_array() || v.is_object())
}

/// An array of scalars, or `None`.
fn scalars(v: &Value) -> Option<&Vec<Value>> {
    v.as_array().filter(|a| a.iter().all(is_scalar))
}

fn join<'a>(base: &[&'a str], more: &[&'a str]) -> Vec<&'a str> {
    base.iter().chain(more).copied().collect()
}

/// Every array of scalars directly in the object at `base` that is as long as the first one: one
/// column each (scalar fields and other lengths are not rows of this table).
fn columns(c: &Ctx<'_>, base: &[&str]) -> Option<Grid> {
    columns_along(c, base, None)
}

/// As [`columns`], the row count set by the array `anchor` (which must be present) when given.
fn columns_along(c: &Ctx<'_>, base: &[&str], anchor: Option<&str>) -> Option<Grid> {
    let obj = at(c.answer, base)?.as_object()?;
    let keys: Vec<&str> = obj
        .iter()
        .filter(|(_, v)| scalars(v).is_some())
        .map(|(k, _)| k.as_str())
        .collect();
    let n = obj
        .get(anchor.or(keys.first().copied())?)
        .and_then(scalars)?
        .len();
    let keys: Vec<&str> = keys
        .into_iter()
        .filter(|k| obj.get(*k).and_then(scalars).is_some_and(|a| a.len() == n))
        .collect();
    parallel(c, base, &keys, None)
}

/// The named arrays of scalars at `base` side by side (all must be present and equally long),
/// optionally led by a 1-based index column.
fn parallel(c: &Ctx<'_>, base: &[&str], keys: &[&str], index: Option<&str>) -> Option<Grid> {
    let obj = at(c.answer, base)?;
    let cols: Vec<&Vec<Value>> = keys
        .iter()
        .map(|k| obj.get(*k).and_then(scalars))
        .collect::<Option<_>>()?;
    let n = cols.first()?.len();
    if cols.iter().any(|a| a.len() != n) {
        return None;
    }
    let mut g = Grid::default();
    if let Some(name) = index {
        g.columns.push(Column {
            name: name.to_owned(),
            unit: None,
        });
    }
    for k in keys {
        g.columns.push(c.column(*k, &join(base, &[k])));
    }
    for i in 0..n {
        let mut row = Vec::with_capacity(g.columns.len());
        if index.is_some() {
            row.push(Value::from(i + 1));
        }
        row.extend(cols.iter().map(|a| a[i].clone()));
        g.rows.push(row);
    }
    Some(g)
}

/// Flattened scalar leaves of one record: `(name, schema path, value)`. Nested objects give dotted
/// names; an array of up to three numbers gives `name.0 …`; an array of strings gives one cell
/// with the strings separated by spaces; other arrays are tables of their own.
fn flatten(
    v: &Value,
    name: &str,
    path: &mut Vec<String>,
    out: &mut Vec<(String, Vec<String>, Value)>,
) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                path.push(k.clone());
                let n = if name.is_empty() {
                    k.clone()
                } else {
                    format!("{name}.{k}")
                };
                flatten(x, &n, path, out);
                path.pop();
            }
        }
        Value::Array(a) if a.len() <= 3 && a.iter().all(Value::is_number) => {
            for (i, x) in a.iter().enumerate() {
                out.push((format!("{name}.{i}"), path.clone(), x.clone()));
            }
        }
        Value::Array(a) if a.iter().all(Value::is_string) => {
            let s: Vec<&str> = a.iter().filter_map(Value::as_str).collect();
            out.push((name.to_owned(), path.clone(), Value::from(s.join(" "))));
        }
        Value::Array(_) => {}
        _ => out.push((name.to_owned(), path.clone(), v.clone())),
    }
}

/// One row per object of the array at `base`, one column per scalar leaf (union over the rows in
/// first-seen order; a leaf a row lacks is an empty cell).
fn records(c: &Ctx<'_>, base: &[&str]) -> Option<Grid> {
    let items = at(c.answer, base)?.as_array()?;
    records_of(c, base, items.iter().map(|r| (Vec::new(), r)), &[])
}

/// Rows from `(leading cells, record)` pairs; `lead` names the leading columns.
fn records_of<'a>(
    c: &Ctx<'_>,
    base: &[&str],
    items: impl Iterator<Item = (Vec<Value>, &'a Value)>,
    lead: &[Column],
) -> Option<Grid> {
    let mut names: Vec<(String, Vec<String>)> = Vec::new();
    let mut flat = Vec::new();
    for (head, r) in items {
        if !r.is_object() {
            return None;
        }
        let mut leaves = Vec::new();
        flatten(r, "", &mut Vec::new(), &mut leaves);
        for (n, p, _) in &leaves {
            if !names.iter().any(|(m, _)| m == n) {
                names.push((n.clone(), p.clone()));
            }
        }
        flat.push((head, leaves));
    }
    let mut g = Grid {
        columns: lead.to_vec(),
        rows: Vec::with_capacity(flat.len()),
    };
    for (n, p) in &names {
        let mut path: Vec<&str> = base.to_vec();
        path.push("*");
        path.extend(p.iter().map(String::as_str));
        g.columns.push(c.column(n.clone(), &path));
    }
    for (head, leaves) in flat {
        let mut row = head;
        for (n, _) in &names {
            row.push(
                leaves
                    .iter()
                    .find(|(m, _, _)| m == n)
                    .map_or(Value::Null, |(_, _, v)| v.clone()),
            );
        }
        g.rows.push(row);
    }
    Some(g)
}

/// The arrays at `base` as long as `anchor` (as [`columns_along`]) and, for each entry of `base.points`, its arrays of the
/// same length, named `key@x=<x_m>`.
fn with_points(c: &Ctx<'_>, base: &[&str], anchor: &str) -> Option<Grid> {
    let mut g = columns_along(c, base, Some(anchor))?;
    let n = g.rows.len();
    let points = at(c.answer, base)?.get("points").and_then(Value::as_array);
    for p in points.into_iter().flatten() {
        let x = p.get("x_m").map_or_else(String::new, Value::to_string);
        for (k, v) in p.as_object()?.iter() {
            let Some(a) = scalars(v).filter(|a| a.len() == n) else {
                continue;
            };
            g.columns
                .push(c.column(format!("{k}@x={x}"), &join(base, &["points", "*", k])));
            for (row, cell) in g.rows.iter_mut().zip(a) {
                row.push(cell.clone());
            }
        }
    }
    Some(g)
}

fn lead(name: &str, unit: Option<String>) -> Column {
    Column {
        name: name.to_owned(),
        unit,
    }
}

fn cognate_curves(c: &Ctx<'_>) -> Option<Grid> {
    let mut g = Grid {
        columns: vec![
            lead("mechanism", None),
            lead("circuit", None),
            c.column(
                "input_deg",
                &["mechanisms", "*", "curves", "*", "input_deg"],
            ),
            c.column("branch", &["mechanisms", "*", "curves", "*", "branch"]),
            c.column("x", &["mechanisms", "*", "curves", "*", "points"]),
            c.column("y", &["mechanisms", "*", "curves", "*", "points"]),
        ],
        rows: Vec::new(),
    };
    let mut any = false;
    for m in c.answer.get("mechanisms")?.as_array()? {
        let Some(curves) = m.get("curves").and_then(Value::as_array) else {
            continue;
        };
        any = true;
        for (ci, curve) in curves.iter().enumerate() {
            let pts = curve.get("points").and_then(Value::as_array);
            for (i, p) in pts.into_iter().flatten().enumerate() {
                g.rows.push(vec![
                    m.get("id").cloned().unwrap_or(Value::Null),
                    Value::from(ci),
                    curve["input_deg"].get(i).cloned().unwrap_or(Value::Null),
                    curve["branch"].get(i).cloned().unwrap_or(Value::Null),
                    p.get(0).cloned().unwrap_or(Value::Null),
                    p.get(1).cloned().unwrap_or(Value::Null),
                ]);
            }
        }
    }
    any.then_some(g)
}

fn ranking(c: &Ctx<'_>) -> Option<Grid> {
    let names = c.answer.get("components")?.as_array()?;
    let results = c.answer.get("results")?.as_array()?;
    let first = results.first()?.as_object()?;
    let per_component: Vec<&str> = first
        .iter()
        .filter(|(_, v)| scalars(v).is_some_and(|a| a.len() == names.len()))
        .map(|(k, _)| k.as_str())
        .collect();
    let mut g = Grid {
        columns: vec![
            c.column("time_h", &["results", "*", "time_h"]),
            lead("component", None),
        ],
        rows: Vec::new(),
    };
    for k in &per_component {
        g.columns.push(c.column(*k, &["results", "*", k]));
    }
    for r in results {
        for (i, name) in names.iter().enumerate() {
            let mut row = vec![
                r.get("time_h").cloned().unwrap_or(Value::Null),
                name.clone(),
            ];
            row.extend(
                per_component
                    .iter()
                    .map(|k| r[*k].get(i).cloned().unwrap_or(Value::Null)),
            );
            g.rows.push(row);
        }
    }
    Some(g)
}

fn motor_map(c: &Ctx<'_>) -> Option<Grid> {
    let a = c.answer;
    let speed = scalars(a.get("speed_rpm")?)?;
    let torque = scalars(a.get("torque_nm")?)?;
    // Every speed × torque matrix of the answer: top level and under `components`.
    let mut maps: Vec<(String, Vec<&str>, &Vec<Value>)> = Vec::new();
    let is_map = |v: &Value| {
        v.as_array().is_some_and(|rows| {
            rows.len() == speed.len()
                && rows
                    .iter()
                    .all(|r| scalars(r).is_some_and(|r| r.len() == torque.len()))
        })
    };
    for (k, v) in a.as_object()? {
        if is_map(v) {
            maps.push((k.clone(), vec![k.as_str()], v.as_array()?));
        }
    }
    if let Some(comp) = a.get("components").and_then(Value::as_object) {
        for (k, v) in comp {
            if is_map(v) {
                maps.push((
                    format!("components.{k}"),
                    vec!["components", k.as_str()],
                    v.as_array()?,
                ));
            }
        }
    }
    let mut g = Grid {
        columns: vec![
            c.column("speed_rpm", &["speed_rpm"]),
            c.column("torque_nm", &["torque_nm"]),
        ],
        rows: Vec::new(),
    };
    for (name, path, _) in &maps {
        g.columns.push(c.column(name.clone(), path));
    }
    for (i, s) in speed.iter().enumerate() {
        for (j, t) in torque.iter().enumerate() {
            let mut row = vec![s.clone(), t.clone()];
            row.extend(maps.iter().map(|(_, _, m)| m[i][j].clone()));
            g.rows.push(row);
        }
    }
    Some(g)
}

/// The nodes of one wave object (`grid` indices from the answer's `grid`).
fn wave_nodes(c: &Ctx<'_>, g: &mut Grid, wave: usize, nodes: &Value, base: &[&str]) -> Option<()> {
    let obj = nodes.as_object()?;
    let l1 = c.answer.pointer("/grid/lambda1_m").and_then(scalars);
    let l2 = c.answer.pointer("/grid/lambda2_m").and_then(scalars);
    let n = obj.values().find_map(|v| v.as_array().map(Vec::len))?;
    if g.columns.is_empty() {
        g.columns.push(lead("wave", None));
        g.columns.push(lead("i", None));
        g.columns.push(lead("j", None));
        g.columns
            .push(c.column("lambda1_m", &["grid", "lambda1_m"]));
        g.columns
            .push(c.column("lambda2_m", &["grid", "lambda2_m"]));
        for (k, v) in obj {
            let first = v.as_array().and_then(|a| a.first());
            let path = join(base, &[k.as_str()]);
            match first {
                Some(Value::Array(x)) => {
                    for e in 0..x.len() {
                        g.columns.push(c.column(format!("{k}.{e}"), &path));
                    }
                }
                _ => g.columns.push(c.column(k.clone(), &path)),
            }
        }
    }
    let m = l2.map_or(1, Vec::len).max(1);
    for idx in 0..n {
        let (i, j) = (idx / m, idx % m);
        let mut row = vec![
            Value::from(wave),
            Value::from(i),
            Value::from(j),
            l1.and_then(|l| l.get(i)).cloned().unwrap_or(Value::Null),
            l2.and_then(|l| l.get(j)).cloned().unwrap_or(Value::Null),
        ];
        for v in obj.values() {
            match v.get(idx) {
                Some(Value::Array(x)) => row.extend(x.iter().cloned()),
                Some(x) => row.push(x.clone()),
                None => row.push(Value::Null),
            }
        }
        row.resize(g.columns.len(), Value::Null);
        g.rows.push(row);
    }
    Some(())
}

fn workspace_nodes(c: &Ctx<'_>) -> Option<Grid> {
    let mut g = Grid::default();
    let mut any = false;
    if let Some(n) = c.answer.get("nodes") {
        any |= wave_nodes(c, &mut g, 0, n, &["nodes"]).is_some();
    }
    for key in ["other_waves", "waves"] {
        for (w, wave) in c
            .answer
            .get(key)
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .enumerate()
        {
            if let Some(n) = wave.get("nodes") {
                let index = if key == "other_waves" { w + 1 } else { w };
                any |= wave_nodes(c, &mut g, index, n, &[key, "*", "nodes"]).is_some();
            }
        }
    }
    any.then_some(g)
}

fn predictions(c: &Ctx<'_>) -> Option<Grid> {
    let preds = scalars(c.answer.get("predictions")?)?;
    let shap = c.answer.pointer("/shap/values").and_then(Value::as_array);
    let names: Vec<String> = [
        "/model/xgboost_json/learner/feature_names",
        "/model/feature_names",
    ]
    .iter()
    .find_map(|p| c.request.pointer(p).and_then(Value::as_array))
    .map(|a| {
        a.iter()
            .filter_map(Value::as_str)
            .map(str::to_owned)
            .collect()
    })
    .unwrap_or_default();
    let width = shap
        .and_then(|s| s.first())
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let mut g = Grid {
        columns: vec![lead("row", None), c.column("prediction", &["predictions"])],
        rows: Vec::new(),
    };
    for f in 0..width {
        let name = names
            .get(f)
            .filter(|_| names.len() == width)
            .map_or_else(|| format!("shap.{f}"), |n| format!("shap.{n}"));
        g.columns.push(c.column(name, &["shap", "values"]));
    }
    for (i, p) in preds.iter().enumerate() {
        let mut row = vec![Value::from(i), p.clone()];
        let values = shap.and_then(|s| s.get(i)).and_then(Value::as_array);
        for f in 0..width {
            row.push(
                values
                    .and_then(|v| v.get(f))
                    .cloned()
                    .unwrap_or(Value::Null),
            );
        }
        g.rows.push(row);
    }
    Some(g)
}

/// The table's CSV: header `name [unit]`, then one line per row; numbers as the JSON answer
/// writes them, strings quoted where CSV needs it, booleans `true`/`false`, absent cells empty.
///
/// # Errors
/// Only when writing to memory fails (it does not).
pub fn to_csv(g: &Grid) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(g.columns.iter().map(Column::header))?;
    for row in &g.rows {
        w.write_record(row.iter().map(|v| match v {
            Value::Null => String::new(),
            Value::String(s) => s.clone(),
            other => other.to_string(),
        }))?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}
