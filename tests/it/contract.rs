//! The published contract tells the truth: every `api/` request validates against its
//! operation's documented request schema, and every answer the service gives to it (the 200 and
//! each problem status the tests provoke) validates against the documented response schema of
//! that status, with a JSON Schema 2020-12 validator (the `jsonschema` crate). Also: no schema
//! name is claimed by two Rust types, every bound comes from a table, and the document served at
//! `/openapi.json` is the one checked here.

use crate::common;

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

pub fn api_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("api")
}

/// The `api/` examples listed in `api/examples.json` as (file, endpoint).
pub fn example_files() -> Vec<(String, String)> {
    let index: Value = serde_json::from_str(
        &std::fs::read_to_string(api_dir().join("examples.json")).expect("api/examples.json"),
    )
    .expect("api/examples.json is JSON");
    index["examples"]
        .as_array()
        .expect("examples array")
        .iter()
        .map(|e| {
            let file = e["file"].as_str().expect("file").to_owned();
            let endpoint = e["endpoint"].as_str().expect("endpoint").to_owned();
            (file, endpoint)
        })
        .collect()
}

/// The `api/` examples as (file, endpoint, request body).
pub fn examples() -> Vec<(String, String, Value)> {
    example_files()
        .into_iter()
        .map(|(file, endpoint)| {
            let body: Value = serde_json::from_str(
                &std::fs::read_to_string(api_dir().join(&file)).expect("example readable"),
            )
            .expect("example is JSON");
            (file, endpoint, body)
        })
        .collect()
}

/// The finished OpenAPI document.
pub fn doc() -> Value {
    mechcalc::http::openapi::document().clone()
}

/// A 2020-12 validator for `schema` (a fragment of the document, `$ref`s into its components).
pub fn validator(doc: &Value, schema: &Value) -> jsonschema::Validator {
    let mut root = schema.clone();
    let obj = root.as_object_mut().expect("schema is an object");
    obj.insert(
        "$schema".to_owned(),
        json!("https://json-schema.org/draft/2020-12/schema"),
    );
    obj.insert("components".to_owned(), doc["components"].clone());
    jsonschema::draft202012::options()
        .build(&root)
        .unwrap_or_else(|e| panic!("the document's schema does not compile: {e}"))
}

/// The request schema of `POST endpoint`.
pub fn request_schema(doc: &Value, endpoint: &str) -> Value {
    let op = &doc["paths"][endpoint]["post"];
    op["requestBody"]["content"]["application/json"]["schema"].clone()
}

/// The response schema of `POST endpoint` for `status` and `content_type`, if documented.
fn response_schema(doc: &Value, endpoint: &str, status: u16, content_type: &str) -> Option<Value> {
    let r = &doc["paths"][endpoint]["post"]["responses"][status.to_string()];
    let s = r["content"][content_type]["schema"].clone();
    (!s.is_null()).then_some(s)
}

/// Every error of `instance` against `schema`, one line each.
pub fn violations(doc: &Value, schema: &Value, instance: &Value) -> Vec<String> {
    validator(doc, schema)
        .iter_errors(instance)
        .map(|e| format!("{}: {e}", e.instance_path()))
        .collect()
}

/// Modules whose wire types are still being moved onto the one-source bounds table (schema-name
/// prefix, and the `api/` folder of their examples). Transitional: the list must end empty.
pub const PENDING_BOUNDS_TABLE: &[&str] = &[];

/// Whether `name` (a schema name or an `api/` file) belongs to a module of [`PENDING_BOUNDS_TABLE`].
pub fn pending(name: &str) -> bool {
    PENDING_BOUNDS_TABLE
        .iter()
        .any(|m| name.starts_with(&format!("{m}.")) || name.starts_with(&format!("{m}/")))
}

#[test]
fn no_schema_name_is_claimed_twice_and_every_bound_comes_from_a_table() {
    let problems: Vec<String> = mechcalc::http::openapi::document_problems()
        .into_iter()
        .filter(|p| !p.contains("literal") || !pending(p.trim_start()))
        .collect();
    assert!(
        problems.is_empty(),
        "OpenAPI problems:\n  {}",
        problems.join("\n  ")
    );
}

