"""Fixtures shared by all tests: a real Zenoh router on a free port."""

from __future__ import annotations

import pytest

from linecrew.bus import BusConfig
from tests.support.processes import free_port, port_open, router_args, running


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
