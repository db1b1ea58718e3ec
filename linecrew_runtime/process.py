"""What every long-running linecrew process shares: common command-line
flags, the run and bus settings they imply, and shutdown on SIGINT/SIGTERM."""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import dataclasses
import logging
import os
import signal
import threading

from linecrew_runtime.bus import BusConfig
from linecrew_runtime.logs import configure_logging
from linecrew_runtime.settings import EnvSettings

log = logging.getLogger(__name__)

DEFAULT_SITE = "default"
"""The site id of a process with neither a scenario nor ``--site`` /
``LINECREW_SITE`` (the id of the shipped scenarios)."""


@dataclasses.dataclass(frozen=True, kw_only=True)
class RunSettings(EnvSettings):
    """What every process of a run shares (flags override ``LINECREW_*``)."""

    ENV_PREFIX = "LINECREW_"

    site: str | None = None  # key space root; None: the scenario's (else DEFAULT_SITE)
    speedup: float = 1.0  # mission seconds per wall second


def site_id(site: str | None = None) -> str:
    """The site of a process without a scenario: ``site`` (its ``--site``),
    else ``LINECREW_SITE``, else :data:`DEFAULT_SITE`. Raises ``ValueError``."""
    return RunSettings.from_env(site=site).site or DEFAULT_SITE


def common_parser(prog: str, description: str) -> argparse.ArgumentParser:
    """An argument parser with the flags every process takes."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument(
        "--site",
        help="site id (key space root; else LINECREW_SITE); must match the scenario's",
    )
    parser.add_argument(
        "--connect", action="append", help="zenoh endpoint to connect to (repeatable)"
    )
    parser.add_argument("--listen", action="append", help="zenoh endpoint to listen on")
    parser.add_argument("--zenoh-config", help="a zenoh json5 config file applied first")
    parser.add_argument("--lease-ms", type=int, help="zenoh transport lease (ms)")
    parser.add_argument(
        "--speedup",
        type=float,
        help="mission seconds per wall second (else LINECREW_SPEEDUP, 1); "
        "the same for every process of a run",
    )
    parser.add_argument("--log-level", default="info", help="debug, info, warning, error")
    parser.add_argument("--log-format", choices=["plain", "json"], default="plain")
    return parser


def start(args: argparse.Namespace, process: str, mode: str | None = None) -> BusConfig:
    """Configure logging for ``process``, resolve ``args.site`` and
    ``args.speedup`` (:class:`RunSettings`) and return its bus settings
    (``mode`` forced, else ``LINECREW_ZENOH_MODE`` or client); flags override
    ``LINECREW_*`` variables. Exits 2 on a bad variable."""
    configure_logging(args.log_level, args.log_format, process)
    try:
        run = RunSettings.from_env(site=args.site, speedup=args.speedup)
        bus = BusConfig.from_env(
            mode=mode,
            connect=tuple(args.connect) if args.connect else None,
            listen=tuple(args.listen) if args.listen else None,
            config_file=args.zenoh_config,
            lease_ms=args.lease_ms,
        )
    except ValueError as exc:
        log.error("%s cannot start: %s", process, exc)
        raise SystemExit(2) from None
    args.site, args.speedup = run.site, run.speedup
    return bus


WAIT_SLICE_S = 0.2
"""How long the main thread sleeps at a time while it waits for a signal."""
DEADLINE_S = 20.0
"""A process still running this long after a signal asked it to stop exits at
once: a close that hangs must not leave it running with nobody to stop it
(children of a killed ``linecrew up`` are asked by the kernel, and a
supervisor that is alive kills its children after 10 s anyway)."""
EXIT_OVERDUE = 70
"""The exit code of a process that did not stop within ``DEADLINE_S``."""


class Shutdown:
    """Set when SIGINT or SIGTERM arrives; usable from threads and asyncio."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self, deadline_s: float | None = DEADLINE_S) -> None:
        self.deadline_s = deadline_s
        self._event = threading.Event()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._async_event: asyncio.Event | None = None
        self.signal_name = ""

    def install(self) -> Shutdown:
        """Install the handlers (main thread only)."""
        for sig in self.SIGNALS:
            signal.signal(sig, self._on_signal)
        return self

    def _on_signal(self, signum: int, _frame: object) -> None:
        """A signal asks for shutdown; the process exits by force if it is
        still running ``deadline_s`` later."""
        if not self._event.is_set() and self.deadline_s is not None:
            timer = threading.Timer(self.deadline_s, self._overdue)
            timer.daemon = True
            timer.start()
        self.signal_name = signal.Signals(signum).name
        self.request()

    def is_set(self) -> bool:
        """Whether shutdown was requested."""
        return self._event.is_set()

    def request(self) -> None:
        """Ask for shutdown from code (e.g. a fatal error in a component)."""
        self._event.set()
        if self._loop is not None and self._async_event is not None:
            with contextlib.suppress(RuntimeError):  # loop already closed
                self._loop.call_soon_threadsafe(self._async_event.set)

    def _overdue(self) -> None:
        log.error("still running %.0f s after shutdown was asked for; exiting now", self.deadline_s)
        logging.shutdown()
        os._exit(EXIT_OVERDUE)

    def wait(self, timeout_s: float | None = None) -> bool:
        """Block until shutdown is requested (or the timeout passes). Waits in
        short slices: a signal the kernel hands to another thread (Zenoh's)
        runs its Python handler only once the main thread wakes up."""
        if timeout_s is not None:
            return self._event.wait(timeout_s)
        while not self._event.wait(WAIT_SLICE_S):
            pass
        return True

    async def wait_async(self) -> None:
        """Await shutdown from the running event loop."""
        if self._async_event is None:
            self._loop = asyncio.get_running_loop()
            self._async_event = asyncio.Event()
            if self._event.is_set():
                self._async_event.set()
        await self._async_event.wait()
