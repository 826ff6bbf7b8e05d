//! The published contract tells the truth: every `api/` request validates against its
//! operation's documented request schema, and every answer the service gives to it (the 200 and
//! each problem status the tests provoke) validates against the documented response schema of
//! that status, with a JSON Schema 2020-12 validator (the `jsonschema` crate). Also: no schema
//! name is claimed by two Rust types, every bound comes from a table, and the document served at
//! `/openapi.json` is the one checked here. And what a generated client relies on: `null` for an
//! optional field is the same as leaving it out, at every depth; every operation lists the rules
//! between fields its schema-valid requests can break (`x-cross-field-rules`).

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

#[test]
fn no_schema_name_is_claimed_twice_and_every_rule_comes_from_its_declaration() {
    let problems: Vec<String> = mechcalc::http::openapi::document_problems();
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

/// Status, problem type and pointers of an answer.
#[derive(Debug)]
struct Answer {
    status: u16,
    pointers: Vec<String>,
}

async fn post(endpoint: &str, body: &Value) -> Answer {
    let r = common::post_json(endpoint, body).await;
    let status = r.status.as_u16();
    let pointers = if status == 200 {
        Vec::new()
    } else {
        r.pointers()
    };
    Answer { status, pointers }
}

fn resolve<'a>(doc: &'a Value, s: &'a Value) -> &'a Value {
    let mut s = s;
    for _ in 0..32 {
        match s.get("$ref").and_then(Value::as_str) {
            Some(r) => {
                s = doc
                    .pointer(r.trim_start_matches('#'))
                    .unwrap_or_else(|| panic!("dangling $ref {r}"));
            }
            None => return s,
        }
    }
    s
}

/// The variant of a `oneOf` that `instance` matches (by discriminator, else by validation).
fn pick_variant<'a>(doc: &'a Value, s: &'a Value, instance: &Value) -> Option<&'a Value> {
    let variants = s.get("oneOf")?.as_array()?;
    if let Some(tag) = s
        .pointer("/discriminator/propertyName")
        .and_then(Value::as_str)
    {
        let v = instance.get(tag)?.as_str()?;
        let r = s
            .pointer(&format!("/discriminator/mapping/{v}"))?
            .as_str()?;
        return doc.pointer(r.trim_start_matches('#'));
    }
    variants
        .iter()
        .find(|v| violations(doc, v, instance).is_empty())
}

/// The wire convention's `time_limit_ms` is accepted at the top level of every operation's
/// request, documented there with the shared bound [1, 600 000] ms, and enforced: 0 and 600 001
/// are 422 naming `/time_limit_ms`, the bound's ends are answered like the example itself.
#[tokio::test]
async fn every_operation_takes_the_top_level_time_limit() {
    let doc = doc();
    let mut failures = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for (file, endpoint, body) in examples() {
        if !seen.insert(endpoint.clone()) {
            continue;
        }
        let schema = resolve(&doc, &request_schema(&doc, &endpoint)).clone();
        let prop = resolve(&doc, &schema["properties"]["time_limit_ms"]);
        if prop["minimum"] != json!(1) || prop["maximum"] != json!(600_000) {
            failures.push(format!(
                "{endpoint}: time_limit_ms documented as {prop} (want minimum 1, maximum 600000)"
            ));
        }
        let base = post(&endpoint, &body).await.status;
        for (ms, want_rejected) in [(0u64, true), (600_001, true), (1, false), (600_000, false)] {
            let mut b = body.clone();
            b["time_limit_ms"] = json!(ms);
            let a = post(&endpoint, &b).await;
            let named = a.pointers.iter().any(|p| p == "/time_limit_ms");
            if want_rejected && !(a.status == 422 && named) {
                failures.push(format!(
                    "api/{file}: time_limit_ms = {ms} answered {} (pointers {:?}), want 422 at \
                     /time_limit_ms",
                    a.status, a.pointers
                ));
            }
            // 1 ms may legitimately run out on a heavy example (a 422 deadline answer); it must
            // never be rejected as an invalid time_limit_ms.
            if !want_rejected && (named || (ms == 600_000 && a.status != base)) {
                failures.push(format!(
                    "api/{file}: time_limit_ms = {ms} answered {} (pointers {:?}), the example \
                     alone {base}",
                    a.status, a.pointers
                ));
            }
        }
    }
    let posts = doc["paths"]
        .as_object()
        .expect("paths")
        .iter()
        .filter(|(_, item)| item.get("post").is_some())
        .count();
    assert_eq!(
        seen.len(),
        posts,
        "every POST operation has an api/ example (seen {seen:?})"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The request with `null` for every optional property the instance leaves out, at every depth
/// (objects inside lists and inside the chosen `oneOf` alternative too): what a client generated
/// from the document sends.
fn with_nulls(doc: &Value, schema: &Value, instance: &Value) -> Value {
    let s = resolve(doc, schema);
    // A `oneOf` beside `properties` is a constraint (exactly one of two fields), not alternatives.
    if s.get("properties").is_none()
        && let Some(v) = pick_variant(doc, s, instance)
    {
        return with_nulls(doc, v, instance);
    }
    match instance {
        Value::Object(obj) => {
            let mut out = obj.clone();
            if let Some(props) = s.get("properties").and_then(Value::as_object) {
                let required: Vec<&str> = s
                    .get("required")
                    .and_then(Value::as_array)
                    .map(|r| r.iter().filter_map(Value::as_str).collect())
                    .unwrap_or_default();
                for (name, ps) in props {
                    match obj.get(name) {
                        Some(v) => {
                            out.insert(name.clone(), with_nulls(doc, ps, v));
                        }
                        None if !required.contains(&name.as_str()) => {
                            out.insert(name.clone(), Value::Null);
                        }
                        None => {}
                    }
                }
            }
            Value::Object(out)
        }
        Value::Array(items) => match s.get("items") {
            Some(is) => Value::Array(items.iter().map(|x| with_nulls(doc, is, x)).collect()),
            None => instance.clone(),
        },
        _ => instance.clone(),
    }
}

/// The answer fields that hold wall-clock or CPU times (they differ from run to run).
pub const TIMING_KEYS: &[&str] = &[
    "elapsed_ms",
    "elapsed_s",
    "cpu_ms",
    "wall_ms",
    "compute_ms",
    "compute_us",
    "timing_ms",
];

/// An answer without what differs from run to run (wall-clock times).
fn without_timing(v: &Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| !TIMING_KEYS.contains(&k.as_str()))
                .map(|(k, x)| (k.clone(), without_timing(x)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(without_timing).collect()),
        _ => v.clone(),
    }
}

/// A generated client sends `null` for every optional field it does not set: each `api/` example
/// so completed is accepted and answered exactly like the example itself (timings aside).
#[tokio::test]
async fn null_is_absent_for_every_optional_field_at_every_depth() {
    let doc = doc();
    let mut failures = Vec::new();
    for (file, endpoint, body) in examples() {
        let schema = request_schema(&doc, &endpoint);
        let nulls = with_nulls(&doc, &schema, &body);
        assert_ne!(nulls, body, "api/{file}: some optional field is left out");
        for v in violations(&doc, &schema, &nulls) {
            failures.push(format!(
                "api/{file} with nulls: the document refuses it: {v}"
            ));
        }
        let plain = common::post_json(&endpoint, &body).await;
        let filled = common::post_json(&endpoint, &nulls).await;
        if filled.status != plain.status {
            failures.push(format!(
                "api/{file}: with nulls {} {}, plain {}",
                filled.status,
                filled.json(),
                plain.status
            ));
        } else if without_timing(&filled.json()) != without_timing(&plain.json()) {
            failures.push(format!("api/{file}: the answer changes with nulls"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Every operation lists its rules between fields under `x-cross-field-rules`: each with a code
/// of its own or of its spec (never the generic `INVALID_INPUT`), the fields it relates and one
/// sentence.
#[test]
fn every_operation_lists_its_cross_field_rules() {
    let doc = doc();
    let mut failures = Vec::new();
    for (route, item) in doc["paths"].as_object().expect("paths") {
        let Some(op) = item.get("post") else { continue };
        let Some(rules) = op.get("x-cross-field-rules").and_then(Value::as_array) else {
            failures.push(format!("{route}: no x-cross-field-rules"));
            continue;
        };
        // A spec may give several rules one code (IREFC's BAD_RANGE); each rule is listed once.
        let mut codes = std::collections::BTreeSet::new();
        let mut seen = std::collections::BTreeSet::new();
        for r in rules {
            let code = r["code"].as_str().unwrap_or("");
            codes.insert(code.to_owned());
            if code.is_empty() || code == "INVALID_INPUT" || !seen.insert(r.to_string()) {
                failures.push(format!(
                    "{route}: rule code `{code}` is empty, generic or repeated"
                ));
            }
            if !r["pointers"].is_array() || r["rule"].as_str().is_none_or(str::is_empty) {
                failures.push(format!("{route}: rule {code} lacks pointers or a sentence"));
            }
        }
        if !codes.contains("RESPONSE_TOO_LARGE") {
            failures.push(format!("{route}: RESPONSE_TOO_LARGE is not listed"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
