"""``linecrew router``: routes between clients, shows its health token, stops
cleanly on SIGTERM and SIGINT, fails clearly when it cannot listen."""

from __future__ import annotations

import os
import signal
import subprocess

import pytest

from linecrew_runtime.bus import Bus, BusConfig
from proto import KeySpace, Role
from tests.support.processes import free_port, port_open, router_args, running, wait_until


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_router_declares_its_token_and_exits_cleanly_on_signal(sig):
    port = free_port()
    with running(router_args(port), "router", lambda: port_open(port)) as proc:
        with Bus.open(BusConfig(connect=(f"tcp/127.0.0.1:{port}",))) as bus:
            token = KeySpace().alive(Role.ROUTER, "router")
            wait_until(lambda: token in bus.alive(token), 10, "router token")
        os.killpg(proc.popen.pid, sig)
        assert proc.popen.wait(10) == 0
        assert "router stopping on " + sig.name in proc.output()


def test_router_that_cannot_listen_exits_with_an_error():
    port = free_port()
    with running(router_args(port), "router", lambda: port_open(port)):
        second = subprocess.run(
            [*router_args(port), "--log-format", "json"], capture_output=True, text=True, timeout=30
        )
    assert second.returncode == 1
    assert '"level": "error"' in second.stderr and "cannot start" in second.stderr
