//! Field documentation from the service's OpenAPI document: the meaning and unit of a request or
//! answer field, read from the same doc comments the document is generated from (every field's
//! doc names its unit in brackets, `Distance driven D [km]`).

use serde_json::Value;

/// One operation's request and 200 answer schemas inside the document.
pub struct Schemas<'a> {
    doc: &'a Value,
    /// Request body schema.
    pub request: Option<&'a Value>,
    /// 200 `application/json` answer schema.
    pub answer: Option<&'a Value>,
}

impl<'a> Schemas<'a> {
    /// The schemas of `POST route` in `doc` (absent parts stay `None`: lookups then find nothing).
    #[must_use]
    pub fn of(doc: &'a Value, route: &str) -> Self {
        let op = doc
            .get("paths")
            .and_then(|p| p.get(route))
            .map(|p| &p["post"]);
        Self {
            doc,
            request: op.and_then(|o| o.pointer("/requestBody/content/application~1json/schema")),
            answer: op.and_then(|o| o.pointer("/responses/200/content/application~1json/schema")),
        }
    }

    /// The description of the request field at `path` (property names; `*` for an array item).
    #[must_use]
    pub fn request_doc(&self, path: &[&str]) -> Option<&'a str> {
        description(self.doc, self.request?, path)
    }

    /// The description of the answer field at `path` (property names; `*` for an array item).
    #[must_use]
    pub fn answer_doc(&self, path: &[&str]) -> Option<&'a str> {
        description(self.doc, self.answer?, path)
    }
}

/// The unit a field's doc names: the first bracketed group (`[km]`, `[N·m]`, `[–]`), if any.
#[must_use]
pub fn unit_of(doc: &str) -> Option<&str> {
    let start = doc.find('[')?;
    let len = doc[start + 1..].find(']')?;
    let unit = doc[start + 1..start + 1 + len].trim();
    // A bracket that holds a sentence or a formula is not a unit.
    (!unit.is_empty() && unit.len() <= 16 && !unit.contains(", ")).then_some(unit)
}

/// Follow `$ref`s to the schema they name.
fn resolve<'a>(doc: &'a Value, mut s: &'a Value) -> &'a Value {
    for _ in 0..16 {
        let Some(r) = s.get("$ref").and_then(Value::as_str) else {
            return s;
        };
        let Some(target) = r.strip_prefix('#').and_then(|p| doc.pointer(p)) else {
            return s;
        };
        s = target;
    }
    s
}

/// The subschemas a value may match (the schema itself, or its `allOf` / `oneOf` / `anyOf` parts).
fn alternatives<'a>(doc: &'a Value, s: &'a Value) -> Vec<&'a Value> {
    let s = resolve(doc, s);
    let mut out = vec![s];
    for key in ["allOf", "oneOf", "anyOf"] {
        if let Some(parts) = s.get(key).and_then(Value::as_array) {
            for p in parts {
                out.extend(alternatives(doc, p));
            }
        }
    }
    out
}

/// The schema of the field at `path` below `s` (first match over the alternatives).
fn field<'a>(doc: &'a Value, s: &'a Value, path: &[&str]) -> Option<&'a Value> {
    let Some((head, rest)) = path.split_first() else {
        return Some(s);
    };
    for alt in alternatives(doc, s) {
        let next = if *head == "*" {
            alt.get("items")
        } else {
            alt.get("properties").and_then(|p| p.get(*head))
        };
        if let Some(found) = next.and_then(|n| field(doc, n, rest)) {
            return Some(found);
        }
    }
    None
}

/// The description at `path` (on the property itself, or on the schema it refers to).
fn description<'a>(doc: &'a Value, root: &'a Value, path: &[&str]) -> Option<&'a str> {
    let f = field(doc, root, path)?;
    f.get("description").and_then(Value::as_str).or_else(|| {
        alternatives(doc, f)
            .into_iter()
            .find_map(|a| a.get("description").and_then(Value::as_str))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_the_first_short_bracket() {
        assert_eq!(unit_of("Distance driven D [km] (achieved)"), Some("km"));
        assert_eq!(unit_of("ratio [–]"), Some("–"));
        assert_eq!(unit_of("no unit"), None);
        assert_eq!(unit_of("a list [a, b, c] of names"), None);
    }
}
