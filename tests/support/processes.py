"""Start real linecrew processes for integration tests and stop them for sure."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator

from linecrew.bus import Bus, BusConfig
from linecrew.bus.router_process import free_port, port_open

__all__ = [
    "Process",
    "free_port",
    "port_open",
    "router_args",
    "running",
    "running_alive",
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


class Process:
    """A child process in its own session, its output captured to a file."""

    def __init__(self, args: list[str], name: str) -> None:
        self.name = name
        fd, self.log_path = tempfile.mkstemp(prefix=f"{name}-", suffix=".log")
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        with os.fdopen(fd, "wb") as log:
            self.popen = subprocess.Popen(
                args, stdout=log, stderr=subprocess.STDOUT, start_new_session=True, env=env
            )

    def output(self) -> str:
        """Everything the process printed so far."""
        with open(self.log_path, errors="replace") as handle:
            return handle.read()

    def stop(self, timeout_s: float = 10.0) -> int:
        """SIGTERM, then SIGKILL to the group after ``timeout_s``; the exit code."""
        if self.popen.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.popen.pid, signal.SIGTERM)
            try:
                self.popen.wait(timeout_s)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(self.popen.pid, signal.SIGKILL)
                self.popen.wait()
        return self.popen.returncode

    def kill(self) -> None:
        """SIGKILL the group now."""
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.popen.pid, signal.SIGKILL)
        self.popen.wait()


@contextlib.contextmanager
def running(args: list[str], name: str, ready: Callable[[], object]) -> Iterator[Process]:
    """Run a process until the block ends; wait for ``ready()`` first; print
    its log if anything fails."""
    proc = Process(args, name)
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
) -> Iterator[Process]:
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
        "linecrew.bus.router",
        "--listen",
        f"tcp/127.0.0.1:{port}",
        *extra,
    ]
