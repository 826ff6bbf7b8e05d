//! Issue 29: sweeps beyond one machine from the command line. `mechcalc run --shard I/N`
//! then `mechcalc merge` give the unsharded answer (timings aside) for every shardable
//! endpoint, shards in any order; missing, duplicated and mismatched shards, endpoints and
//! requests that cannot be sharded are refused with a clear message and exit code 2; the
//! Kubernetes Indexed Job of `deploy/sweep-job.yaml`, simulated with its own arguments (N
//! processes with `JOB_COMPLETION_INDEX`, then the merge Job), gives the unsharded answer.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

use mechcalc::merge::{DIGEST_MEMBER, Sweep};
use serde_json::{Value, json};

use crate::sharding::{bus_body, comparable, continuum_body, irefc_body, train_body, with_shard};

fn mechcalc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mechcalc"))
}

/// A directory of its own under the system's temporary directory, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let p =
            std::env::temp_dir().join(format!("mechcalc-{name}-{}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&p).expect("temporary directory");
        Self(p)
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    fn write_json(&self, name: &str, v: &Value) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, v.to_string()).expect("write");
        p
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json_of(bytes: &[u8]) -> Value {
    serde_json::from_slice(bytes)
        .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(bytes)))
}

/// The unsharded answer of `mechcalc run <endpoint> <file>`.
fn whole(endpoint: &str, request: &Path) -> Value {
    let o = mechcalc()
        .args(["run", endpoint, &s(request)])
        .output()
        .expect("runs");
    assert!(o.status.success(), "{endpoint}: {}", stderr(&o));
    json_of(&o.stdout)
}

/// Starts `mechcalc run <endpoint> <request> --shard i/count --out <dir>/shard-i.json` for
/// every i at once (as the pods of a Job run) and waits for all; returns the files.
fn run_shards(dir: &TempDir, endpoint: &str, request: &Path, count: u32) -> Vec<PathBuf> {
    let children: Vec<(PathBuf, Child)> = (0..count)
        .map(|i| {
            let out = dir.path(&format!("shard-{i}.json"));
            let child = mechcalc()
                .args([
                    "run",
                    endpoint,
                    &s(request),
                    "--shard",
                    &format!("{i}/{count}"),
                ])
                .args(["--out", &s(&out)])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("runs");
            (out, child)
        })
        .collect();
    children
        .into_iter()
        .map(|(out, child)| {
            let o = child.wait_with_output().expect("exits");
            assert!(o.status.success(), "{endpoint} {out:?}: {}", stderr(&o));
            assert!(o.stdout.is_empty(), "--out: nothing on stdout");
            out
        })
        .collect()
}

fn merge_cli(endpoint: &str, request: Option<&Path>, files: &[PathBuf]) -> Output {
    let mut c = mechcalc();
    c.args(["merge", endpoint]);
    if let Some(r) = request {
        c.args(["--request", &s(r)]);
    }
    c.args(files.iter().map(|f| s(f))).output().expect("runs")
}

#[test]
fn run_shard_then_merge_gives_the_unsharded_answer_for_every_sweep() {
    let cases = [
        ("irefc-stress", Sweep::IrefcStress, irefc_body()),
        ("bus-fuel-economy", Sweep::BusFuelEconomy, bus_body()),
        (
            "/v1/machining-size/train",
            Sweep::MachiningTrain,
            train_body(),
        ),
        (
            "continuum-workspace",
            Sweep::ContinuumWorkspace,
            continuum_body(),
        ),
    ];
    for (endpoint, sweep, body) in cases {
        let dir = TempDir::new("sweep-cli");
        let request = dir.write_json("request.json", &body);
        let want = comparable(&whole(endpoint, &request), sweep);
        for count in [1, 3] {
            let mut files = run_shards(&dir, endpoint, &request, count);
            for f in &files {
                let a = json_of(&std::fs::read(f).expect("shard file"));
                assert!(
                    a[DIGEST_MEMBER].as_str().is_some_and(|d| d.len() == 64),
                    "{endpoint}: a shard carries its request's digest"
                );
                assert!(a.pointer(sweep.shard_pointer()).is_some());
            }
            files.reverse();
            let o = merge_cli(endpoint, Some(&request), &files);
            assert!(o.status.success(), "{endpoint} {count}: {}", stderr(&o));
            let merged = json_of(&o.stdout);
            assert!(merged.get(DIGEST_MEMBER).is_none());
            assert_eq!(
                comparable(&merged, sweep),
                want,
                "{endpoint}: {count} shards merged"
            );
        }
    }
}

