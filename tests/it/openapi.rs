//! `openapi.yaml` at the top level is generated from code; this test fails when it drifts.
//! Regenerate with `MECHCALC_UPDATE_OPENAPI=1 cargo test --test it openapi` (or
//! `cargo run -- --print-openapi > openapi.yaml`).

use std::path::Path;

#[test]
fn openapi_yaml_matches_code() {
    let generated = mechcalc::http::openapi_yaml().expect("the document renders as YAML");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("openapi.yaml");
    if std::env::var_os("MECHCALC_UPDATE_OPENAPI").is_some() {
        std::fs::write(&path, &generated).expect("openapi.yaml is writable");
    }
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        on_disk == generated,
        "openapi.yaml is out of date with the code; regenerate it with \
         `MECHCALC_UPDATE_OPENAPI=1 cargo test --test it openapi` and commit it"
    );
}

#[test]
fn every_operation_is_documented() {
    let api = mechcalc::http::openapi();
    for (path, item) in &api.paths.paths {
        for op in [item.get.as_ref(), item.post.as_ref()]
            .into_iter()
            .flatten()
        {
            assert!(
                op.summary.as_deref().is_some_and(|s| !s.is_empty()),
                "{path} has no summary"
            );
            assert!(op.operation_id.is_some(), "{path} has no operation id");
            assert!(
                op.tags.as_ref().is_some_and(|t| !t.is_empty()),
                "{path} has no tag"
            );
        }
    }
}

/// Every property of every schema carries a description (meaning, unit, range): clients read
/// the units from the docs. An `Option<Struct>` field needs `#[schema(nullable = false)]`, or
/// utoipa wraps it in a `oneOf` that drops the doc comment.
#[test]
fn every_schema_property_is_described() {
    let api = serde_json::to_value(mechcalc::http::openapi()).expect("document serializes");
    let mut missing = Vec::new();
    if let Some(schemas) = api
        .pointer("/components/schemas")
        .and_then(|s| s.as_object())
    {
        for (name, schema) in schemas {
            if let Some(props) = schema.get("properties").and_then(|p| p.as_object()) {
                for (prop, body) in props {
                    if body
                        .get("description")
                        .and_then(|d| d.as_str())
                        .is_none_or(str::is_empty)
                    {
                        missing.push(format!("{name}.{prop}"));
                    }
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "schema properties without a description: {missing:?}"
    );
}
