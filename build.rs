//! Embeds the `api/` examples (listed in `api/examples.json`) into the binary, so the page at `/`
//! and `GET /v1/examples` work with no files beside the binary; embeds each calculation module's
//! documentation (the `//!` text of `src/calc/<module>/mod.rs`: method, references, validity) for
//! the calculation reports; and sets `MECHCALC_GIT_COMMIT` (the source commit a report names:
//! `git rev-parse HEAD` when the sources are a git checkout, else the variable as given to the
//! build, else "unknown").

use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

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
    module_docs(Path::new(&root));
    git_commit();
}

/// `MODULE_DOCS`: (module folder name, its `//!` documentation) of every `src/calc/<module>/`.
fn module_docs(root: &Path) {
    let calc = root.join("src").join("calc");
    println!("cargo:rerun-if-changed={}", calc.display());
    let mut modules: Vec<_> = std::fs::read_dir(&calc)
        .into_iter()
        .flatten()
        .filter_map(Result::ok)
        .filter(|e| e.path().join("mod.rs").is_file())
        .collect();
    modules.sort_by_key(std::fs::DirEntry::file_name);
    let mut out =
        String::from("/// (module, its `//!` documentation) of every calculation module.\n");
    out.push_str("pub const MODULE_DOCS: &[(&str, &str)] = &[\n");
    for m in modules {
        let path = m.path().join("mod.rs");
        println!("cargo:rerun-if-changed={}", path.display());
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        let doc: Vec<&str> = text
            .lines()
            .map_while(|l| l.strip_prefix("//!"))
            .map(|l| l.strip_prefix(' ').unwrap_or(l))
            .collect();
        let name = m.file_name().to_string_lossy().into_owned();
        let _ = writeln!(out, "    ({name:?}, {:?}),", doc.join("\n"));
    }
    out.push_str("];\n");
    let dest =
        Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("module_docs.rs");
    std::fs::write(dest, out).expect("OUT_DIR is writable");
}

/// `MECHCALC_GIT_COMMIT` for the build: the checkout's HEAD, re-read when HEAD moves.
fn git_commit() {
    println!("cargo:rerun-if-env-changed=MECHCALC_GIT_COMMIT");
    let git = |args: &[&str]| -> Option<String> {
        let out = Command::new("git").args(args).output().ok()?;
        let s = String::from_utf8(out.stdout).ok()?.trim().to_owned();
        (out.status.success() && !s.is_empty()).then_some(s)
    };
    let commit = git(&["rev-parse", "HEAD"])
        .or_else(|| std::env::var("MECHCALC_GIT_COMMIT").ok())
        .unwrap_or_else(|| "unknown".to_owned());
    // HEAD and the branch it points at (both inside the git directory, also for a worktree).
    for p in [
        git(&["rev-parse", "--git-path", "HEAD"]),
        git(&["symbolic-ref", "-q", "HEAD"]).and_then(|r| git(&["rev-parse", "--git-path", &r])),
        git(&["rev-parse", "--git-path", "packed-refs"]),
    ]
    .into_iter()
    .flatten()
    {
        // A path that does not exist would make cargo rerun this script on every build.
        if Path::new(&p).exists() {
            println!("cargo:rerun-if-changed={p}");
        }
    }
    println!("cargo:rustc-env=MECHCALC_GIT_COMMIT={commit}");
}
