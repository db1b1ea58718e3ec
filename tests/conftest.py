"""Fixtures shared by all tests: a real Zenoh router on a free port; every
run a test starts registers in a session file of its own, never in the
user's ``.linecrew/session.json``."""

from __future__ import annotations

import pytest

from linecrew_runtime.bus import BusConfig
from tests.support.processes import free_port, port_open, router_args, running


@pytest.fixture(autouse=True, scope="session")
def private_session_file(tmp_path_factory):
    """``LINECREW_SESSION`` points into the test's temporary directory, for
    this process and every process a test starts."""
    path = tmp_path_factory.mktemp("linecrew-session") / "session.json"
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("LINECREW_SESSION", str(path))
        yield path


@pytest.fixture
def router():
    """A running ``linecrew router`` process; yields its endpoint."""
    port = free_port()
    with running(router_args(port), "router", lambda: port_open(port)):
        yield f"tcp/127.0.0.1:{port}"


@pytest.fixture
def bus_config(router):
    """Client settings for the test router."""
    return BusConfig(connect=(router,))
