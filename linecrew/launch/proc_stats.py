"""CPU and memory of a run's processes, read from Linux ``/proc``: CPU % over
a window and resident memory at its end, summed per process kind."""

from __future__ import annotations

import dataclasses
import os
import pathlib
import time
from collections.abc import Iterable

from linecrew.launch.supervisor import Child

KINDS = ("router", "gs", "gateway", "sim", "agents")
_KIND_OF = {"router": "router", "ground-station": "gs", "gateway": "gateway", "sim": "sim"}


def kind_of(name: str) -> str:
    """The kind of a supervised process by its name (``agent-uav-1``, ``agents-2``: agents)."""
    return _KIND_OF.get(name, "agents" if name.startswith("agent") else name)


def cpu_s(pid: int) -> float:
    """User + system CPU seconds of ``pid`` so far (0 once it is gone)."""
    try:
        stat = pathlib.Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return 0.0
    fields = stat.rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def rss_mb(pid: int) -> float:
    """Resident memory of ``pid`` in MiB (0 once it is gone)."""
    try:
        status = pathlib.Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0.0
    line = next((ln for ln in status.splitlines() if ln.startswith("VmRSS:")), "VmRSS: 0 kB")
    return int(line.split()[1]) / 1024


@dataclasses.dataclass
class KindUsage:
    """What the processes of one kind used."""

    procs: int = 0
    cpu_pct: float = 0.0  # of one core, summed over the kind's processes
    rss_mb: float = 0.0


def measure(children: Iterable[Child], window_s: float) -> dict[str, KindUsage]:
    """CPU % over the next ``window_s`` seconds and RSS at its end, per kind."""
    pids = [(kind_of(c.name), c.popen.pid) for c in children]
    before = {pid: cpu_s(pid) for _, pid in pids}
    started = time.monotonic()
    time.sleep(window_s)
    elapsed = time.monotonic() - started
    usage = {kind: KindUsage() for kind in KINDS}
    for kind, pid in pids:
        entry = usage.setdefault(kind, KindUsage())
        entry.procs += 1
        entry.cpu_pct += 100.0 * (cpu_s(pid) - before[pid]) / elapsed
        entry.rss_mb += rss_mb(pid)
    return usage
