//! A guard against silent NaN: serde_json writes a non-finite float as `null`, which a client
//! cannot tell from "absent". [`super::encode`] refuses to write any `null`; when one comes, the
//! answer is walked by [`first_non_finite`]: a non-finite number is a bug in a calculation,
//! logged as an error and answered with a 422 `NON_FINITE_ANSWER` naming the number.

use serde::Serialize;
use serde::ser::{self, Impossible};

/// The JSON pointer of the first non-finite float in `value`, if any.
///
/// The common case (every number finite) is one pass that allocates nothing; only when a
/// non-finite number is found is the value walked again, recording the path to it.
pub fn first_non_finite<T: Serialize + ?Sized>(value: &T) -> Option<String> {
    if all_finite(value) {
        return None;
    }
    let mut walker = Walker {
        path: Vec::new(),
        record: true,
        found: None,
    };
    // The walker's only error is "found one"; any other serialization error is ignored here
    // (serde_json reports it when the body is written).
    let _ = value.serialize(&mut walker);
    walker.found.or_else(|| Some(String::new()))
}

/// Whether every float in `value` is finite (no allocation).
pub fn all_finite<T: Serialize + ?Sized>(value: &T) -> bool {
    let mut walker = Walker {
        path: Vec::new(),
        record: false,
        found: None,
    };
    value.serialize(&mut walker).is_ok()
}

struct Walker {
    path: Vec<String>,
    /// Record the path (the slow pass that names the offending number).
    record: bool,
    found: Option<String>,
}

#[derive(Debug)]
struct Found;

impl std::fmt::Display for Found {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("non-finite number")
    }
}
impl std::error::Error for Found {}
impl ser::Error for Found {
    fn custom<T: std::fmt::Display>(_msg: T) -> Self {
        Self
    }
}

impl Walker {
    fn float(&mut self, v: f64) -> Result<(), Found> {
        if v.is_finite() {
            Ok(())
        } else {
            if self.record {
                self.found = Some(self.path.iter().map(|p| format!("/{p}")).collect());
            }
            Err(Found)
        }
    }
    /// Walk `value` under the path segment `key` (built only when the path is recorded).
    fn nested<T: Serialize + ?Sized>(
        &mut self,
        key: impl FnOnce() -> String,
        value: &T,
    ) -> Result<(), Found> {
        if !self.record {
            return value.serialize(&mut *self);
        }
        self.path.push(key());
        let r = value.serialize(&mut *self);
        self.path.pop();
        r
    }
}

struct Seq<'a> {
    w: &'a mut Walker,
    index: usize,
}
struct Map<'a> {
    w: &'a mut Walker,
    key: String,
}

macro_rules! ok_scalars {
    ($($name:ident: $t:ty),*) => { $(fn $name(self, _v: $t) -> Result<(), Found> { Ok(()) })* };
}

impl<'a> ser::Serializer for &'a mut Walker {
    type Ok = ();
    type Error = Found;
    type SerializeSeq = Seq<'a>;
    type SerializeTuple = Seq<'a>;
    type SerializeTupleStruct = Seq<'a>;
    type SerializeTupleVariant = Seq<'a>;
    type SerializeMap = Map<'a>;
    type SerializeStruct = Map<'a>;
    type SerializeStructVariant = Map<'a>;

    ok_scalars!(serialize_bool: bool, serialize_i8: i8, serialize_i16: i16, serialize_i32: i32,
        serialize_i64: i64, serialize_u8: u8, serialize_u16: u16, serialize_u32: u32,
        serialize_u64: u64, serialize_char: char, serialize_str: &str, serialize_bytes: &[u8]);

    fn serialize_f32(self, v: f32) -> Result<(), Found> {
        self.float(f64::from(v))
    }
    fn serialize_f64(self, v: f64) -> Result<(), Found> {
        self.float(v)
    }
    fn serialize_none(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_variant(
        self,
        _n: &'static str,
        _i: u32,
        _v: &'static str,
    ) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _n: &'static str,
        value: &T,
    ) -> Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _n: &'static str,
        _i: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Found> {
        self.nested(|| variant.to_owned(), value)
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Seq<'a>, Found> {
        Ok(Seq { w: self, index: 0 })
    }
    fn serialize_tuple(self, _len: usize) -> Result<Seq<'a>, Found> {
        Ok(Seq { w: self, index: 0 })
    }
    fn serialize_tuple_struct(self, _n: &'static str, _len: usize) -> Result<Seq<'a>, Found> {
        Ok(Seq { w: self, index: 0 })
    }
    fn serialize_tuple_variant(
        self,
        _n: &'static str,
        _i: u32,
        _v: &'static str,
        _len: usize,
    ) -> Result<Seq<'a>, Found> {
        Ok(Seq { w: self, index: 0 })
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<Map<'a>, Found> {
        Ok(Map {
            w: self,
            key: String::new(),
        })
    }
    fn serialize_struct(self, _n: &'static str, _len: usize) -> Result<Map<'a>, Found> {
        Ok(Map {
            w: self,
            key: String::new(),
        })
    }
    fn serialize_struct_variant(
        self,
        _n: &'static str,
        _i: u32,
        _v: &'static str,
        _len: usize,
    ) -> Result<Map<'a>, Found> {
        Ok(Map {
            w: self,
            key: String::new(),
        })
    }
}

impl Seq<'_> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
        let index = self.index;
        self.index += 1;
        self.w.nested(|| index.to_string(), value)
    }
}

/// The sequence-like serializer traits of [`Seq`]: `$method` (each element or field) walks into
/// the next index.
macro_rules! seq_impls {
    ($($tr:ident: $method:ident),*) => {$(
        impl ser::$tr for Seq<'_> {
            type Ok = ();
            type Error = Found;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
                self.element(value)
            }
            fn end(self) -> Result<(), Found> {
                Ok(())
            }
        }
    )*};
}

