//! The OpenAPI document: generated from the handlers and wire types, then completed in one pass
//! from the same tables the validators use, and built once per process.
//!
//! * Schema names are module-qualified (`cognates.Meta`); [`Registry`] records every schema a
//!   route brings and reports two different Rust types that map to one name (utoipa would keep
//!   one of them silently).
//! * Per-field rules (`minimum`, `maximum`, `exclusiveMinimum`, `exclusiveMaximum`, `minItems`,
//!   `maxItems`, `minLength`, `maxLength`, `oneOf` groups) are written from the `#[rule]`
//!   declarations ([`crate::calc::document_rules`]); a bound written anywhere else is reported by
//!   [`document_problems`]. Each operation lists its rules between fields (`x-cross-field-rules`).
//! * Internally tagged request enums (`{"model": "constant", ...}`) are rewritten so the tag is a
//!   property of each variant's own closed object and the `oneOf` carries a discriminator: utoipa
//!   renders them as `allOf[{closed object}, {tag}]`, which no instance can satisfy.

use std::collections::BTreeMap;
use std::sync::OnceLock;

use axum::routing::MethodRouter;
use serde_json::{Map, Value, json};
use utoipa::openapi::path::Paths;
use utoipa::openapi::{RefOr, schema::Schema};
use utoipa_axum::router::OpenApiRouter;

use crate::calc::Range;
use crate::calc::rules::{DocRules, Kind};

use super::AppState;

/// What `routes!` hands over: the route's schemas, its paths and its method router.
pub type RouteParts = (Vec<(String, RefOr<Schema>)>, Paths, MethodRouter<AppState>);

/// The router under construction plus every schema name seen so far, to detect two Rust types
/// that map to one schema name.
pub struct Registry {
    router: OpenApiRouter<AppState>,
    seen: BTreeMap<String, String>,
    conflicts: Vec<String>,
}

impl Registry {
    /// Start from the document's fixed parts.
    #[must_use]
    pub fn new(router: OpenApiRouter<AppState>) -> Self {
        Self {
            router,
            seen: BTreeMap::new(),
            conflicts: Vec::new(),
        }
    }

    /// Add one route (the output of `routes!`), recording its schemas.
    #[must_use]
    pub fn route(mut self, parts: RouteParts) -> Self {
        for (name, schema) in &parts.0 {
            let body = serde_json::to_string(schema).unwrap_or_default();
            match self.seen.get(name) {
                Some(prev) if *prev != body => self.conflicts.push(name.clone()),
                Some(_) => {}
                None => {
                    self.seen.insert(name.clone(), body);
                }
            }
        }
        self.router = self.router.routes(parts);
        self
    }

    /// The router, and the schema names claimed by more than one type.
    #[must_use]
    pub fn finish(self) -> (OpenApiRouter<AppState>, Vec<String>) {
        let mut c = self.conflicts;
        c.sort();
        c.dedup();
        (self.router, c)
    }
}

/// The finished document, as JSON, built once.
pub fn document() -> &'static Value {
    static DOC: OnceLock<Value> = OnceLock::new();
    DOC.get_or_init(|| build().0)
}

/// Problems of the generated document that a test must see: schema-name conflicts, bounds whose
/// schema or property does not exist, and bounds written as literals instead of from a table.
#[must_use]
pub fn document_problems() -> Vec<String> {
    build().1
}

