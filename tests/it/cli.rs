//! `mechcalc run`: the command line gives the HTTP answer for every `api/` example (timings
//! aside), problem details on stderr with exit code 2 for a refused request, and NDJSON batches
//! in input order.

use crate::common;
use crate::contract::examples;

use std::io::Write;
use std::process::{Command, Output, Stdio};

use serde_json::Value;

fn mechcalc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mechcalc"))
}

/// Runs the CLI with `args`, writes `input` to its stdin and waits for it to exit.
fn run_with_stdin(args: &[&str], input: &[u8]) -> Output {
    let mut child = mechcalc()
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(input)
        .expect("write");
    child.wait_with_output().expect("exits")
}

/// Wall-clock measurements differ between two runs of the same request.
fn is_timing(key: &str) -> bool {
    ["elapsed", "compute_", "wall_", "cpu_", "timing"]
        .iter()
        .any(|p| key.starts_with(p) || key.contains(&format!("_{p}")))
        && (key.ends_with("_ms") || key.ends_with("_us") || key.ends_with("_s"))
}

/// `a` equals `b` except timing fields.
fn same_answer(a: &Value, b: &Value, path: &str, diffs: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, va) in x {
                if is_timing(k) {
                    continue;
                }
                match y.get(k) {
                    Some(vb) => same_answer(va, vb, &format!("{path}/{k}"), diffs),
                    None => diffs.push(format!("{path}/{k} missing")),
                }
            }
            if x.len() != y.len() {
                diffs.push(format!("{path}: {} vs {} members", x.len(), y.len()));
            }
        }
        (Value::Array(x), Value::Array(y)) => {
            if x.len() != y.len() {
                diffs.push(format!("{path}: {} vs {} items", x.len(), y.len()));
            }
            for (i, (va, vb)) in x.iter().zip(y).enumerate() {
                same_answer(va, vb, &format!("{path}/{i}"), diffs);
            }
        }
        _ if a == b => {}
        _ => diffs.push(format!("{path}: {a} vs {b}")),
    }
}

#[tokio::test]
async fn run_gives_the_http_answer_for_every_example() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api");
    let mut failures = Vec::new();
    for (file, endpoint, body) in examples() {
        let out = mechcalc()
            .args(["run", &endpoint, &dir.join(&file).to_string_lossy()])
            .output()
            .expect("the binary runs");
        assert!(
            out.status.success(),
            "api/{file}: exit {:?}: {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        let cli: Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
        let http = common::post_json(&endpoint, &body).await.json();
        let mut diffs = Vec::new();
        same_answer(&cli, &http, "", &mut diffs);
        if !diffs.is_empty() {
            failures.push(format!("api/{file}: {diffs:?}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn a_refused_request_is_problem_details_on_stderr_and_exit_2() {
    let out = run_with_stdin(
        &["run", "cam-law/evaluate", "-"],
        br#"{"coefficients": [1, 2]}"#,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let p: Value = serde_json::from_slice(&out.stderr).expect("problem JSON on stderr");
    assert_eq!(p["status"], 422);
    assert_eq!(p["errors"][0]["pointer"], "/coefficients");
    // Malformed JSON: 400 → also exit 2; an unknown endpoint: exit 2 with the list.
    let out = mechcalc()
        .args(["run", "cognates", "/dev/null"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let out = mechcalc()
        .args(["run", "no-such-thing", "/dev/null"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/v1/cognates"));
}

#[test]
fn batch_is_ndjson_in_input_order() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("api/cam_law");
    let good: Value =
        serde_json::from_slice(&std::fs::read(dir.join("evaluate_table1.json")).expect("example"))
            .expect("JSON");
    let other: Value = serde_json::from_slice(
        &std::fs::read(dir.join("evaluate_modified_sine.json")).expect("example"),
    )
    .expect("JSON");
    let mut input = String::new();
    for i in 0..40 {
        let line = match i % 3 {
            0 => good.to_string(),
            1 => other.to_string(),
            _ => r#"{"law": "no-such-law"}"#.to_owned(),
        };
        input.push_str(&line);
        input.push('\n');
    }
    let out = run_with_stdin(
        &["run", "/v1/cam-law/evaluate", "--batch"],
        input.as_bytes(),
    );
    assert_eq!(out.status.code(), Some(2), "one line is refused");
    let lines: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON value per line"))
        .collect();
    assert_eq!(lines.len(), 40);
    for (i, l) in lines.iter().enumerate() {
        match i % 3 {
            0 => assert!(
                l.get("law").is_none() && l["coefficients"].is_array(),
                "line {i}"
            ),
            1 => assert_eq!(l["law"], "modified_sine", "line {i}"),
            _ => assert_eq!(l["status"], 422, "line {i}"),
        }
    }
}
