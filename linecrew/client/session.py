"""Which linecrew run the operator CLI talks to.

``linecrew up`` / ``demo`` / ``chaos`` (any :class:`~linecrew.launch.local_run.LocalRun`)
register their gateway in a session file and remove it when they stop. The
file holds every run started from here (several may be up at once); the CLI
takes the newest one whose gateway answers ``/healthz`` and says on stderr
which one it is.

Where the file is: ``$LINECREW_SESSION`` if set, else ``.linecrew/session.json``
in the current directory or the nearest parent that has one (so the CLI
works from anywhere inside the checkout), else in the current directory.

An explicit ``--url`` or ``LINECREW_URL`` skips all this (no health check:
the call itself says if nothing answers).
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import json
import os
import pathlib
import sys
import tempfile
import time
from collections.abc import Iterator

import httpx

from linecrew.client.gateway import Gateway, tls_verify
from proto.errors import LinecrewError

SESSION_ENV = "LINECREW_SESSION"
SESSION_NAME = pathlib.Path(".linecrew") / "session.json"


class NoRunError(LinecrewError, RuntimeError):
    """No gateway to talk to; the message (one line) says what was tried."""

    code = "no_run"


@dataclasses.dataclass(frozen=True)
class RunEntry:
    """One run's gateway, as registered by the process that started it."""

    url: str
    token: str = ""
    run_dir: str = ""
    pid: int = 0
    started_s: float = 0.0  # UNIX seconds
    speedup: float | None = None  # unknown in the old one-run format
    scenario: str = ""
    ca_file: str = ""  # the CA of an HTTPS gateway (a --secure run's site CA)

    def describe(self) -> str:
        """``run DIR (gateway URL, scenario S, xK)``."""
        parts = [f"gateway {self.url}"]
        if self.scenario:
            parts.append(f"scenario {self.scenario}")
        if self.speedup:
            parts.append(f"x{self.speedup:g}")
        where = f"run {self.run_dir}" if self.run_dir else "run"
        return f"{where} ({', '.join(parts)})"


def session_path(start: pathlib.Path | None = None) -> pathlib.Path:
    """The session file in force (it may not exist yet)."""
    if env := os.environ.get(SESSION_ENV):
        return pathlib.Path(env)
    here = (start or pathlib.Path.cwd()).resolve()
    for directory in (here, *here.parents):
        if (directory / SESSION_NAME).is_file():
            return directory / SESSION_NAME
    return here / SESSION_NAME


def read_runs(path: pathlib.Path) -> list[RunEntry]:
    """The runs a session file lists, oldest first (the old one-run format too);
    an unreadable file lists none."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return []
    items = data.get("runs", [data] if "url" in data else []) if isinstance(data, dict) else []
    fields = {f.name for f in dataclasses.fields(RunEntry)}
    runs = []
    for item in items:
        if isinstance(item, dict) and isinstance(item.get("url"), str):
            runs.append(RunEntry(**{k: v for k, v in item.items() if k in fields}))
    return runs


@contextlib.contextmanager
def _locked(path: pathlib.Path) -> Iterator[None]:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path.with_name(path.name + ".lock"), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _write(path: pathlib.Path, runs: list[RunEntry]) -> None:
    body = json.dumps({"runs": [dataclasses.asdict(r) for r in runs]}, indent=1)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".session-")
    with os.fdopen(fd, "w") as handle:
        handle.write(body)
    os.chmod(tmp, 0o600)  # it holds bearer tokens
    os.replace(tmp, path)


def _process_alive(pid: int) -> bool:
    if pid <= 0:
        return True  # unknown: keep it, the health check decides
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def register(entry: RunEntry, path: pathlib.Path | None = None) -> pathlib.Path:
    """Add a run to the session file (dropping runs whose process is gone)."""
    path = path or session_path()
    with _locked(path):
        runs = [r for r in read_runs(path) if _process_alive(r.pid) and r.url != entry.url]
        _write(path, [*runs, entry])
    return path


def unregister(url: str, path: pathlib.Path) -> None:
    """Remove the run with gateway ``url`` from the session file."""
    if not path.exists():
        return
    with _locked(path):
        runs = read_runs(path)
        kept = [r for r in runs if r.url != url and _process_alive(r.pid)]
        if kept != runs:
            _write(path, kept)


def healthy(url: str, timeout_s: float = 1.0, ca_file: str | None = None) -> bool:
    """Whether a gateway answers ``/healthz`` (over HTTPS: with a certificate
    ``ca_file`` vouches for)."""
    try:
        answer = httpx.get(
            f"{url.rstrip('/')}/healthz", timeout=timeout_s, verify=tls_verify(ca_file)
        )
        return answer.status_code == 200
    except httpx.HTTPError:
        return False


def live_run(path: pathlib.Path | None = None) -> RunEntry:
    """The newest registered run whose gateway answers; :class:`NoRunError` if none."""
    path = path or session_path()
    runs = read_runs(path)
    hint = "start one with 'linecrew up', or give --url URL / set LINECREW_URL"
    if not runs:
        where = f"{path} does not exist" if not path.exists() else f"{path} lists no run"
        raise NoRunError(f"no linecrew run found ({where}); {hint}")
    for run in sorted(runs, key=lambda r: r.started_s, reverse=True):
        if healthy(run.url, ca_file=run.ca_file or None):
            return run
    raise NoRunError(
        f"no linecrew run is up: none of the {len(runs)} run(s) in {path} answers; {hint}"
    )


@dataclasses.dataclass(frozen=True)
class Target:
    """Where a CLI call goes, and what is known of that run."""

    url: str
    token: str
    run: RunEntry | None = None  # when found through the session file

    def gateway(self) -> Gateway:
        """A client of this gateway (HTTPS checked against the run's CA, else
        ``$LINECREW_CA_FILE``)."""
        ca_file = self.run.ca_file if self.run and self.run.ca_file else None
        return Gateway(self.url, self.token, ca_file=ca_file)


def resolve(url: str | None, token: str | None, *, announce: bool = True) -> Target:
    """The gateway to use: ``url`` / ``LINECREW_URL``, else the live run of the
    session file (announced on stderr). Raises :class:`NoRunError`."""
    explicit = url or os.environ.get("LINECREW_URL")
    token = token or os.environ.get("LINECREW_TOKEN")
    if explicit:
        known = {r.url.rstrip("/"): r for r in read_runs(session_path())}
        run = known.get(explicit.rstrip("/"))
        return Target(explicit, token or (run.token if run else ""), run)
    run = live_run()
    if announce:
        print(f"linecrew: {run.describe()}", file=sys.stderr, flush=True)
    return Target(run.url, token or run.token, run)


def entry_for(
    url: str,
    token: str,
    run_dir: pathlib.Path,
    speedup: float,
    scenario: str,
    ca_file: str | None = None,
) -> RunEntry:
    """The entry this process registers for a run it started."""
    return RunEntry(
        url=url,
        token=token,
        run_dir=str(run_dir.resolve()),
        pid=os.getpid(),
        started_s=time.time(),
        speedup=speedup,
        scenario=scenario,
        ca_file=ca_file or "",
    )