fn build() -> (Value, Vec<String>) {
    let (api, conflicts) = super::api_parts();
    let mut problems: Vec<String> = conflicts
        .into_iter()
        .map(|n| format!("schema name `{n}` is used by two different types"))
        .collect();
    let mut doc = serde_json::to_value(&api).unwrap_or(Value::Null);
    if let Some(schemas) = doc
        .pointer_mut("/components/schemas")
        .and_then(Value::as_object_mut)
    {
        problems.extend(literal_bounds(schemas));
        for s in schemas.values_mut() {
            unsigned_32_bit_range(s);
        }
        problems.extend(apply_rules(schemas, &crate::calc::document_rules()));
        close_tagged_enums(schemas);
        close_inline_variants(schemas);
    }
    let request_roots: Vec<String> = doc
        .get("paths")
        .and_then(Value::as_object)
        .map(|paths| {
            paths
                .values()
                .filter_map(|item| {
                    item.pointer("/post/requestBody/content/application~1json/schema/$ref")
                        .and_then(Value::as_str)
                        .and_then(|r| r.strip_prefix("#/components/schemas/"))
                        .map(str::to_owned)
                })
                .collect()
        })
        .unwrap_or_default();
    if let Some(schemas) = doc
        .pointer_mut("/components/schemas")
        .and_then(Value::as_object_mut)
    {
        allow_null_for_optional_request_fields(schemas, &request_roots);
    }
    document_cross_field_rules(&mut doc);
    // The one service-wide refusal a schema-valid request can meet on every operation.
    let r = &crate::calc::common::NON_FINITE_ANSWER_RULE;
    if let Some(root) = doc.as_object_mut() {
        root.insert(
            "x-service-rules".to_owned(),
            json!([{"code": r.code, "pointers": r.pointers, "rule": r.rule}]),
        );
    }
    document_alternative_media_types(&mut doc);
    unescape_unit_brackets(&mut doc);
    (doc, problems)
}

/// Bounds present before the table is applied: every one is a literal in a `#[schema]`
/// attribute, except the `minimum: 0` utoipa writes for unsigned integers (which serde enforces).
fn literal_bounds(schemas: &Map<String, Value>) -> Vec<String> {
    let mut out = Vec::new();
    for (name, schema) in schemas {
        let Some(props) = schema.get("properties").and_then(Value::as_object) else {
            continue;
        };
        for (prop, body) in props {
            for (path, s) in [("", body), ("/items", &body["items"])] {
                for key in [
                    "minimum",
                    "maximum",
                    "exclusiveMinimum",
                    "exclusiveMaximum",
                    "minItems",
                    "maxItems",
                    "minLength",
                    "maxLength",
                ] {
                    let Some(v) = s.get(key) else { continue };
                    let unsigned_zero =
                        key == "minimum" && v.as_f64() == Some(0.0) && type_is(s, "integer");
                    if !unsigned_zero {
                        out.push(format!(
                            "{name}.{prop}{path}: `{key}` is written as a literal; declare it as a \
                             #[rule(...)] on the field"
                        ));
                    }
                }
            }
        }
    }
    out
}

fn type_is(schema: &Value, ty: &str) -> bool {
    match schema.get("type") {
        Some(Value::String(s)) => s == ty,
        Some(Value::Array(a)) => a.iter().any(|t| t == ty),
        _ => false,
    }
}

/// Writes each declared rule ([`crate::calc::rules`]) into its schema; returns the rules whose
/// place does not exist in the document.
fn apply_rules(schemas: &mut Map<String, Value>, rules: &DocRules) -> Vec<String> {
    let mut missing = Vec::new();
    for r in &rules.rules {
        let target = schemas.get_mut(r.schema.as_ref()).and_then(|s| {
            if r.pointer.is_empty() {
                Some(s)
            } else {
                s.pointer_mut(r.pointer)
            }
        });
        let Some(t) = target.and_then(Value::as_object_mut) else {
            missing.push(format!(
                "rule for {}{} names no place in the document",
                r.schema, r.pointer
            ));
            continue;
        };
        match r.kind {
            Kind::Range(range) => write_range(t, &range),
            Kind::Len { min, max, string } => {
                let (lo, hi) = if string {
                    ("minLength", "maxLength")
                } else {
                    ("minItems", "maxItems")
                };
                if let Some(n) = min {
                    t.insert(lo.to_owned(), json!(n));
                }
                if let Some(n) = max {
                    t.insert(hi.to_owned(), json!(n));
                }
            }
            Kind::OneOf(names) => {
                let props = t.get("properties").cloned().unwrap_or_else(|| json!({}));
                let alternatives: Vec<Value> = names
                    .iter()
                    .map(|given| {
                        let mut p = Map::new();
                        for name in names {
                            let s = if name == given {
                                non_null(props.get(*name).cloned().unwrap_or_else(|| json!({})))
                            } else {
                                json!({"type": "null"})
                            };
                            p.insert((*name).to_owned(), s);
                        }
                        json!({"required": [given], "properties": p})
                    })
                    .collect();
                t.insert("oneOf".to_owned(), Value::Array(alternatives));
            }
        }
    }
    missing
}

