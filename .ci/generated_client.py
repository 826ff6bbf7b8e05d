"""A client generated from openapi.yaml, used as a PLM integrator would use it.

datamodel-code-generator (pinned in .ci/generated_client) turns the document's schemas into
pydantic v2 models. For every `api/` example: the example is read into its operation's generated
request model and sent as the model dumps it (every unset optional field as `null`); the answer
must equal the answer to the plain example (wall-clock timings aside) and parse into the
generated model of the 200 response.

Usage: python .ci/generated_client.py MODELS_DIR BASE_URL
"""

import importlib
import json
import pathlib
import sys
import typing
import urllib.error
import urllib.request

import yaml
from pydantic import RootModel

ROOT = pathlib.Path(__file__).resolve().parent.parent
models_dir = pathlib.Path(sys.argv[1])
base = sys.argv[2].rstrip("/")
sys.path.insert(0, str(models_dir.parent))
package = models_dir.name
doc = yaml.safe_load((ROOT / "openapi.yaml").read_text())


def union_of(mod, cls):
    """The generated RootModel whose union holds `cls`: a schema with a `oneOf` beside its
    properties (exactly one of two fields) becomes a union of one model per alternative, the
    first of which keeps the schema's name."""
    for obj in vars(mod).values():
        if isinstance(obj, type) and issubclass(obj, RootModel) and obj is not cls:
            ann = obj.model_fields["root"].annotation
            while typing.get_origin(ann) is typing.Annotated:
                ann = typing.get_args(ann)[0]
            if cls in typing.get_args(ann):
                return obj
    return cls


def model_of(schema_ref):
    """The generated class of a `#/components/schemas/<module>.<Name>` reference."""
    name = schema_ref.rsplit("/", 1)[1]
    parts = name.split(".")
    module = ".".join([package, *parts[:-1]]) if len(parts) > 1 else package
    mod = importlib.import_module(module)
    return union_of(mod, getattr(mod, parts[-1]))


def post(endpoint, body):
    req = urllib.request.Request(
        base + endpoint,
        data=json.dumps(body).encode(),
        headers={"content-type": "application/json", "accept": "application/json"},
        method="POST",
    )
    try:
        with urllib.request.urlopen(req, timeout=120) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"null")


# Answer fields holding wall-clock or CPU times (they differ from run to run).
TIMING_KEYS = {"elapsed_ms", "elapsed_s", "cpu_ms", "wall_ms", "compute_ms", "compute_us", "timing_ms"}


def without_timing(v):
    if isinstance(v, dict):
        return {
            k: without_timing(x)
            for k, x in v.items()
            if k not in TIMING_KEYS
        }
    if isinstance(v, list):
        return [without_timing(x) for x in v]
    return v


def nulls_in(v):
    if isinstance(v, dict):
        return sum(1 for x in v.values() if x is None) + sum(nulls_in(x) for x in v.values())
    if isinstance(v, list):
        return sum(nulls_in(x) for x in v)
    return 0


index = json.loads((ROOT / "api" / "examples.json").read_text())
failures = []
checked = 0
for entry in index["examples"]:
    file, endpoint = entry["file"], entry["endpoint"]
    op = doc["paths"][endpoint]["post"]
    req_model = model_of(op["requestBody"]["content"]["application/json"]["schema"]["$ref"])
    resp_model = model_of(op["responses"]["200"]["content"]["application/json"]["schema"]["$ref"])
    example = json.loads((ROOT / "api" / file).read_text())
    try:
        sent = req_model.model_validate(example).model_dump(mode="json", by_alias=True)
    except Exception as e:  # noqa: BLE001 - any refusal by the generated model is a finding
        failures.append(f"api/{file}: the generated request model refuses the example: {e}")
        continue
    status_plain, plain = post(endpoint, example)
    status_sent, answer = post(endpoint, sent)
    if status_sent != 200 or status_plain != 200:
        failures.append(
            f"api/{file}: sent through the generated model {status_sent} {answer}, plain {status_plain}"
        )
        continue
    if without_timing(answer) != without_timing(plain):
        failures.append(f"api/{file}: the answer differs from the plain example's")
    try:
        resp_model.model_validate(answer)
    except Exception as e:  # noqa: BLE001
        failures.append(f"api/{file}: the answer does not parse into the generated model: {e}")
        continue
    checked += 1
    print(f"ok  api/{file}: {nulls_in(sent)} nulls sent, answer parsed as {resp_model.__name__}")

if failures:
    print("\n".join(["FAILED:"] + failures), file=sys.stderr)
    sys.exit(1)
print(f"generated client: {checked} examples sent and parsed")
