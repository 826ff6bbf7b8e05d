"""Consistency of deploy/ with the service, beyond the Kubernetes schemas.

* The pod's termination grace period covers the service's shutdown deadline plus a margin.
* The probes use the service's health endpoint on the named port.
* The validator in use really rejects a broken manifest (so a green validation means something).
* The manifests .ci/run does not list by name (the NetworkPolicy, the API keys Secret) pass the
  same strict validation here, and kustomization.yaml lists every manifest in deploy/.
* The API keys file is mounted from the Secret at the path MECHCALC_API_KEYS_FILE names, readable
  by the service's user, and every line of it has the service's format.
* The NetworkPolicy selects the service's pods, admits the API port only from pods and namespaces
  carrying the documented client label, and the metrics port (MECHCALC_METRICS_BIND, the one the
  scrape annotation names) only from the monitoring namespace.

Usage: python .ci/check_deploy.py PATH_TO_kubernetes-validate
"""

import pathlib
import re
import subprocess
import sys
import tempfile

import yaml  # installed with kubernetes-validate

ROOT = pathlib.Path(__file__).resolve().parent.parent
validator = sys.argv[1]
dep = yaml.safe_load((ROOT / "deploy" / "deployment.yaml").read_text())
spec = dep["spec"]["template"]["spec"]
container = spec["containers"][0]
env = {e["name"]: e.get("value") for e in container.get("env", [])}

grace_ms = int(env.get("MECHCALC_SHUTDOWN_GRACE_MS", "20000"))
period_s = spec["terminationGracePeriodSeconds"]
assert period_s * 1000 >= grace_ms + 5000, (
    f"terminationGracePeriodSeconds={period_s} does not cover the service's shutdown deadline "
    f"({grace_ms} ms) plus 5 s"
)
for probe in ("readinessProbe", "livenessProbe", "startupProbe"):
    p = container[probe]["httpGet"]
    assert p["path"] == "/healthz" and p["port"] == "http", f"{probe} does not use /healthz on http"
assert container["resources"]["requests"]["cpu"] == env["MECHCALC_COMPUTE_THREADS"], (
    "the CPU request and the compute threads differ: admission would not bound the CPU"
)

DEPLOY = ROOT / "deploy"
EXTRA = ["networkpolicy.yaml", "api-keys-secret.yaml"]
r = subprocess.run(
    [validator, "--strict", "--kubernetes-version", "1.37.0", *[str(DEPLOY / f) for f in EXTRA]],
    capture_output=True, text=True,
)
assert r.returncode == 0, f"kubernetes-validate refused {EXTRA}:\n{r.stdout}\n{r.stderr}"
kust = yaml.safe_load((DEPLOY / "kustomization.yaml").read_text())
listed = set(kust["resources"])
# The sweep Jobs are applied on their own (README "Running a sweep on a cluster") and checked by
# .ci/check_sweep_job.py; every other manifest belongs to the service's kustomization.
present = {p.name for p in DEPLOY.glob("*.yaml")} - {"kustomization.yaml"}
present = {p for p in present if not p.startswith("sweep-")}
assert listed == present, f"kustomization.yaml lists {sorted(listed)}, deploy/ holds {sorted(present)}"

# The keys file: Secret -> volume -> mount -> MECHCALC_API_KEYS_FILE.
secret = yaml.safe_load((DEPLOY / "api-keys-secret.yaml").read_text())
keys_path = pathlib.PurePosixPath(env["MECHCALC_API_KEYS_FILE"])
mount = next(m for m in container["volumeMounts"] if keys_path.is_relative_to(m["mountPath"]))
assert mount.get("readOnly") is True, "the keys volume is not mounted read-only"
volume = next(v for v in spec["volumes"] if v["name"] == mount["name"])
vsec = volume["secret"]
assert vsec["secretName"] == secret["metadata"]["name"], "the keys volume names another Secret"
item = next(i for i in vsec["items"] if str(pathlib.PurePosixPath(mount["mountPath"]) / i["path"]) == str(keys_path))
keys_text = secret["stringData"][item["key"]]
mode = vsec.get("defaultMode", 0o644)
pod_sc = spec["securityContext"]
readable = bool(mode & 0o004) or (bool(mode & 0o040) and pod_sc.get("fsGroup") == pod_sc.get("runAsGroup"))
assert readable, f"the keys file (mode {oct(mode)}) is not readable by the service's user"
assert not (mode & 0o002 or mode & 0o020), "the keys file is writable by others"
line_re = re.compile(r"^\S+\s+[0-9a-fA-F]{64}(\s+[1-9][0-9]*)?$")
n_keys = 0
for i, raw in enumerate(keys_text.splitlines(), 1):
    line = raw.split("#", 1)[0].strip()
    if line:
        assert line_re.match(line), f"api-keys-secret.yaml, keys line {i} is not `<id> <sha256 hex> [<rpm>]`"
        n_keys += 1
assert n_keys >= 1, "the keys Secret holds no key: the service would not start"

# The NetworkPolicy.
pol = yaml.safe_load((DEPLOY / "networkpolicy.yaml").read_text())
pod_labels = dep["spec"]["template"]["metadata"]["labels"]
sel = pol["spec"]["podSelector"]["matchLabels"]
assert all(pod_labels.get(k) == v for k, v in sel.items()) and sel, "the policy does not select the pods"
assert pol["spec"]["policyTypes"] == ["Ingress"]
ports = {p["name"]: p["containerPort"] for p in container["ports"]}
metrics_port = int(env["MECHCALC_METRICS_BIND"].rsplit(":", 1)[1])
assert ports["metrics"] == metrics_port, "the metrics container port is not MECHCALC_METRICS_BIND's"
annotations = dep["spec"]["template"]["metadata"]["annotations"]
assert int(annotations["prometheus.io/port"]) == metrics_port, "the scrape annotation names another port"
rules = {tuple(p["port"] for p in rule["ports"]): rule["from"] for rule in pol["spec"]["ingress"]}
assert set(rules) == {("http",), ("metrics",)}, f"unexpected ingress rules {sorted(rules)}"
for peer in rules[("http",)]:
    assert peer["namespaceSelector"]["matchLabels"] == {"mechcalc.io/client": "true"}, peer
    assert peer["podSelector"]["matchLabels"] == {"mechcalc.io/client": "true"}, peer
for peer in rules[("metrics",)]:
    assert peer == {"namespaceSelector": {"matchLabels": {"kubernetes.io/metadata.name": "monitoring"}}}, peer
assert "mechcalc.io/client" in (DEPLOY / "networkpolicy.yaml").read_text().split("apiVersion")[0], (
    "the client label is not documented in networkpolicy.yaml's header"
)

broken_pol = dict(pol)
broken_pol["spec"] = dict(pol["spec"], ingress="everyone")
with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
    yaml.safe_dump(broken_pol, f)
r = subprocess.run([validator, "--strict", "--quiet", f.name], capture_output=True, text=True)
assert r.returncode != 0, "the manifest validator accepted a NetworkPolicy with ingress: 'everyone'"

broken = dict(dep)
broken["spec"] = dict(dep["spec"], replicas="two")
with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
    yaml.safe_dump(broken, f)
r = subprocess.run([validator, "--strict", "--quiet", f.name], capture_output=True, text=True)
assert r.returncode != 0, "the manifest validator accepted a Deployment with replicas: 'two'"
print("deploy/: grace period, probes and CPU request consistent; NetworkPolicy and API keys Secret valid and")
print("         consistent with the Deployment; the validator rejects a broken manifest")
