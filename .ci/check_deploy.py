"""Consistency of deploy/ with the service, beyond the Kubernetes schemas.

* The pod's termination grace period covers the service's shutdown deadline plus a margin.
* The probes use the service's health endpoint on the named port.
* The validator in use really rejects a broken manifest (so a green validation means something).

Usage: python .ci/check_deploy.py PATH_TO_kubernetes-validate
"""

import pathlib
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

broken = dict(dep)
broken["spec"] = dict(dep["spec"], replicas="two")
with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
    yaml.safe_dump(broken, f)
r = subprocess.run([validator, "--strict", "--quiet", f.name], capture_output=True, text=True)
assert r.returncode != 0, "the manifest validator accepted a Deployment with replicas: 'two'"
print("deploy/: grace period, probes and CPU request consistent; the validator rejects a broken manifest")
