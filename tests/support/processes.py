"""Start real linecrew processes for integration tests, the one way the
product does (:class:`linecrew.launch.supervisor.Supervisor`), and stop
them for sure."""

from __future__ import annotations

import contextlib
import pathlib
import sys
import tempfile
import time
from collections.abc import Callable, Iterator

from linecrew.launch.supervisor import Child, Supervisor
from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.bus.router_process import free_port, port_open

__all__ = [
    "Child",
    "free_port",
    "port_open",
    "router_args",
    "running",
    "running_alive",
    "start",
    "wait_until",
]


def wait_until(
    predicate: Callable[[], object],
    timeout_s: float = 10.0,
    what: str = "",
    period_s: float = 0.01,
) -> None:
    """Poll ``predicate`` every ``period_s`` until it is truthy; fail the test
    after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout_s} s waiting for {what or predicate}")
        time.sleep(period_s)


def start(args: list[str], name: str) -> Child:
    """Start ``args`` as the product starts its processes (its own session,
    dying with this one), logging to a fresh directory."""
    return Supervisor(pathlib.Path(tempfile.mkdtemp(prefix=f"linecrew-{name}-"))).run(name, args)


@contextlib.contextmanager
def running(args: list[str], name: str, ready: Callable[[], object]) -> Iterator[Child]:
    """Run a process until the block ends; wait for ``ready()`` first; print
    its log if anything fails."""
    proc = start(args, name)
    try:
        wait_until(lambda: ready() or proc.popen.poll() is not None, 20.0, f"{name} ready")
        if proc.popen.poll() is not None:
            raise AssertionError(f"{name} exited with {proc.popen.returncode}")
        yield proc
    except BaseException:
        proc.stop()
        sys.stderr.write(f"--- {name} log ---\n{proc.output()}\n")
        raise
    finally:
        proc.stop()


@contextlib.contextmanager
def running_alive(
    args: list[str], name: str, bus_config: BusConfig, token_key: str
) -> Iterator[Child]:
    """:func:`running`, ready once the process's liveliness ``token_key`` is seen."""
    with (
        Bus.open(bus_config) as watcher,
        running(args, name, lambda: token_key in watcher.alive(token_key)) as proc,
    ):
        yield proc


def router_args(port: int, *extra: str) -> list[str]:
    """Command line of a router listening on 127.0.0.1:port."""
    return [
        sys.executable,
        "-m",
        "linecrew_runtime.bus.router",
        "--listen",
        f"tcp/127.0.0.1:{port}",
        *extra,
    ]
