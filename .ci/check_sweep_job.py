"""The sweep Jobs (deploy/sweep-job.yaml, deploy/sweep-merge-job.yaml): Kubernetes 1.37 schemas
(offline, strict) and their consistency with each other and with mechcalc's command line.

* The sweep Job is Indexed; its container runs
  `run <endpoint> <request> --shard $(JOB_COMPLETION_INDEX)/N --out <results>/...$(JOB_COMPLETION_INDEX)...`
  with N = completions, parallelism <= N, the request file a key of the mounted ConfigMap and
  the output on the results volume (a ReadWriteMany claim defined beside it).
* The merge Job runs `merge <same endpoint> --request <same request> --out <results>/...` over
  exactly the N files the sweep's pods write (indices 0..N-1), with the same volumes.
* The endpoint is one that can be sharded; the request in the ConfigMap is a JSON object.
* Every check can fail: the validator rejects a broken Job and the consistency check rejects a
  sweep Job whose completions differ from N (a green run means something).

Usage: python .ci/check_sweep_job.py PATH_TO_kubernetes-validate
"""

import copy
import json
import pathlib
import subprocess
import sys
import tempfile

import yaml  # installed with kubernetes-validate

ROOT = pathlib.Path(__file__).resolve().parent.parent
SWEEP = ROOT / "deploy" / "sweep-job.yaml"
MERGE = ROOT / "deploy" / "sweep-merge-job.yaml"
# The endpoints whose answers `mechcalc merge` merges (src/merge/mod.rs, Sweep::ALL), as the
# command line accepts them (with or without /v1/).
SHARDABLE = {"irefc-stress", "bus-fuel-economy", "machining-size/train", "continuum-workspace"}
INDEX = "$(JOB_COMPLETION_INDEX)"


def validate(validator, *files):
    r = subprocess.run(
        [validator, "--strict", "--kubernetes-version", "1.37.0", *map(str, files)],
        capture_output=True,
        text=True,
    )
    return r.returncode, r.stdout + r.stderr


def option(args, name):
    """The value of `--name VALUE` in args (None when absent)."""
    if name in args:
        i = args.index(name)
        if i + 1 < len(args):
            return args[i + 1]
    return None


def mounts(pod, container):
    """mountPath -> the volume's source ({'configMap': ...} or {'persistentVolumeClaim': ...})."""
    volumes = {v["name"]: v for v in pod.get("volumes", [])}
    out = {}
    for m in container.get("volumeMounts", []):
        v = volumes[m["name"]]
        out[m["mountPath"].rstrip("/")] = {k: val for k, val in v.items() if k != "name"}
    return out


def source(path, mounted):
    """(mountPath, volume source, path inside the volume) of a file path, or None."""
    for mp, src in mounted.items():
        if path.startswith(mp + "/"):
            return mp, src, path[len(mp) + 1 :]
    return None


