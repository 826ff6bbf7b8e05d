//! The request's shape, checked against the published document itself.
//!
//! serde is lenient in ways the document is not (a struct may arrive as a JSON array, for
//! example). After a request has decoded, its JSON is validated against the operation's request
//! schema from the OpenAPI document with a JSON Schema 2020-12 validator, minus the numeric
//! bounds: types, required and unknown members, enums and variants are checked at the door, and
//! every value bound is left to the module's validator, which reads the same table the document
//! was written from (and names the quantity and limit in its message). So a request the document
//! calls invalid is never answered with a 2xx.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use jsonschema::error::ValidationErrorKind;
use serde_json::{Map, Value, json};

use super::openapi;
use super::problem::ApiError;

/// Value-bound keywords: enforced by the module validators (which name the quantity and the
/// limit, with the module's code), not here.
const BOUND_KEYWORDS: [&str; 9] = [
    "minimum",
    "maximum",
    "exclusiveMinimum",
    "exclusiveMaximum",
    "minLength",
    "maxLength",
    "minItems",
    "maxItems",
    "pattern",
];

/// The document's components without numeric bounds, built once.
fn shape_components() -> &'static Value {
    static C: OnceLock<Value> = OnceLock::new();
    C.get_or_init(|| {
        let mut c = openapi::document()
            .get("components")
            .cloned()
            .unwrap_or_else(|| json!({}));
        strip_bounds(&mut c);
        c
    })
}

fn strip_bounds(v: &mut Value) {
    match v {
        Value::Object(m) => {
            // Only where the keyword has a keyword's value: a property may be *named* "minimum".
            for k in BOUND_KEYWORDS {
                if m.get(k).is_some_and(|v| v.is_number() || v.is_string()) {
                    m.remove(k);
                }
            }
            m.values_mut().for_each(strip_bounds);
        }
        Value::Array(a) => a.iter_mut().for_each(strip_bounds),
        _ => {}
    }
}

/// A compiled request schema (`None` when it does not compile).
type Compiled = Option<Arc<jsonschema::Validator>>;

/// The compiled validator of one request schema (by schema name; with the document's value
/// bounds when `bounded`), built on first use.
fn validator(schema: &str, bounded: bool) -> Compiled {
    static CACHE: OnceLock<Mutex<HashMap<(String, bool), Compiled>>> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(v) = cache.lock().ok()?.get(&(schema.to_owned(), bounded)) {
        return v.clone();
    }
    let mut root = Map::new();
    root.insert(
        "$schema".to_owned(),
        json!("https://json-schema.org/draft/2020-12/schema"),
    );
    root.insert(
        "$ref".to_owned(),
        json!(format!("#/components/schemas/{schema}")),
    );
    let components = if bounded {
        openapi::document()
            .get("components")
            .cloned()
            .unwrap_or_else(|| json!({}))
    } else {
        shape_components().clone()
    };
    root.insert("components".to_owned(), components);
    let compiled = jsonschema::draft202012::options()
        .build(&Value::Object(root))
        .map_err(|e| tracing::error!(%schema, error = %e, "request schema does not compile"))
        .ok()
        .map(Arc::new);
    if let Ok(mut c) = cache.lock() {
        c.insert((schema.to_owned(), bounded), compiled.clone());
    }
    compiled
}

/// Validates a decoded request's JSON against the shape of schema `schema`; a 422 listing every
/// offending member by JSON pointer when it does not fit.
pub fn check(schema: &str, body: &[u8]) -> Result<(), ApiError> {
    let Some(v) = validator(schema, false) else {
        // A schema that does not compile is a bug (logged above); the module validator still runs.
        return Ok(());
    };
    let Ok(value) = serde_json::from_slice::<Value>(body) else {
        return Ok(());
    };
    let mut found = Vec::new();
    for e in v.iter_errors(&value).take(20) {
        flatten(&e, &mut found);
    }
    let mut err: Option<ApiError> = None;
    for (pointer, detail) in found {
        err = Some(match err {
            None => ApiError::invalid_field(pointer, detail),
            Some(a) => a.with_field(pointer, detail),
        });
    }
    err.map_or(Ok(()), Err)
}

/// (pointer, message) of an error; a failed `oneOf`/`anyOf` is explained by the alternative that
/// got furthest into the value (the deepest error), not by "no alternative matched".
fn flatten(e: &jsonschema::ValidationError<'_>, out: &mut Vec<(String, String)>) {
    let path = e.instance_path().as_str().to_owned();
    match e.kind() {
        ValidationErrorKind::Required { property } => out.push((
            format!("{path}/{}", property.as_str().unwrap_or("?")),
            "missing required field".to_owned(),
        )),
        ValidationErrorKind::AdditionalProperties { unexpected } => {
            for u in unexpected {
                out.push((format!("{path}/{u}"), "unknown field".to_owned()));
            }
        }
        ValidationErrorKind::OneOfNotValid { context } | ValidationErrorKind::AnyOf { context } => {
            // The variant the request most likely meant: the one whose errors reach deepest
            // (a missing or unknown member counts one level below its object), and of those the
            // one with the fewest errors.
            let depth = |errs: &Vec<jsonschema::ValidationError<'static>>| {
                errs.iter()
                    .map(|x| {
                        let member = matches!(
                            x.kind(),
                            ValidationErrorKind::Required { .. }
                                | ValidationErrorKind::AdditionalProperties { .. }
                        );
                        x.instance_path().as_str().matches('/').count() + usize::from(member)
                    })
                    .max()
                    .unwrap_or(0)
            };
            match context
                .iter()
                .filter(|c| !c.is_empty())
                .max_by_key(|c| (depth(c), std::cmp::Reverse(c.len())))
            {
                Some(best) if depth(best) > path.matches('/').count() => {
                    best.iter().for_each(|x| flatten(x, out));
                }
                _ => out.push((path, format!("does not fit the documented schema: {e}"))),
            }
        }
        _ => out.push((path, format!("does not fit the documented schema: {e}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_stripped_but_properties_named_like_them_stay() {
        let mut v =
            json!({"minimum": 0, "properties": {"minimum": {"type": "number", "maximum": 3}}});
        strip_bounds(&mut v);
        assert_eq!(v, json!({"properties": {"minimum": {"type": "number"}}}));
    }
}
