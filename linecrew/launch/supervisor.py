"""Child processes of ``linecrew up``: started in their own sessions with a
log file each, checked for health, stopped in reverse order (SIGTERM, then
SIGKILL), and told to die with their parent (Linux ``PR_SET_PDEATHSIG``) so
nothing is orphaned even if the supervisor is killed."""

from __future__ import annotations

import contextlib
import ctypes
import dataclasses
import logging
import os
import pathlib
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Mapping

from proto.errors import LinecrewError

log = logging.getLogger(__name__)

_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:  # runs in the child between fork and exec
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)


class StartError(LinecrewError):
    """A child exited or never became healthy; the message names it and its log."""

    code = "start_failed"


@dataclasses.dataclass
class Child:
    """One supervised process (its own session: signals go to its group)."""

    name: str
    popen: subprocess.Popen[bytes]
    log_path: pathlib.Path

    def alive(self) -> bool:
        """Still running."""
        return self.popen.poll() is None

    def output(self) -> str:
        """Everything it logged so far."""
        return self.log_path.read_text(errors="replace") if self.log_path.exists() else ""

    def tail(self, lines: int = 15) -> str:
        """The end of its log."""
        return "\n".join(self.output().splitlines()[-lines:])

    def terminate(self) -> None:
        """SIGTERM its group, if it runs."""
        if self.alive():
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.popen.pid, signal.SIGTERM)

    def finish(self, timeout_s: float) -> int:
        """Wait ``timeout_s`` for it to exit, then SIGKILL its group; its exit code."""
        try:
            return self.popen.wait(timeout_s)
        except subprocess.TimeoutExpired:
            log.warning("%s ignored SIGTERM; killing it", self.name)
            return self.kill()

    def stop(self, timeout_s: float = 10.0) -> int:
        """SIGTERM, then SIGKILL after ``timeout_s``; its exit code."""
        self.terminate()
        return self.finish(timeout_s)

    def kill(self) -> int:
        """SIGKILL its group now; its exit code."""
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.popen.pid, signal.SIGKILL)
        return self.popen.wait()


class Supervisor:
    """Starts, watches and stops the processes of one run."""

    def __init__(self, run_dir: pathlib.Path) -> None:
        self.run_dir = run_dir
        self.children: list[Child] = []

    def start(
        self, name: str, module: str, *args: str, env: Mapping[str, str] | None = None
    ) -> Child:
        """Start ``python -m module args...`` (see :meth:`run`)."""
        return self.run(name, [sys.executable, "-m", module, *args], env)

    def run(self, name: str, argv: list[str], env: Mapping[str, str] | None = None) -> Child:
        """Start ``argv`` logging to ``run_dir/name.log``, with ``env`` added
        to this process's environment."""
        log_path = self.run_dir / f"{name}.log"
        env = dict(os.environ, **(env or {}), PYTHONUNBUFFERED="1")
        with open(log_path, "wb") as log_file:
            popen = subprocess.Popen(
                [*self.command_prefix(name), *argv],
                stdout=log_file,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                env=env,
                start_new_session=True,
                preexec_fn=_die_with_parent,
            )
        child = Child(name, popen, log_path)
        self.children.append(child)
        return child

    def command_prefix(self, name: str) -> list[str]:
        """What runs child ``name``'s command (none: it runs here)."""
        return []

    def wait_ready(self, child: Child, ready: Callable[[], object], timeout_s: float) -> None:
        """Wait until ``ready()``; raise :class:`StartError` if the child dies or is late."""
        deadline = time.monotonic() + timeout_s
        while not ready():
            if not child.alive():
                raise StartError(
                    f"{child.name} exited with code {child.popen.returncode}; "
                    f"its log ({child.log_path}):\n{child.tail()}"
                )
            if time.monotonic() > deadline:
                raise StartError(
                    f"{child.name} not healthy after {timeout_s:.0f} s; "
                    f"its log ({child.log_path}):\n{child.tail()}"
                )
            time.sleep(0.05)

    def dead(self) -> list[Child]:
        """Children that have exited."""
        return [c for c in self.children if not c.alive()]

    def stop_all(self, timeout_s: float = 10.0) -> None:
        """SIGTERM every child (newest first), then SIGKILL what is left."""
        for child in reversed(self.children):
            child.terminate()
        deadline = time.monotonic() + timeout_s
        for child in reversed(self.children):
            child.finish(max(0.1, deadline - time.monotonic()))
