"""Schemathesis against the live gateway of a running fleet: every operation
of its OpenAPI, valid and invalid requests, checked for answers it documents
(status, content type, response schema), invalid input rejected, and no
server error but a documented 503 in the error shape."""

from __future__ import annotations

import pytest
import schemathesis
from hypothesis import HealthCheck, given, settings
from hypothesis.errors import Unsatisfiable
from schemathesis import GenerationMode
from schemathesis.specs.openapi.checks import (
    content_type_conformance,
    negative_data_rejection,
    response_schema_conformance,
    status_code_conformance,
)

from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew_runtime.scenarios import load

EXAMPLES = 60  # per operation and mode (about a minute in all)


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    options = RunOptions(speedup=10.0, run_dir=tmp_path_factory.mktemp("fuzz") / "run")
    with LocalRun(load("paper"), options) as run:
        yield run


def only_a_documented_503(ctx, response, case) -> None:
    """No 5xx but 503, and that one in the error shape."""
    if response.status_code < 500:
        return
    assert response.status_code == 503, f"{case.method} {case.path}: {response.status_code}"
    body = response.json()
    assert set(body) >= {"error", "message", "field"}, body


CHECKS = [
    only_a_documented_503,
    status_code_conformance,
    content_type_conformance,
    response_schema_conformance,
    negative_data_rejection,
]


def fuzz(operation, mode: GenerationMode, headers: dict[str, str]) -> None:
    """EXAMPLES generated requests to ``operation``, each checked."""

    @given(case=operation.as_strategy(generation_mode=mode))
    @settings(
        max_examples=EXAMPLES,
        deadline=None,
        suppress_health_check=list(HealthCheck),
        derandomize=True,
        database=None,
    )
    def run(case) -> None:
        case.call_and_validate(headers=headers, checks=CHECKS, timeout=10)

    run()


def test_every_operation_answers_only_what_it_documents(live):
    schema = schemathesis.openapi.from_url(f"{live.url}/openapi.json")
    headers = {"Authorization": f"Bearer {live.token}"}
    failures, tried = [], 0
    for result in schema.get_all_operations():
        operation = result.ok()
        if operation.path == "/v1/events":
            continue  # a stream that never ends: tests/ground_station/gateway
        for mode in (GenerationMode.POSITIVE, GenerationMode.NEGATIVE):
            tried += 1
            try:
                fuzz(operation, mode, headers)
            except Unsatisfiable:
                assert mode is GenerationMode.NEGATIVE  # nothing in it can be made invalid
            except Exception as exc:
                failures.append(f"{operation.label} ({mode}): {exc}")
    assert tried >= 30, tried  # every operation, both ways
    assert not failures, "\n\n".join(failures)