/// The shard files of the IREFC sweep (3 shards) in `dir`, and the request's path.
fn irefc_shards(dir: &TempDir) -> (PathBuf, Vec<PathBuf>) {
    let request = dir.write_json("request.json", &irefc_body());
    let files = run_shards(dir, "irefc-stress", &request, 3);
    (request, files)
}

/// Asserts that the merge is refused with exit code 2 and a message containing `words`.
fn assert_refused(o: &Output, words: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(o.stdout.is_empty(), "nothing merged on stdout");
    assert!(e.contains(words), "expected {words:?} in: {e}");
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn merge_refuses_missing_duplicated_and_mismatched_shards() {
    let dir = TempDir::new("sweep-refusals");
    let (request, f) = irefc_shards(&dir);
    let ep = "irefc-stress";
    assert_refused(
        &merge_cli(ep, None, &f[..2]),
        "1 of 3 shards missing: index 2",
    );
    assert_refused(
        &merge_cli(ep, None, &[f[2].clone(), f[0].clone()]),
        "1 of 3 shards missing: index 1",
    );
    let dup = [f[0].clone(), f[1].clone(), f[1].clone(), f[2].clone()];
    assert_refused(&merge_cli(ep, None, &dup), "shard 1 is given twice");

    // A shard of another count (N = 4).
    let other = TempDir::new("sweep-refusals-n");
    let four = run_shards(&other, ep, &request, 4);
    assert_refused(
        &merge_cli(ep, None, &[f[0].clone(), four[1].clone(), f[2].clone()]),
        "shard 1 of 4",
    );

    // A shard of another request that only differs in a value no answer echoes (the torque):
    // told apart by the request digest, also against --request.
    let mut body = irefc_body();
    body["torque_Nm"] = json!(100);
    let other_request = other.write_json("other.json", &body);
    let o = mechcalc()
        .args(["run", ep, &s(&other_request), "--shard", "1/3"])
        .args(["--out", &s(&other.path("torque-1.json"))])
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let mixed = [f[0].clone(), other.path("torque-1.json"), f[2].clone()];
    assert_refused(&merge_cli(ep, None, &mixed), "different requests");
    assert_refused(
        &merge_cli(ep, Some(&other_request), &f),
        "the request given (--request)",
    );

    // Shards fetched from the service carry no digest: a different request is then told apart
    // by what its answer echoes (here the grid step in `meta`).
    let strip = |p: &Path, name: &str| {
        let mut a = json_of(&std::fs::read(p).expect("read"));
        a.as_object_mut().map(|o| o.shift_remove(DIGEST_MEMBER));
        other.write_json(name, &a)
    };
    let mut body = irefc_body();
    body["step_deg"] = json!(3);
    let step_request = other.write_json("step.json", &body);
    let step_dir = TempDir::new("sweep-step");
    let step = run_shards(&step_dir, ep, &step_request, 3);
    let mixed = [
        strip(&f[0], "plain-0.json"),
        strip(&step[1], "plain-1.json"),
        strip(&f[2], "plain-2.json"),
    ];
    assert_refused(
        &merge_cli(ep, None, &mixed),
        "at /meta/step_deg (2.0 vs 3.0)",
    );
    // A digest on some shards only.
    let some = [strip(&f[0], "plain-0.json"), f[1].clone(), f[2].clone()];
    assert_refused(&merge_cli(ep, None, &some), "different requests");

    // Not a sharded answer; a problem document; not JSON; the wrong endpoint.
    let whole_file = dir.write_json("whole.json", &whole(ep, &request));
    assert_refused(
        &merge_cli(ep, None, &[whole_file]),
        "has no shard statement at /shard",
    );
    let problem = dir.write_json(
        "problem.json",
        &json!({"type": "/problems/invalid-input", "title": "Request failed validation",
                "status": 422, "detail": "1 field out of range", "errors": []}),
    );
    assert_refused(
        &merge_cli(ep, None, &[f[0].clone(), problem, f[2].clone()]),
        "is not an answer but a problem (status 422)",
    );
    let junk = dir.path("junk.json");
    std::fs::write(&junk, b"{\"records\": [").expect("write");
    assert_refused(&merge_cli(ep, None, &[junk]), "is not JSON");
    assert_refused(
        &merge_cli("bus-fuel-economy", None, &f),
        "is not an answer of /v1/bus-fuel-economy: it has no /results",
    );
    assert_refused(
        &merge_cli("cam-law/evaluate", None, &f),
        "is not a shardable endpoint",
    );
    let o = merge_cli(ep, None, &[dir.path("absent.json")]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "an unreadable file: {}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("cannot read"), "{}", stderr(&o));
}

#[test]
fn run_shard_refuses_what_cannot_be_sharded() {
    let dir = TempDir::new("sweep-unshardable");
    let out = dir.path("shard-0.json");
    let run = |endpoint: &str, body: &Value, shard: &str| {
        let request = dir.write_json("request.json", body);
        mechcalc()
            .args(["run", endpoint, &s(&request), &format!("--shard={shard}")])
            .args(["--out", &s(&out)])
            .output()
            .expect("runs")
    };
    // An endpoint with nothing to split.
    let cam = json!({"law": "cycloidal"});
    let o = run("cam-law/evaluate", &cam, "0/2");
    assert_refused(&o, "cannot be sharded");
    assert!(
        stderr(&o).contains("/v1/irefc-stress"),
        "names the shardable endpoints"
    );
    // A request of a shardable endpoint with nothing to split: the service's 422 at /shard.
    let mut single = irefc_body();
    single["mode"] = json!("single");
    single["Z2"] = json!(26);
    single["chi"] = json!(1.4);
    single.as_object_mut().map(|o| o.remove("sweep"));
    let o = run("irefc-stress", &single, "0/2");
    assert_refused(&o, "\"pointer\":\"/shard\"");
    let mut no_cv = train_body();
    no_cv["validation"] = json!({"test_fraction": 0.2});
    assert_refused(&run("machining-size/train", &no_cv, "1/2"), "/shard");
    // Not a block: the command line refuses it before computing.
    for bad in ["3/3", "1/0", "-1/2", "2", "$(JOB_COMPLETION_INDEX)/4"] {
        let o = run("irefc-stress", &irefc_body(), bad);
        assert_refused(&o, "--shard");
    }
    // A count the service does not take (10 001 > 10 000 blocks): its 422 at /shard/count.
    assert_refused(
        &run("irefc-stress", &irefc_body(), "0/10001"),
        "/shard/count",
    );
    assert!(!out.exists(), "no answer file for a refused shard");
    // The request's own shard is replaced by --shard.
    let o = run("irefc-stress", &with_shard(&irefc_body(), 0, 2), "1/3");
    assert!(o.status.success(), "{}", stderr(&o));
    let a = json_of(&std::fs::read(&out).expect("answer"));
    assert_eq!(
        a["shard"],
        json!({"index": 1, "count": 3, "start": 14, "end": 28, "total": 42})
    );
}

/// Regression test for issue 29's small fix: `mechcalc --print-openapi | head` panicked with a
/// backtrace when `head` closed the pipe; it now exits quietly (and successfully).
#[test]
fn print_openapi_into_a_closed_pipe_exits_quietly_issue_29() {
    for args in [&["--print-openapi"][..], &["run", "--list"][..]] {
        let mut child = mechcalc()
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("runs");
        let mut head = [0u8; 16];
        child
            .stdout
            .take()
            .expect("stdout")
            .read_exact(&mut head)
            .expect("the first bytes");
        // Dropping the reader closes the pipe, as `head` does.
        let o = child.wait_with_output().expect("exits");
        let e = stderr(&o);
        assert!(
            !e.contains("panicked") && !e.contains("Broken pipe"),
            "{args:?}: {e}"
        );
        assert!(o.status.success(), "{args:?}: {:?} {e}", o.status);
    }
}

// ---------------------------------------------------------------------------------------------
// The Kubernetes Indexed Job, simulated
// ---------------------------------------------------------------------------------------------

fn yaml_docs(file: &str) -> Vec<Value> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("deploy")
        .join(file);
    let text = std::fs::read_to_string(&path).expect("manifest");
    serde_norway::Deserializer::from_str(&text)
        .map(|d| serde::Deserialize::deserialize(d).expect("YAML document"))
        .filter(|v: &Value| !v.is_null())
        .collect()
}

fn doc<'a>(docs: &'a [Value], kind: &str) -> &'a Value {
    docs.iter()
        .find(|d| d["kind"] == kind)
        .unwrap_or_else(|| panic!("a {kind} in the manifest"))
}

