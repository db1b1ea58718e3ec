"""A ground station and a gateway process over a real router."""

from __future__ import annotations

import sys

import httpx
import pytest

from proto import KeySpace, Role
from tests.support.processes import free_port, running, running_alive

TOKEN = "test-token-123"
KEYS = KeySpace()


@pytest.fixture
def gs(router, bus_config, tmp_path):
    args = [
        sys.executable,
        "-m",
        "ground_station",
        "--connect",
        router,
        "--db",
        str(tmp_path / "gs.db"),
    ]
    token = KEYS.alive(Role.GROUND_STATION, "gs")
    with running_alive(args, "gs", bus_config, token) as proc:
        yield proc


@pytest.fixture
def gateway_process(router, gs):
    """A running gateway process; yields it and its base URL."""
    port = free_port()
    args = [
        sys.executable,
        "-m",
        "ground_station.gateway",
        "--connect",
        router,
        "--port",
        str(port),
        "--token",
        TOKEN,
        "--rpc-timeout",
        "1.0",
    ]
    base = f"http://127.0.0.1:{port}"

    def healthy() -> bool:
        try:
            return httpx.get(f"{base}/healthz", timeout=1).status_code == 200
        except httpx.HTTPError:
            return False

    with running(args, "gateway", healthy) as proc:
        yield proc, base


@pytest.fixture
def gateway_url(gateway_process):
    """The base URL of a running gateway process."""
    return gateway_process[1]


@pytest.fixture
def gateway(gateway_url):
    """An HTTP client of the gateway with the right token."""
    headers = {"Authorization": f"Bearer {TOKEN}"}
    with httpx.Client(base_url=gateway_url, headers=headers, timeout=10) as client:
        yield client
