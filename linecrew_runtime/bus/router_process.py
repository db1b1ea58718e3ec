"""Start a ``linecrew router`` child process on a free loopback port."""

from __future__ import annotations

import contextlib
import socket
import subprocess
import sys
import time
from collections.abc import Iterator


def free_port() -> int:
    """A TCP port free on 127.0.0.1 right now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@contextlib.contextmanager
def router_process(site: str = "default", lease_ms: int = 1000) -> Iterator[str]:
    """Run a router until the block ends; yields its endpoint once it listens."""
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    args = [
        sys.executable,
        "-m",
        "linecrew_runtime.bus.router",
        "--listen",
        endpoint,
        "--site",
        site,
        "--lease-ms",
        str(lease_ms),
        "--log-level",
        "warning",
    ]
    proc = subprocess.Popen(args, start_new_session=True)
    try:
        deadline = time.monotonic() + 20
        while not port_open(port):
            if proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"router on {endpoint} did not start")
            time.sleep(0.02)
        yield endpoint
    finally:
        proc.terminate()
        proc.wait(10)


def port_open(port: int) -> bool:
    """Whether something accepts TCP connections on 127.0.0.1:port."""
    with socket.socket() as sock:
        sock.settimeout(0.2)
        return sock.connect_ex(("127.0.0.1", port)) == 0
