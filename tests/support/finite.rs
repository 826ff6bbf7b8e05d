//! "No silent NaN" in the tests: the same walker the service runs over every response
//! (`mechcalc::http::finite`), for typed responses, plus the JSON form for answers received over
//! HTTP (where serde_json has already written a non-finite number as `null`).

use serde::Serialize;
use serde_json::Value;

/// Panics with the JSON pointer of the first non-finite number of a typed response.
pub fn assert_finite<T: Serialize + ?Sized>(value: &T) {
    if let Some(p) = mechcalc::http::finite::first_non_finite(value) {
        panic!("non-finite number at {p}");
    }
}

/// The JSON pointer of the first `null` or non-finite number in a JSON answer whose key is not in
/// `nullable` (keys that the contract documents as possibly null).
pub fn first_null_or_non_finite(v: &Value, nullable: &[&str]) -> Option<String> {
    first_null_or_non_finite_where(v, |key, _| nullable.contains(&key))
}

/// The JSON pointer of the first non-finite number, or of the first `null` for which
/// `may_be_null(key, pointer)` is false (`key`: the nearest object key above the value).
pub fn first_null_or_non_finite_where(
    v: &Value,
    may_be_null: impl Fn(&str, &str) -> bool,
) -> Option<String> {
    fn walk(
        v: &Value,
        key: &str,
        path: &str,
        may_be_null: &dyn Fn(&str, &str) -> bool,
    ) -> Option<String> {
        match v {
            Value::Null => (!may_be_null(key, path)).then(|| path.to_owned()),
            Value::Number(n) => (!n.as_f64().is_some_and(f64::is_finite)).then(|| path.to_owned()),
            Value::Array(a) => a
                .iter()
                .enumerate()
                .find_map(|(i, x)| walk(x, key, &format!("{path}/{i}"), may_be_null)),
            Value::Object(o) => o
                .iter()
                .find_map(|(k, x)| walk(x, k, &format!("{path}/{k}"), may_be_null)),
            Value::Bool(_) | Value::String(_) => None,
        }
    }
    walk(v, "", "", &may_be_null)
}

/// Whether every number of a JSON answer is finite and nothing is `null`.
pub fn all_numbers_finite(v: &Value) -> bool {
    first_null_or_non_finite(v, &[]).is_none()
}
