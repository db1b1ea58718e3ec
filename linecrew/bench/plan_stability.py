"""Measurement 2 of ``linecrew bench ground-station``: plan stability, read
from the ground station's events (collected with their arrival times by
:class:`EventWatch`, which the other measurements wait on too) and from
its metrics (whether the background improvement has settled)."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from linecrew.launch.proc_stats import cpu_s
from linecrew_runtime.bus import Bus
from proto import EventKind, GetMetrics, GsEvent, KeySpace, MetricsReply


class EventWatch:
    """Collects ground-station events with their arrival times."""

    def __init__(self, bus: Bus, keys: KeySpace) -> None:
        self.items: list[tuple[float, GsEvent]] = []
        self._cond = threading.Condition()
        bus.subscribe(keys.events(), GsEvent, self._on_event)

    def _on_event(self, _key: str, event: GsEvent) -> None:
        with self._cond:
            self.items.append((time.perf_counter(), event))
            self._cond.notify_all()

    def wait_for(
        self, predicate: Callable[[GsEvent], bool], timeout_s: float, since: float = 0.0
    ) -> tuple[float, GsEvent] | None:
        """The first (time, event) after ``since`` satisfying ``predicate``."""
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while True:
                found = next(
                    (item for item in self.items if item[0] >= since and predicate(item[1])), None
                )
                remaining = deadline - time.monotonic()
                if found or remaining <= 0:
                    return found
                self._cond.wait(remaining)


def improvements(watch: EventWatch, since: float) -> set[int | None]:
    """Epochs of the improvements adopted since ``since``."""
    return {
        e.epoch
        for t, e in watch.items
        if e.kind == EventKind.REPLAN and t >= since and e.detail.startswith("improvement")
    }


def settle(client: Bus, keys: KeySpace, timeout_s: float = 120.0) -> float:
    """Wait until the gs's plan is final (the background improvement of the
    last trigger's state done); returns the seconds it took."""
    started = time.perf_counter()
    while time.perf_counter() - started < timeout_s:
        metrics = client.query(keys.rpc("metrics"), GetMetrics(), MetricsReply, 10.0)
        if metrics.values.get("planner_settled") == 1.0:
            break
        time.sleep(0.1)
    return time.perf_counter() - started


def measure_stability(
    client: Bus,
    keys: KeySpace,
    watch: EventWatch,
    since: float,
    counts: tuple[int, int],
    steady_s: float,
    gs_pid: int,
) -> dict[str, float]:
    """Epochs per trigger during the submissions (from ``since``), how long
    the improvement of the last state ran, then epochs per UAV per minute and
    the gs's CPU while nothing happens (the gs runs at x1)."""
    uavs, events = counts
    settle_s = settle(client, keys)
    quiet_from = time.perf_counter()
    changes = [(t, e) for t, e in watch.items if e.kind == EventKind.PLAN_CHANGED]
    improved = improvements(watch, since)
    epochs = {e.epoch for t, e in changes if t >= since} - improved
    before = {e.epoch for t, e in changes if t < since}
    cpu = cpu_s(gs_pid)
    time.sleep(steady_s)
    cpu = cpu_s(gs_pid) - cpu
    improved = improvements(watch, since)  # adopted late: counted apart, not as steady
    quiet = {
        e.epoch
        for t, e in watch.items
        if e.kind == EventKind.PLAN_CHANGED
        and t >= quiet_from
        and e.epoch not in epochs | before | improved
    }
    return {
        "epochs_per_submit": len(epochs) / max(1, events),
        "improvement_epochs": float(len(improved)),
        "improvement_settle_s": settle_s,
        "steady_epochs_per_uav_min": len(quiet) / uavs / (steady_s / 60.0),
        "steady_gs_cpu_pct": 100.0 * cpu / steady_s,
    }