def check(docs, merge_job):
    """Every inconsistency between the sweep's documents and the merge Job, as messages."""
    errors = []
    by_kind = {}
    for d in docs:
        by_kind.setdefault(d["kind"], []).append(d)
    jobs = by_kind.get("Job", [])
    if len(jobs) != 1:
        return [f"{SWEEP.name}: expected one Job, found {len(jobs)}"]
    job = jobs[0]
    spec = job["spec"]
    pod = spec["template"]["spec"]
    n = spec.get("completions")
    if spec.get("completionMode") != "Indexed":
        errors.append("the sweep Job is not `completionMode: Indexed` (no JOB_COMPLETION_INDEX)")
    if not isinstance(n, int) or n < 1:
        errors.append(f"completions must be a positive integer, got {n!r}")
        return errors
    if not 1 <= spec.get("parallelism", 1) <= n:
        errors.append(f"parallelism {spec.get('parallelism')} is not in 1..completions ({n})")
    if pod.get("restartPolicy") not in ("Never", "OnFailure"):
        errors.append("a Job's pods need restartPolicy Never or OnFailure")
    c = pod["containers"][0]
    args = c.get("args", [])
    if args[:1] != ["run"] or len(args) < 3:
        return errors + [f"the sweep container's args are not `run <endpoint> <request> ...`: {args}"]
    endpoint, request = args[1], args[2]
    if endpoint.removeprefix("/").removeprefix("v1/") not in SHARDABLE:
        errors.append(f"{endpoint} is not a shardable endpoint ({sorted(SHARDABLE)})")
    if option(args, "--shard") != f"{INDEX}/{n}":
        errors.append(f"--shard is {option(args, '--shard')!r}, expected '{INDEX}/{n}' (completions {n})")
    out = option(args, "--out")
    if out is None or INDEX not in out:
        errors.append(f"--out {out!r} must name one file per index (contain {INDEX})")
        return errors
    mounted = mounts(pod, c)
    req = source(request, mounted)
    if req is None or "configMap" not in req[1]:
        errors.append(f"the request {request} is not on a mounted ConfigMap")
    else:
        name = req[1]["configMap"]["name"]
        maps = [m for m in by_kind.get("ConfigMap", []) if m["metadata"]["name"] == name]
        if not maps or req[2] not in maps[0].get("data", {}):
            errors.append(f"ConfigMap {name} with key {req[2]} is not defined in {SWEEP.name}")
        else:
            try:
                body = json.loads(maps[0]["data"][req[2]])
                if not isinstance(body, dict):
                    errors.append(f"the request in ConfigMap {name} is not a JSON object")
            except json.JSONDecodeError as e:
                errors.append(f"the request in ConfigMap {name} is not JSON: {e}")
    res = source(out, mounted)
    if res is None or "persistentVolumeClaim" not in res[1]:
        errors.append(f"the shard answers ({out}) are not written to a persistent volume claim")
        return errors
    claim = res[1]["persistentVolumeClaim"]["claimName"]
    pvcs = [p for p in by_kind.get("PersistentVolumeClaim", []) if p["metadata"]["name"] == claim]
    if not pvcs:
        errors.append(f"PersistentVolumeClaim {claim} is not defined in {SWEEP.name}")
    elif parallelism_needs_rwx(spec) and "ReadWriteMany" not in pvcs[0]["spec"]["accessModes"]:
        errors.append(f"{claim}: parallel pods on several nodes need accessModes ReadWriteMany")

    # The merge Job: same endpoint, request and volumes, exactly the N files the pods write.
    mpod = merge_job["spec"]["template"]["spec"]
    mc = mpod["containers"][0]
    margs = mc.get("args", [])
    if margs[:2] != ["merge", endpoint]:
        errors.append(f"the merge Job's args do not start with `merge {endpoint}`: {margs[:2]}")
    if option(margs, "--request") != request:
        errors.append(f"the merge Job's --request is {option(margs, '--request')!r}, not {request}")
    merged = option(margs, "--out")
    skip = {"--request", "--out"}
    files, i = [], 2
    while i < len(margs):
        if margs[i] in skip:
            i += 2
        elif margs[i].startswith("--"):
            i += 1
        else:
            files.append(margs[i])
            i += 1
    want = [out.replace(INDEX, str(k)) for k in range(n)]
    if sorted(files) != sorted(want):
        errors.append(f"the merge Job merges {files}, but the sweep's pods write {want}")
    if merged is None or merged in want:
        errors.append(f"the merge Job's --out {merged!r} must be a file apart from the shards'")
    if mounts(mpod, mc) != {mp: src for mp, src in mounted.items()}:
        errors.append("the merge Job does not mount the sweep Job's volumes at the same paths")
    return errors


def parallelism_needs_rwx(spec):
    return spec.get("parallelism", 1) > 1


def main():
    validator = sys.argv[1]
    rc, out = validate(validator, SWEEP, MERGE)
    print(out.strip())
    assert rc == 0, f"kubernetes-validate rejected the sweep Jobs (exit {rc})"
    docs = [d for d in yaml.safe_load_all(SWEEP.read_text()) if d]
    merge_job = yaml.safe_load(MERGE.read_text())
    errors = check(docs, merge_job)
    assert not errors, "sweep Jobs inconsistent:\n  " + "\n  ".join(errors)

    # The checks can fail: a Job with completions "four" is invalid, and one more completion
    # than shards in --shard is inconsistent.
    broken = copy.deepcopy(docs)
    job = next(d for d in broken if d["kind"] == "Job")
    job["spec"]["completions"] = "four"
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        yaml.safe_dump_all(broken, f)
    rc, _ = validate(validator, f.name)
    assert rc != 0, "the manifest validator accepted a Job with completions: 'four'"
    job["spec"]["completions"] = job["spec"]["parallelism"] + 1
    assert check(broken, merge_job), "the consistency check accepted completions != N"
    n = next(d for d in docs if d["kind"] == "Job")["spec"]["completions"]
    print(
        f"deploy/sweep-job.yaml, deploy/sweep-merge-job.yaml: valid for Kubernetes 1.37; "
        f"{n} indexed shards, --shard and the merge's {n} files consistent; "
        "the validator and the consistency check reject broken Jobs"
    )


if __name__ == "__main__":
    main()
