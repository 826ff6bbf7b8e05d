//! The JSON tree of a model document, read straight from the request's bytes. Like
//! `serde_json::Value` (same numbers, same key order, a later duplicate key replacing the
//! earlier one) but an array holding only integers or only non-integer numbers is stored flat
//! (8 bytes per element instead of 32 and no allocation per element): the node arrays of a
//! model, which are nearly all of its bytes, cost about a quarter of the memory of a `Value`
//! tree, so a large model raises the service's memory by a small multiple of its JSON size.

use std::fmt;

use indexmap::IndexMap;
use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{Serialize, SerializeSeq, Serializer};
use serde_json::Number;

/// A JSON value of a model document.
#[derive(Debug, Clone, PartialEq)]
pub enum Doc {
    /// `null`.
    Null,
    /// `true` / `false`.
    Bool(bool),
    /// A number, exactly as `serde_json::Value` holds it.
    Number(Number),
    /// A string.
    String(String),
    /// An array of integers, each representable as `i64` (written as integers in the JSON).
    Ints(Vec<i64>),
    /// An array of numbers written with a fraction or an exponent (not integers in the JSON).
    Floats(Vec<f64>),
    /// Any other array.
    Array(Vec<Doc>),
    /// An object, in document order.
    Object(IndexMap<String, Doc>),
}

impl Doc {
    /// The object's members, if this is an object.
    #[must_use]
    pub const fn as_object(&self) -> Option<&IndexMap<String, Self>> {
        match self {
            Self::Object(o) => Some(o),
            _ => None,
        }
    }

    /// What kind of JSON value this is ("an array", ...), for messages.
    #[must_use]
    pub const fn kind(&self) -> &'static str {
        match self {
            Self::Null => "null",
            Self::Bool(_) => "a boolean",
            Self::Number(_) => "a number",
            Self::String(_) => "a string",
            Self::Ints(_) | Self::Floats(_) | Self::Array(_) => "an array",
            Self::Object(_) => "an object",
        }
    }

    /// The number of elements, if this is an array.
    #[must_use]
    pub fn array_len(&self) -> Option<usize> {
        match self {
            Self::Ints(v) => Some(v.len()),
            Self::Floats(v) => Some(v.len()),
            Self::Array(v) => Some(v.len()),
            _ => None,
        }
    }

    /// Element `i` of an array as a value of its own (a number of a flat array is rebuilt).
    #[must_use]
    pub fn item(&self, i: usize) -> Option<Item<'_>> {
        match self {
            Self::Ints(v) => v.get(i).map(|&x| Item::Number(Number::from(x))),
            Self::Floats(v) => v
                .get(i)
                .and_then(|&x| Number::from_f64(x))
                .map(Item::Number),
            Self::Array(v) => v.get(i).map(Item::Doc),
            _ => None,
        }
    }
}

/// One element of an array: a value of the tree, or a number of a flat array.
#[derive(Debug, Clone, PartialEq)]
pub enum Item<'a> {
    /// An element of a general array.
    Doc(&'a Doc),
    /// A number of a flat array.
    Number(Number),
}

impl Item<'_> {
    /// The number, if it is one.
    #[must_use]
    pub fn number(&self) -> Option<&Number> {
        match self {
            Self::Doc(Doc::Number(n)) | Self::Number(n) => Some(n),
            Self::Doc(_) => None,
        }
    }

    /// The value, if it is a value of the tree.
    #[must_use]
    pub const fn doc(&self) -> Option<&Doc> {
        match self {
            Self::Doc(d) => Some(d),
            Self::Number(_) => None,
        }
    }
}

impl fmt::Display for Item<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Doc(d) => d.fmt(f),
            Self::Number(n) => n.fmt(f),
        }
    }
}

/// The value as compact JSON text (what `serde_json::Value` displays).
impl fmt::Display for Doc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = serde_json::to_string(self).map_err(|_| fmt::Error)?;
        f.write_str(&s)
    }
}

impl Serialize for Doc {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Self::Null => s.serialize_unit(),
            Self::Bool(b) => s.serialize_bool(*b),
            Self::Number(n) => n.serialize(s),
            Self::String(x) => s.serialize_str(x),
            Self::Ints(v) => v.serialize(s),
            Self::Floats(v) => v.serialize(s),
            Self::Array(v) => {
                let mut seq = s.serialize_seq(Some(v.len()))?;
                for x in v {
                    seq.serialize_element(x)?;
                }
                seq.end()
            }
            Self::Object(o) => s.collect_map(o),
        }
    }
}

impl<'de> Deserialize<'de> for Doc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(DocVisitor)
    }
}

struct DocVisitor;

/// An array being read: flat while every element fits, general from the first that does not.
enum Building {
    Ints(Vec<i64>),
    Floats(Vec<f64>),
    General(Vec<Doc>),
}

impl Building {
    fn push(&mut self, x: Doc) {
        match (&mut *self, x) {
            (Self::Ints(v), Doc::Number(n)) if n.is_i64() => {
                v.push(n.as_i64().unwrap_or_default());
            }
            (Self::Floats(v), Doc::Number(n)) if n.is_f64() => {
                v.push(n.as_f64().unwrap_or_default());
            }
            (Self::General(v), x) => v.push(x),
            (_, x) => {
                let mut general = self.take_general();
                general.push(x);
                *self = Self::General(general);
            }
        }
    }