#[test]
fn every_example_request_validates_against_its_schema() {
    let doc = doc();
    let mut failures = Vec::new();
    for (file, endpoint, body) in examples() {
        let schema = request_schema(&doc, &endpoint);
        assert!(
            !schema.is_null(),
            "{endpoint} documents no JSON request body"
        );
        for v in violations(&doc, &schema, &body) {
            failures.push(format!("api/{file}: {v}"));
        }
    }
    assert!(
        failures.is_empty(),
        "example requests that the document rejects:\n  {}",
        failures.join("\n  ")
    );
}

/// Sends `body` and checks that the answer's status is documented for the operation and that the
/// body validates against the schema documented for that status and content type.
async fn check_answer(
    doc: &Value,
    endpoint: &str,
    what: &str,
    content_type: Option<&str>,
    body: Vec<u8>,
    failures: &mut Vec<String>,
) -> u16 {
    let r = common::send("POST", endpoint, content_type, body).await;
    let status = r.status.as_u16();
    let ct = r.content_type().split(';').next().unwrap_or("").to_owned();
    let Some(schema) = response_schema(doc, endpoint, status, &ct) else {
        failures.push(format!(
            "{endpoint} ({what}): status {status} with content type `{ct}` is not documented"
        ));
        return status;
    };
    let answer = r.json();
    for v in violations(doc, &schema, &answer) {
        failures.push(format!("{endpoint} ({what}) {status}: {v}"));
    }
    status
}

#[tokio::test]
async fn every_answer_validates_against_its_documented_response() {
    let doc = doc();
    let mut failures = Vec::new();
    for (file, endpoint, body) in examples() {
        let what = format!("api/{file}");
        let bytes = serde_json::to_vec(&body).expect("serializes");
        let ok = check_answer(
            &doc,
            &endpoint,
            &what,
            Some("application/json"),
            bytes.clone(),
            &mut failures,
        )
        .await;
        assert_eq!(ok, 200, "{what} must succeed");
        // 400: truncated JSON.
        let s = check_answer(
            &doc,
            &endpoint,
            &format!("{what} truncated"),
            Some("application/json"),
            bytes[..bytes.len() / 2].to_vec(),
            &mut failures,
        )
        .await;
        assert_eq!(s, 400);
        // 415: wrong content type.
        let s = check_answer(
            &doc,
            &endpoint,
            &format!("{what} as text/plain"),
            Some("text/plain"),
            bytes.clone(),
            &mut failures,
        )
        .await;
        assert_eq!(s, 415);
        // 422: an unknown member.
        let mut unknown = body.clone();
        unknown
            .as_object_mut()
            .expect("requests are objects")
            .insert("no_such_field".to_owned(), json!(1));
        let s = check_answer(
            &doc,
            &endpoint,
            &format!("{what} with an unknown member"),
            Some("application/json"),
            serde_json::to_vec(&unknown).expect("serializes"),
            &mut failures,
        )
        .await;
        assert_eq!(s, 422);
    }
    assert!(
        failures.is_empty(),
        "answers that the document does not describe:\n  {}",
        failures.join("\n  ")
    );
}

#[tokio::test]
async fn the_served_document_is_the_checked_one() {
    let r = common::get("/openapi.json").await;
    assert_eq!(r.status.as_u16(), 200);
    assert_eq!(r.json(), doc());
}

/// serde would read a struct from a JSON array of its fields; the document says object. Every
/// object-valued top-level member of every example, sent as an array, is refused with its pointer.
#[tokio::test]
async fn objects_sent_as_arrays_are_refused() {
    let mut failures = Vec::new();
    for (file, endpoint, body) in examples() {
        let obj = body.as_object().expect("requests are objects");
        for (key, value) in obj {
            let Some(inner) = value.as_object() else {
                continue;
            };
            let mut b = body.clone();
            b[key] = Value::Array(inner.values().cloned().collect());
            let r = common::post_json(&endpoint, &b).await;
            let pointer = format!("/{key}");
            let refused = matches!(r.status.as_u16(), 400 | 422);
            if !refused || !r.pointers().iter().any(|p| p.starts_with(&pointer)) {
                failures.push(format!(
                    "api/{file} {pointer} as an array: {} {:?}",
                    r.status,
                    r.pointers()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
