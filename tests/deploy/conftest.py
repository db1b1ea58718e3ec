"""Fixtures of the Docker deployment tests: the image, built once per
session (offline: local base image + host wheelhouse), and one compose
project of the repository's docker-compose.yml shared by the tests of a
module, always removed (``down -v``) at the end. Skipped only when no Docker
daemon is reachable."""

from __future__ import annotations

import sys

import pytest

from tests.deploy.compose import (
    AGENTS,
    Stack,
    build_image,
    compose_command,
    docker_unavailable,
    poll,
)

SPEEDUP = 10.0


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Keep each phase's report on the test item (fixtures print logs on failure)."""
    outcome = yield
    report = outcome.get_result()
    setattr(item, f"report_{report.when}", report)


@pytest.fixture(scope="session")
def image():
    """Build local/python-base:bookworm (if missing) and linecrew:dev."""
    reason = docker_unavailable()
    if reason:
        pytest.skip(f"Docker deployment tests need a Docker daemon: {reason}")
    seconds = build_image()
    sys.stderr.write(f"\nlinecrew:dev built in {seconds:.0f} s\n")
    return "linecrew:dev"


@pytest.fixture(scope="module")
def stack(image):
    """The whole fleet in containers, every agent present; removed at the end."""
    deployment = Stack(compose_command(), SPEEDUP)
    try:
        deployment.up()
        poll(deployment.present, 120, f"agents {', '.join(AGENTS)} present")
        yield deployment
    except BaseException:
        sys.stderr.write(f"--- {deployment.project} logs ---\n{deployment.logs()}\n")
        raise
    finally:
        deployment.down()


@pytest.fixture
def fleet(stack, request):
    """The shared stack; prints the containers' logs if the test fails."""
    yield stack
    report = getattr(request.node, "report_call", None)
    if report is not None and report.failed:
        sys.stderr.write(f"--- {stack.project} logs ---\n{stack.logs(400)}\n")
