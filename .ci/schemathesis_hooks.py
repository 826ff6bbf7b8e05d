"""mechcalc's contract rule for schema-valid requests, as a schemathesis check.

A request the document accepts must be answered (2xx), or refused only for a rule the operation
lists under `x-cross-field-rules` (a 422 whose `code` is one of those codes), or shed for load
(503 with Retry-After). `positive_data_acceptance` (configured in schemathesis.toml to let 422
and 503 through) checks the status; this check checks the code of every such 422.
Loaded with SCHEMATHESIS_HOOKS=schemathesis_hooks (PYTHONPATH=.ci).
"""

import json

import schemathesis
from schemathesis.generation.modes import GenerationMode


@schemathesis.check
def cross_field_rule_codes(ctx, response, case):
    meta = case.meta
    if meta is None or meta.generation.mode != GenerationMode.POSITIVE:
        return None
    if response.status_code != 422:
        return None
    listed = {r.get("code") for r in case.operation.definition.raw.get("x-cross-field-rules", [])}
    # The document's `x-service-rules` (every operation): a non-finite answer refused as a typed
    # 422; the service also logs it as a defect, which fails .ci/fuzz_api on its own.
    listed.add("NON_FINITE_ANSWER")
    try:
        body = json.loads(response.content)
    except ValueError as e:
        raise AssertionError(f"a 422 without a JSON problem body: {e}") from e
    code = body.get("code")
    if code not in listed:
        raise AssertionError(
            f"a schema-valid request was refused with 422 code {code!r}, which "
            f"{case.operation.label} does not list in x-cross-field-rules "
            f"({sorted(c for c in listed if c)}): {body.get('detail')!r} {body.get('errors')!r}"
        )
    return None
