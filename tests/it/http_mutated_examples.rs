//! Stress over HTTP: every `api/` example is mutated (numbers pushed to 0, ±1e300 and 1e-300,
//! fields removed, strings replaced, arrays emptied) and sent to the router. Whatever the module,
//! the answer must be a 200 with finite numbers or a 4xx problem+json: never a 500.

use crate::common;

use std::path::Path;

use mechcalc::AppState;
use mechcalc::config::ServiceConfig;
use serde_json::Value;

/// Leaves mutated per example (spread over the document by a fixed stride).
const MAX_LEAVES: usize = 24;
/// Each mutated request runs with at most this budget, so heavy examples stay cheap.
const BUDGET_MS: u64 = 200;

fn leaf_pointers(v: &Value, path: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                leaf_pointers(x, format!("{path}/{k}"), out);
            }
        }
        Value::Array(a) => {
            out.push(path.clone());
            for (i, x) in a.iter().enumerate().take(3) {
                leaf_pointers(x, format!("{path}/{i}"), out);
            }
        }
        _ => out.push(path),
    }
}

fn mutations(original: &Value, pointer: &str) -> Vec<Value> {
    let Some(target) = original.pointer(pointer) else {
        return Vec::new();
    };
    let replacements: Vec<Value> = match target {
        Value::Number(_) => vec![
            0.0.into(),
            (-1e300).into(),
            1e300.into(),
            1e-300.into(),
            (-1.0).into(),
        ],
        Value::String(_) => vec!["bogus".into(), "".into()],
        Value::Bool(b) => vec![(!b).into()],
        Value::Array(_) => vec![Value::Array(Vec::new())],
        _ => vec![Value::Null],
    };
    let mut out = Vec::new();
    for r in replacements {
        let mut v = original.clone();
        if let Some(slot) = v.pointer_mut(pointer) {
            *slot = r;
            out.push(v);
        }
    }
    // Removing the field (objects only).
    if let Some((parent, key)) = pointer.rsplit_once('/') {
        let mut v = original.clone();
        if let Some(Value::Object(m)) = v.pointer_mut(parent) {
            m.remove(key);
            out.push(v);
        }
    }
    out
}

#[tokio::test]
async fn mutated_examples_never_give_500() {
    let api = Path::new(env!("CARGO_MANIFEST_DIR")).join("api");
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(api.join("examples.json")).expect("index"))
            .expect("json");
    let config = ServiceConfig {
        max_time_budget_ms: BUDGET_MS,
        compute_slots: 2,
        queue_depth: 64,
        ..ServiceConfig::default()
    };
    // One app for every mutated request (sent one after another): building the router per
    // request cost more than most of the answers.
    let router = mechcalc::app(AppState::new(config));
    let mut failures = Vec::new();
    let mut sent = 0usize;
    for e in index["examples"].as_array().expect("examples") {
        let file = e["file"].as_str().expect("file");
        let endpoint = e["endpoint"].as_str().expect("endpoint");
        let original: Value =
            serde_json::from_slice(&std::fs::read(api.join(file)).expect("example"))
                .expect("example is JSON");
        let mut leaves = Vec::new();
        leaf_pointers(&original, String::new(), &mut leaves);
        let stride = leaves.len().div_ceil(MAX_LEAVES).max(1);
        for pointer in leaves.iter().step_by(stride) {
            for body in mutations(&original, pointer) {
                sent += 1;
                let r = common::post_json_via(router.clone(), endpoint, &body).await;
                let status = r.status.as_u16();
                let ok = match status {
                    // JSON text has no NaN: a non-finite number in an answer is the service's
                    // logged 500 (src/http/finite.rs), which fails below.
                    200 => r.content_type() == "application/json" && r.json().is_object(),
                    400 | 413 | 422 => r.content_type() == "application/problem+json",
                    _ => false,
                };
                if !ok {
                    failures.push(format!(
                        "{file} {pointer}: status {status}: {}",
                        String::from_utf8_lossy(&r.bytes)
                            .chars()
                            .take(300)
                            .collect::<String>()
                    ));
                }
            }
        }
    }
    assert!(sent > 0, "no mutated request was sent");
    assert!(
        failures.is_empty(),
        "{} of {sent} mutated requests failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