/// The schema of a property without its `null` alternative (the given branch of a `oneOf`).
fn non_null(mut s: Value) -> Value {
    let Some(obj) = s.as_object_mut() else {
        return s;
    };
    obj.remove("description");
    obj.remove("default");
    obj.remove("example");
    obj.remove("examples");
    if let Some(Value::Array(types)) = obj.get_mut("type") {
        types.retain(|t| t != "null");
        if types.len() == 1 {
            let t = types[0].clone();
            obj.insert("type".to_owned(), t);
        }
    }
    if let Some(Value::Array(alts)) = obj.get_mut("oneOf") {
        alts.retain(|a| a.get("type") != Some(&json!("null")));
        if alts.len() == 1 {
            let only = alts[0].clone();
            obj.remove("oneOf");
            if let Some(o) = only.as_object() {
                for (k, v) in o {
                    obj.insert(k.clone(), v.clone());
                }
            }
        }
    }
    s
}

/// Each POST operation lists the rules between fields (and of feasibility) that its requests
/// can break beyond the schema, under `x-cross-field-rules`: `[{code, pointers, rule}]`. A 422
/// for a request the schema accepts carries one of these codes.
fn document_cross_field_rules(doc: &mut Value) {
    let Some(paths) = doc.get_mut("paths").and_then(Value::as_object_mut) else {
        return;
    };
    for (route, rules) in super::cross_field_rules() {
        let Some(op) = paths
            .get_mut(route)
            .and_then(|p| p.get_mut("post"))
            .and_then(Value::as_object_mut)
        else {
            continue;
        };
        let list: Vec<Value> = rules
            .iter()
            .map(|r| json!({"code": r.code, "pointers": r.pointers, "rule": r.rule}))
            .collect();
        op.insert("x-cross-field-rules".to_owned(), Value::Array(list));
    }
}

/// A bound as JSON Schema 2020-12 keywords; integer ranges are written as integers.
pub fn write_range(t: &mut Map<String, Value>, r: &Range) {
    // A side the rule leaves open keeps the bound of the Rust type (e.g. a u32's maximum).
    if r.has_lo() {
        t.remove("minimum");
        t.remove("exclusiveMinimum");
    }
    if r.has_hi() {
        t.remove("maximum");
        t.remove("exclusiveMaximum");
    }
    let num = |x: f64| -> Value {
        if r.integer && x.fract() == 0.0 && x.abs() < 9.0e15 {
            // Exact: |x| < 2^53 and whole.
            json!(x as i64)
        } else {
            json!(x)
        }
    };
    if r.has_lo() {
        t.insert(
            (if r.lo_open {
                "exclusiveMinimum"
            } else {
                "minimum"
            })
            .to_owned(),
            num(r.lo),
        );
    }
    if r.has_hi() {
        t.insert(
            (if r.hi_open {
                "exclusiveMaximum"
            } else {
                "maximum"
            })
            .to_owned(),
            num(r.hi),
        );
    }
}

/// Untagged request enums whose inline object alternatives are decoded with unknown members
/// refused (through a flat raw form with `deny_unknown_fields`).
const CLOSED_UNTAGGED: &[&str] = &["cognates.CouplerPoint"];