/// `$(NAME)` replaced by `env[NAME]` and `$$` by `$`, as Kubernetes expands a container's
/// command and arguments (an undefined name stays as written).
fn expand(arg: &str, env: &BTreeMap<String, String>) -> String {
    let mut out = String::new();
    let mut rest = arg;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        if let Some(t) = tail.strip_prefix("$$") {
            out.push('$');
            rest = t;
        } else if let Some((name, after)) = tail
            .strip_prefix("$(")
            .and_then(|t| t.split_once(')'))
            .filter(|(n, _)| env.contains_key(*n))
        {
            out.push_str(&env[name]);
            rest = after;
        } else {
            out.push('$');
            rest = &tail[1..];
        }
    }
    out.push_str(rest);
    out
}

/// A pod of `job`: its container's arguments and environment, the volumes mounted where the
/// pod sees them (`mountPath` -> the directory standing for the volume: a ConfigMap's keys as
/// files, a claim shared by every pod).
struct Pod {
    args: Vec<String>,
    env: BTreeMap<String, String>,
    mounts: Vec<(String, PathBuf)>,
}

fn pod(job: &Value, config_maps: &[&Value], volumes_root: &TempDir) -> Pod {
    let spec = &job["spec"]["template"]["spec"];
    let c = &spec["containers"][0];
    let strings = |v: &Value| -> Vec<String> {
        v.as_array()
            .into_iter()
            .flatten()
            .map(|a| a.as_str().expect("a string").to_owned())
            .collect()
    };
    let env = c["env"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|e| {
            let v = e["value"].as_str().expect("a literal value");
            (e["name"].as_str().expect("a name").to_owned(), v.to_owned())
        })
        .collect();
    let mut mounts = Vec::new();
    for m in c["volumeMounts"].as_array().expect("volume mounts") {
        let name = m["name"].as_str().expect("name");
        let v = spec["volumes"]
            .as_array()
            .and_then(|vs| vs.iter().find(|v| v["name"] == name))
            .expect("the mounted volume is defined");
        let dir = if let Some(cm) = v["configMap"]["name"].as_str() {
            let map = config_maps
                .iter()
                .find(|m| m["metadata"]["name"] == cm)
                .expect("the ConfigMap is in the manifest");
            let dir = volumes_root.path(&format!("configmap-{cm}"));
            std::fs::create_dir_all(&dir).expect("dir");
            for (k, text) in map["data"].as_object().expect("data") {
                std::fs::write(dir.join(k), text.as_str().expect("text")).expect("write");
            }
            dir
        } else {
            let claim = v["persistentVolumeClaim"]["claimName"]
                .as_str()
                .expect("a ConfigMap or a claim");
            let dir = volumes_root.path(&format!("claim-{claim}"));
            std::fs::create_dir_all(&dir).expect("dir");
            dir
        };
        let at = m["mountPath"].as_str().expect("path").trim_end_matches('/');
        mounts.push((at.to_owned(), dir));
    }
    Pod {
        args: strings(&c["args"]),
        env,
        mounts,
    }
}

