//! Embeds the `api/` examples (listed in `api/examples.json`) into the binary, so the page at `/`
//! and `GET /v1/examples` work with no files beside the binary.

use std::fmt::Write as _;
use std::path::Path;

fn main() {
    println!("cargo:rerun-if-changed=api");
    let root = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let api = Path::new(&root).join("api");
    let index = std::fs::read_to_string(api.join("examples.json")).unwrap_or_default();
    let parsed: serde_json::Value = serde_json::from_str(&index).unwrap_or_default();
    let mut out = String::from("/// (file, endpoint, request) of every `api/` example.\n");
    out.push_str("pub const EXAMPLES: &[(&str, &str, &str)] = &[\n");
    for e in parsed["examples"].as_array().into_iter().flatten() {
        let (Some(file), Some(endpoint)) = (e["file"].as_str(), e["endpoint"].as_str()) else {
            continue;
        };
        let path = api.join(file);
        println!("cargo:rerun-if-changed={}", path.display());
        let _ = writeln!(
            out,
            "    ({file:?}, {endpoint:?}, include_str!({:?})),",
            path.display().to_string()
        );
    }
    out.push_str("];\n");
    let dest =
        Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("examples.rs");
    std::fs::write(dest, out).expect("OUT_DIR is writable");
}