/// The inline object alternatives of those enums refuse unknown members: say so.
fn close_inline_variants(schemas: &mut Map<String, Value>) {
    for name in CLOSED_UNTAGGED {
        let Some(s) = schemas.get_mut(*name) else {
            continue;
        };
        let Some(alts) = s.get_mut("oneOf").and_then(Value::as_array_mut) else {
            continue;
        };
        for a in alts.iter_mut().filter_map(Value::as_object_mut) {
            if a.contains_key("properties") && !a.contains_key("additionalProperties") {
                a.insert("additionalProperties".to_owned(), json!(false));
            }
        }
    }
}

/// Rewrites `oneOf[allOf[{$ref: X}, {properties: {tag: {enum: [v]}}}], ...]` (utoipa's rendering of
/// an internally tagged enum with newtype variants) so that each variant is one closed object with
/// the tag among its own properties, and adds a discriminator when every variant is a reference.
fn close_tagged_enums(schemas: &mut Map<String, Value>) {
    let names: Vec<String> = schemas.keys().cloned().collect();
    let refs = reference_counts(schemas);
    for name in names {
        let Some(variants) = schemas
            .get(&name)
            .and_then(|s| s.get("oneOf"))
            .and_then(Value::as_array)
            .cloned()
        else {
            continue;
        };
        let mut tag_name: Option<String> = None;
        let mut new_variants = Vec::with_capacity(variants.len());
        let mut mapping = Map::new();
        let mut all_refs = true;
        for v in &variants {
            let Some((target, tag, value, tag_schema)) = tagged_ref_variant(v) else {
                all_refs &= v.get("$ref").is_some();
                new_variants.push(v.clone());
                continue;
            };
            tag_name.get_or_insert_with(|| tag.clone());
            // Merge the tag into the referenced schema when only this enum uses it; else into a copy.
            let merged_name = if refs.get(&target).copied().unwrap_or(0) <= 1 {
                target.clone()
            } else {
                format!("{target}.{value}")
            };
            let mut merged = schemas.get(&target).cloned().unwrap_or_else(|| json!({}));
            if let Some(obj) = merged.as_object_mut() {
                let props = obj
                    .entry("properties")
                    .or_insert_with(|| json!({}))
                    .as_object_mut();
                if let Some(props) = props {
                    let mut tag_schema = tag_schema.clone();
                    if let Some(t) = tag_schema.as_object_mut() {
                        t.entry("description").or_insert_with(|| {
                            json!(format!("Variant tag: always `{value}` for this variant."))
                        });
                    }
                    let mut with_tag = Map::new();
                    with_tag.insert(tag.clone(), tag_schema);
                    with_tag.extend(std::mem::take(props));
                    *props = with_tag;
                }
                let req = obj.entry("required").or_insert_with(|| json!([]));
                if let Some(req) = req.as_array_mut()
                    && !req.iter().any(|r| r == &Value::String(tag.clone()))
                {
                    req.insert(0, Value::String(tag.clone()));
                }
                if let Some(d) = v.get("description") {
                    obj.entry("description").or_insert_with(|| d.clone());
                }
            }
            schemas.insert(merged_name.clone(), merged);
            let reference = format!("#/components/schemas/{merged_name}");
            mapping.insert(value, Value::String(reference.clone()));
            new_variants.push(json!({ "$ref": reference }));
        }
        let Some(tag) = tag_name else { continue };
        if let Some(obj) = schemas.get_mut(&name).and_then(Value::as_object_mut) {
            obj.insert("oneOf".to_owned(), Value::Array(new_variants));
            if all_refs {
                obj.insert(
                    "discriminator".to_owned(),
                    json!({ "propertyName": tag, "mapping": mapping }),
                );
            }
        }
    }
}