    fn take_general(&mut self) -> Vec<Doc> {
        match std::mem::replace(self, Self::General(Vec::new())) {
            Self::Ints(v) => v.into_iter().map(|x| Doc::Number(x.into())).collect(),
            Self::Floats(v) => v
                .into_iter()
                .filter_map(Number::from_f64)
                .map(Doc::Number)
                .collect(),
            Self::General(v) => v,
        }
    }

    fn finish(self) -> Doc {
        match self {
            Self::Ints(v) => Doc::Ints(v),
            Self::Floats(v) => Doc::Floats(v),
            Self::General(v) => Doc::Array(v),
        }
    }
}

impl<'de> Visitor<'de> for DocVisitor {
    type Value = Doc;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, b: bool) -> Result<Doc, E> {
        Ok(Doc::Bool(b))
    }

    fn visit_i64<E>(self, x: i64) -> Result<Doc, E> {
        Ok(Doc::Number(x.into()))
    }

    fn visit_u64<E>(self, x: u64) -> Result<Doc, E> {
        Ok(Doc::Number(x.into()))
    }

    fn visit_f64<E>(self, x: f64) -> Result<Doc, E> {
        Ok(Number::from_f64(x).map_or(Doc::Null, Doc::Number))
    }

    fn visit_str<E: de::Error>(self, s: &str) -> Result<Doc, E> {
        Ok(Doc::String(s.to_owned()))
    }

    fn visit_string<E>(self, s: String) -> Result<Doc, E> {
        Ok(Doc::String(s))
    }

    fn visit_none<E>(self) -> Result<Doc, E> {
        Ok(Doc::Null)
    }

    fn visit_unit<E>(self) -> Result<Doc, E> {
        Ok(Doc::Null)
    }

    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Doc, D::Error> {
        Doc::deserialize(d)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Doc, A::Error> {
        let Some(first) = seq.next_element::<Doc>()? else {
            return Ok(Doc::Ints(Vec::new()));
        };
        let cap = seq.size_hint().unwrap_or(0).min(4096) + 1;
        let mut b = match first {
            Doc::Number(n) if n.is_i64() => {
                let mut v = Vec::with_capacity(cap);
                v.push(n.as_i64().unwrap_or_default());
                Building::Ints(v)
            }
            Doc::Number(n) if n.is_f64() => {
                let mut v = Vec::with_capacity(cap);
                v.push(n.as_f64().unwrap_or_default());
                Building::Floats(v)
            }
            x => Building::General(vec![x]),
        };
        while let Some(x) = seq.next_element::<Doc>()? {
            b.push(x);
        }
        Ok(b.finish())
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Doc, A::Error> {
        let mut o = IndexMap::new();
        while let Some((k, v)) = map.next_entry::<String, Doc>()? {
            o.insert(k, v);
        }
        Ok(Doc::Object(o))
    }
}

impl crate::calc::rules::Rules for Doc {
    const LEAF: bool = true;
    fn check_rules(&self, _at: crate::calc::rules::At<'_>, _v: &mut crate::calc::Validator) {}
    fn document_rules(_out: &mut crate::calc::rules::DocRules) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{Value, json};

    /// Reads `text` both ways: the tree is flat where it can be and writes back the same JSON
    /// as `serde_json::Value`.
    fn both(text: &str) -> (Doc, Value) {
        let d: Doc = serde_json::from_str(text).expect("doc");
        let v: Value = serde_json::from_str(text).expect("value");
        assert_eq!(
            serde_json::to_string(&d).ok(),
            serde_json::to_string(&v).ok(),
            "{text}"
        );
        assert_eq!(d.to_string(), v.to_string());
        (d, v)
    }

    #[test]
    fn same_json_as_value() {
        for text in [
            r#"{"b": [1, -2, 3], "a": [0.5, 1e-7, -3.25E2], "c": [1, 2.5, "x", null, true]}"#,
            r#"{"k": 1, "k": [2]}"#,
            r#"[[1, 2], [0.5], [], {"x": {}}]"#,
            r#"[18446744073709551615, 1]"#,
            r#"[-0.0, 0, -0]"#,
            r#"{"s": "é\n", "n": null, "t": false}"#,
        ] {
            both(text);
        }
    }

    #[test]
    fn number_arrays_are_flat_and_items_match_value() {
        let (d, v) = both(r#"{"i": [1, -2, 3], "f": [0.5, 2.0, 1e300], "m": [1, 0.5]}"#);
        let o = d.as_object().expect("object");
        assert!(matches!(o["i"], Doc::Ints(_)));
        assert!(matches!(o["f"], Doc::Floats(_)));
        assert!(matches!(o["m"], Doc::Array(_)));
        for k in ["i", "f", "m"] {
            let items = v[k].as_array().expect("array");
            assert_eq!(o[k].array_len(), Some(items.len()));
            for (i, x) in items.iter().enumerate() {
                let it = o[k].item(i).expect("item");
                assert_eq!(it.number(), x.as_number(), "{k}/{i}");
                assert_eq!(it.to_string(), x.to_string());
            }
        }
        assert_eq!(o["i"].item(3), None);
        assert_eq!(json!({"k": 1}).to_string(), r#"{"k":1}"#);
    }
}
