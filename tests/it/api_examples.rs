//! Every request example under `api/` is sent to the in-process router and checked against its
//! `<name>.expected.json` (leaves must match; numbers within rel 1e-6 or abs 1e-9). The list
//! `api/examples.json` maps each file to its endpoint; a file missing from the list, or a POST
//! endpoint without an example, fails the test.

use crate::common;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde_json::Value;

fn api_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("api")
}

fn example_files(dir: &Path, out: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).expect("api/ is readable") {
        let path = entry.expect("dir entry").path();
        if path.is_dir() {
            example_files(&path, out);
        } else if let Some(name) = path.file_name().and_then(|n| n.to_str())
            && name.ends_with(".json")
            && !name.ends_with(".expected.json")
            && name != "examples.json"
        {
            let rel = path.strip_prefix(api_dir()).expect("under api/");
            out.insert(rel.to_string_lossy().replace('\\', "/"));
        }
    }
}

#[tokio::test]
async fn every_example_runs_and_matches_its_expected_outputs() {
    let index: Value = serde_json::from_str(
        &std::fs::read_to_string(api_dir().join("examples.json")).expect("api/examples.json"),
    )
    .expect("api/examples.json is JSON");
    let listed = index["examples"].as_array().expect("examples array");
    let mut files = BTreeSet::new();
    example_files(&api_dir(), &mut files);
    let listed_files: BTreeSet<String> = listed
        .iter()
        .filter_map(|e| e["file"].as_str().map(str::to_owned))
        .collect();
    assert_eq!(
        files, listed_files,
        "api/examples.json must list exactly the example files under api/"
    );

    let mut covered = BTreeSet::new();
    let mut failures = Vec::new();
    for e in listed {
        let file = e["file"].as_str().expect("file");
        let endpoint = e["endpoint"].as_str().expect("endpoint");
        let status = e["status"].as_u64().unwrap_or(200);
        covered.insert(endpoint.to_owned());
        let body = std::fs::read(api_dir().join(file)).expect("example readable");
        let r = common::send("POST", endpoint, Some("application/json"), body).await;
        if u64::from(r.status.as_u16()) != status {
            failures.push(format!(
                "{file}: status {} (expected {status}): {}",
                r.status,
                String::from_utf8_lossy(&r.bytes)
            ));
            continue;
        }
        let expected_path = api_dir().join(file.replace(".json", ".expected.json"));
        let expected: Value = serde_json::from_str(
            &std::fs::read_to_string(&expected_path)
                .unwrap_or_else(|_| panic!("{} is missing", expected_path.display())),
        )
        .expect("expected file is JSON");
        let mut mismatches = Vec::new();
        common::leaves_match(&expected, &r.json(), "", 1e-6, 1e-9, &mut mismatches);
        for m in mismatches {
            failures.push(format!("{file}: {m}"));
        }
    }
    assert!(
        failures.is_empty(),
        "example failures:\n{}",
        failures.join("\n")
    );

    let api = mechcalc::http::openapi();
    for (path, item) in &api.paths.paths {
        if item.post.is_some() {
            assert!(
                covered.contains(path),
                "POST {path} has no example under api/"
            );
        }
    }
}