/// `(referenced schema, tag property, tag value, tag property schema)` of an `allOf` variant.
fn tagged_ref_variant(v: &Value) -> Option<(String, String, String, Value)> {
    let parts = v.get("allOf")?.as_array()?;
    let [first, second] = parts.as_slice() else {
        return None;
    };
    let target = first
        .get("$ref")?
        .as_str()?
        .strip_prefix("#/components/schemas/")?
        .to_owned();
    let props = second.get("properties")?.as_object()?;
    let (tag, tag_schema) = props.iter().next().filter(|_| props.len() == 1)?;
    let value = tag_schema
        .get("enum")?
        .as_array()?
        .first()?
        .as_str()?
        .to_owned();
    Some((target, tag.clone(), value, tag_schema.clone()))
}

/// How many times each component schema is referenced anywhere in the components.
fn reference_counts(schemas: &Map<String, Value>) -> BTreeMap<String, usize> {
    fn walk(v: &Value, out: &mut BTreeMap<String, usize>) {
        match v {
            Value::Object(m) => {
                if let Some(Value::String(r)) = m.get("$ref")
                    && let Some(n) = r.strip_prefix("#/components/schemas/")
                {
                    *out.entry(n.to_owned()).or_default() += 1;
                }
                m.values().for_each(|x| walk(x, out));
            }
            Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    let mut out = BTreeMap::new();
    for s in schemas.values() {
        walk(s, &mut out);
    }
    out
}

/// Request decoding reads an explicit `null` for an optional field as "absent" (and some fields
/// use `null` to mean "none", e.g. a limit that is off), so the documented request schemas say
/// so: every optional property of a schema reachable from a request body also admits `null`.
/// (Responses omit absent fields; their schemas are not changed.)
fn allow_null_for_optional_request_fields(schemas: &mut Map<String, Value>, roots: &[String]) {
    let mut seen: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    let mut todo: Vec<String> = roots.to_vec();
    while let Some(name) = todo.pop() {
        if !seen.insert(name.clone()) {
            continue;
        }
        if let Some(s) = schemas.get(&name) {
            collect_refs(s, &mut todo);
        }
    }
    for name in seen {
        let Some(schema) = schemas.get_mut(&name) else {
            continue;
        };
        let required: Vec<String> = schema
            .get("required")
            .and_then(Value::as_array)
            .map(|r| {
                r.iter()
                    .filter_map(|x| x.as_str().map(str::to_owned))
                    .collect()
            })
            .unwrap_or_default();
        let Some(props) = schema.get_mut("properties").and_then(Value::as_object_mut) else {
            continue;
        };
        for (prop, body) in props.iter_mut() {
            if !required.contains(prop) {
                admit_null(body);
            }
        }
    }
}

fn collect_refs(v: &Value, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            if let Some(n) = m
                .get("$ref")
                .and_then(Value::as_str)
                .and_then(|r| r.strip_prefix("#/components/schemas/"))
            {
                out.push(n.to_owned());
            }
            m.values().for_each(|x| collect_refs(x, out));
        }
        Value::Array(a) => a.iter().for_each(|x| collect_refs(x, out)),
        _ => {}
    }
}

/// Make a property schema admit `null` as well, keeping its description at the top.
fn admit_null(body: &mut Value) {
    let Some(obj) = body.as_object_mut() else {
        return;
    };
    match obj.get_mut("type") {
        Some(Value::String(t)) => {
            let t = t.clone();
            if t != "null" {
                obj.insert("type".to_owned(), json!([t, "null"]));
            }
            if let Some(Value::Array(e)) = obj.get_mut("enum")
                && !e.contains(&Value::Null)
            {
                e.push(Value::Null);
            }
            return;
        }
        Some(Value::Array(a)) => {
            if !a.iter().any(|x| x == "null") {
                a.push(json!("null"));
            }
            if let Some(Value::Array(e)) = obj.get_mut("enum")
                && !e.contains(&Value::Null)
            {
                e.push(Value::Null);
            }
            return;
        }
        _ => {}
    }
    if let Some(Value::Array(alts)) = obj.get_mut("oneOf") {
        if !alts.iter().any(|a| a.get("type") == Some(&json!("null"))) {
            alts.push(json!({"type": "null"}));
        }
        return;
    }
    if let Some(r) = obj.remove("$ref") {
        obj.insert(
            "oneOf".to_owned(),
            json!([{ "$ref": r }, { "type": "null" }]),
        );
    } else if let Some(parts) = obj.remove("allOf") {
        obj.insert(
            "oneOf".to_owned(),
            json!([{ "allOf": parts }, { "type": "null" }]),
        );
    }
}