impl Pod {
    /// The command the container runs (the image's entrypoint is the mechcalc binary), with
    /// `extra` environment variables and the mounted paths mapped to their directories.
    fn command(&self, extra: &[(&str, String)]) -> Command {
        let mut env = self.env.clone();
        env.extend(extra.iter().map(|(k, v)| ((*k).to_owned(), v.clone())));
        let args = self.args.iter().map(|a| {
            let a = expand(a, &env);
            self.mounts
                .iter()
                .find_map(|(at, dir)| {
                    a.strip_prefix(&format!("{at}/"))
                        .map(|rel| s(&dir.join(rel)))
                })
                .unwrap_or(a)
        });
        let mut cmd = mechcalc();
        cmd.args(args).envs(&env);
        cmd
    }
}

#[test]
fn the_sweep_job_simulated_with_its_own_arguments_gives_the_unsharded_answer() {
    let docs = yaml_docs("sweep-job.yaml");
    let merge_docs = yaml_docs("sweep-merge-job.yaml");
    let job = doc(&docs, "Job");
    let spec = &job["spec"];
    assert_eq!(spec["completionMode"], "Indexed");
    let n = spec["completions"].as_u64().expect("completions");
    let maps: Vec<&Value> = docs.iter().filter(|d| d["kind"] == "ConfigMap").collect();
    let volumes = TempDir::new("sweep-job");
    let sweep_pod = pod(job, &maps, &volumes);
    let merge_pod = pod(doc(&merge_docs, "Job"), &maps, &volumes);

    // The pods of the Indexed Job: index i in JOB_COMPLETION_INDEX, all at once.
    let children: Vec<Child> = (0..n)
        .map(|i| {
            sweep_pod
                .command(&[("JOB_COMPLETION_INDEX", i.to_string())])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("runs")
        })
        .collect();
    for (i, c) in children.into_iter().enumerate() {
        let o = c.wait_with_output().expect("exits");
        assert!(o.status.success(), "pod {i}: {}", stderr(&o));
    }
    // Then the merge Job.
    let o = merge_pod.command(&[]).output().expect("runs");
    assert!(o.status.success(), "merge: {}", stderr(&o));

    // Its output file, against the unsharded answer of the ConfigMap's request.
    let out = merge_pod
        .command(&[])
        .get_args()
        .skip_while(|a| *a != "--out")
        .nth(1)
        .map(PathBuf::from)
        .expect("the merge Job writes --out");
    let merged = json_of(&std::fs::read(&out).expect("the merged answer"));
    let endpoint = sweep_pod.args[1].clone();
    let request = sweep_pod.command(&[]).get_args().nth(2).map(PathBuf::from);
    let request = request.expect("the request argument");
    assert!(request.exists(), "the request is on the ConfigMap volume");
    let sweep = Sweep::ALL
        .into_iter()
        .find(|s| s.path().trim_start_matches("/v1/") == endpoint.trim_start_matches("/v1/"))
        .expect("a shardable endpoint");
    let whole = whole(&endpoint, &request);
    assert_eq!(comparable(&merged, sweep), comparable(&whole, sweep));
    let total = merged["meta"]["n_combinations"].as_u64();
    assert!(
        total.is_some_and(|t| t > n),
        "more designs than pods: {total:?}"
    );
}

#[test]
fn kubernetes_expansion_of_the_arguments_is_simulated_as_documented() {
    let env = BTreeMap::from([("JOB_COMPLETION_INDEX".to_owned(), "3".to_owned())]);
    assert_eq!(expand("$(JOB_COMPLETION_INDEX)/4", &env), "3/4");
    assert_eq!(
        expand("/results/shard-$(JOB_COMPLETION_INDEX).json", &env),
        "/results/shard-3.json"
    );
    assert_eq!(
        expand("$$(JOB_COMPLETION_INDEX)", &env),
        "$(JOB_COMPLETION_INDEX)"
    );
    assert_eq!(expand("$(UNDEFINED)/4", &env), "$(UNDEFINED)/4");
}