seq_impls!(
    SerializeSeq: serialize_element,
    SerializeTuple: serialize_element,
    SerializeTupleStruct: serialize_field,
    SerializeTupleVariant: serialize_field
);

/// Renders map keys (strings or integers) as pointer tokens.
struct KeyText;

impl ser::Serializer for KeyText {
    type Ok = String;
    type Error = Found;
    type SerializeSeq = Impossible<String, Found>;
    type SerializeTuple = Impossible<String, Found>;
    type SerializeTupleStruct = Impossible<String, Found>;
    type SerializeTupleVariant = Impossible<String, Found>;
    type SerializeMap = Impossible<String, Found>;
    type SerializeStruct = Impossible<String, Found>;
    type SerializeStructVariant = Impossible<String, Found>;
    fn serialize_str(self, v: &str) -> Result<String, Found> {
        Ok(v.to_owned())
    }
    fn serialize_bool(self, v: bool) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i8(self, v: i8) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i16(self, v: i16) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i32(self, v: i32) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_i64(self, v: i64) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u8(self, v: u8) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u16(self, v: u16) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u32(self, v: u32) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_u64(self, v: u64) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_f32(self, v: f32) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_f64(self, v: f64) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_char(self, v: char) -> Result<String, Found> {
        Ok(v.to_string())
    }
    fn serialize_bytes(self, _v: &[u8]) -> Result<String, Found> {
        Ok(String::from("?"))
    }
    fn serialize_none(self) -> Result<String, Found> {
        Ok(String::from("null"))
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<String, Found> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<String, Found> {
        Ok(String::from("null"))
    }
    fn serialize_unit_struct(self, name: &'static str) -> Result<String, Found> {
        Ok(name.to_owned())
    }
    fn serialize_unit_variant(
        self,
        _n: &'static str,
        _i: u32,
        v: &'static str,
    ) -> Result<String, Found> {
        Ok(v.to_owned())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _n: &'static str,
        value: &T,
    ) -> Result<String, Found> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _n: &'static str,
        _i: u32,
        v: &'static str,
        _value: &T,
    ) -> Result<String, Found> {
        Ok(v.to_owned())
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Self::SerializeSeq, Found> {
        Err(Found)
    }
    fn serialize_tuple(self, _len: usize) -> Result<Self::SerializeTuple, Found> {
        Err(Found)
    }
    fn serialize_tuple_struct(
        self,
        _n: &'static str,
        _l: usize,
    ) -> Result<Self::SerializeTupleStruct, Found> {
        Err(Found)
    }
    fn serialize_tuple_variant(
        self,
        _n: &'static str,
        _i: u32,
        _v: &'static str,
        _l: usize,
    ) -> Result<Self::SerializeTupleVariant, Found> {
        Err(Found)
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<Self::SerializeMap, Found> {
        Err(Found)
    }
    fn serialize_struct(self, _n: &'static str, _l: usize) -> Result<Self::SerializeStruct, Found> {
        Err(Found)
    }
    fn serialize_struct_variant(
        self,
        _n: &'static str,
        _i: u32,
        _v: &'static str,
        _l: usize,
    ) -> Result<Self::SerializeStructVariant, Found> {
        Err(Found)
    }
}

impl ser::SerializeMap for Map<'_> {
    type Ok = ();
    type Error = Found;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Found> {
        if self.w.record {
            self.key = key.serialize(KeyText).unwrap_or_else(|_| String::from("?"));
        }
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
        let key = std::mem::take(&mut self.key);
        self.w.nested(|| key, value)
    }
    fn end(self) -> Result<(), Found> {
        Ok(())
    }
}
/// The struct serializer traits of [`Map`]: each field walks into its name.
macro_rules! struct_impls {
    ($($tr:ident),*) => {$(
        impl ser::$tr for Map<'_> {
            type Ok = ();
            type Error = Found;
            fn serialize_field<T: Serialize + ?Sized>(
                &mut self,
                key: &'static str,
                value: &T,
            ) -> Result<(), Found> {
                self.w.nested(|| key.to_owned(), value)
            }
            fn end(self) -> Result<(), Found> {
                Ok(())
            }
        }
    )*};
}

struct_impls!(SerializeStruct, SerializeStructVariant);

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[derive(Serialize)]
    struct Inner {
        x: Vec<f64>,
        y: Option<f64>,
    }
    #[derive(Serialize)]
    struct Outer {
        name: &'static str,
        inner: Vec<Inner>,
        map: BTreeMap<String, f64>,
    }

    #[test]
    fn finds_nan_with_pointer() {
        let v = Outer {
            name: "a",
            inner: vec![
                Inner {
                    x: vec![1.0],
                    y: None,
                },
                Inner {
                    x: vec![0.0, f64::NAN],
                    y: Some(1.0),
                },
            ],
            map: BTreeMap::new(),
        };
        assert_eq!(first_non_finite(&v).as_deref(), Some("/inner/1/x/1"));
    }

    #[test]
    fn finds_infinity_in_map_and_option() {
        let mut map = BTreeMap::new();
        map.insert("k".to_owned(), f64::INFINITY);
        let v = Outer {
            name: "a",
            inner: vec![],
            map,
        };
        assert_eq!(first_non_finite(&v).as_deref(), Some("/map/k"));
        let w = Inner {
            x: vec![],
            y: Some(f64::NEG_INFINITY),
        };
        assert_eq!(first_non_finite(&w).as_deref(), Some("/y"));
    }

    #[test]
    fn clean_value_passes() {
        let v = Inner {
            x: vec![1.0, -2.5, 0.0],
            y: Some(3.0),
        };
        assert_eq!(first_non_finite(&v), None);
    }
}