/// Every calculation can also answer as an event stream (progress, then the JSON answer) and,
/// where it has a picture, as SVG; the 200 response of each POST operation says so.
fn document_alternative_media_types(doc: &mut Value) {
    let Some(paths) = doc.get_mut("paths").and_then(Value::as_object_mut) else {
        return;
    };
    for (route, item) in paths.iter_mut() {
        let Some(content) = item
            .pointer_mut("/post/responses/200/content")
            .and_then(Value::as_object_mut)
        else {
            continue;
        };
        content.insert(
            "text/event-stream".to_owned(),
            json!({"schema": {"type": "string", "description":
                "With `Accept: text/event-stream`: Server-Sent Events `progress` ({fraction, best?, \
                 elapsed_ms}) while the calculation runs, then one `result` event whose data is the \
                 JSON answer above (or one `problem` event with the problem details)."}}),
        );
        if crate::plot::has_picture(route) {
            content.insert(
                "image/svg+xml".to_owned(),
                json!({"schema": {"type": "string", "description":
                    "With `Accept: image/svg+xml`: the answer's picture (SVG; axes carry quantity \
                     and unit)."}}),
            );
        }
    }
    crate::export::document_formats(doc);
}

/// utoipa writes `u32` as `format: int32, minimum: 0`, and validators read `int32` as at most
/// 2^31 − 1, while the service accepts every `u32`: say `int64` with the true maximum instead
/// (a table bound, applied afterwards, narrows it further where the module has one).
fn unsigned_32_bit_range(v: &mut Value) {
    match v {
        Value::Object(m) => {
            // utoipa writes u64 as `format: int64, minimum: 0`, which validators bound at 2^63 − 1
            // while the service accepts every u64: say so.
            let format = m.get("format").and_then(Value::as_str);
            let unsigned64 = matches!(format, None | Some("int64" | "uint64" | "uint"))
                && m.get("minimum").and_then(Value::as_f64) == Some(0.0)
                && m.get("maximum").is_none()
                && type_is(&Value::Object(m.clone()), "integer");
            if unsigned64 {
                m.insert("format".to_owned(), json!("uint64"));
                m.insert("maximum".to_owned(), json!(u64::MAX));
            }
            let unsigned32 = m.get("format").and_then(Value::as_str) == Some("int32")
                && m.get("minimum").and_then(Value::as_f64) == Some(0.0)
                && type_is(&Value::Object(m.clone()), "integer");
            if unsigned32 {
                m.insert("format".to_owned(), json!("int64"));
                m.entry("maximum").or_insert(json!(u32::MAX));
            }
            m.values_mut().for_each(unsigned_32_bit_range);
        }
        Value::Array(a) => a.iter_mut().for_each(unsigned_32_bit_range),
        _ => {}
    }
}

/// Doc comments write units in brackets escaped for rustdoc (`time \[s\]`, so rustdoc does not
/// read `[s]` as a link); the document says them plainly (`time [s]`), as CommonMark renders both.
fn unescape_unit_brackets(v: &mut Value) {
    match v {
        Value::Object(m) => {
            for (k, x) in m.iter_mut() {
                match x {
                    Value::String(s) if k == "description" && s.contains('\\') => {
                        *s = s.replace("\\[", "[").replace("\\]", "]");
                    }
                    _ => unescape_unit_brackets(x),
                }
            }
        }
        Value::Array(a) => a.iter_mut().for_each(unescape_unit_brackets),
        _ => {}
    }
}
