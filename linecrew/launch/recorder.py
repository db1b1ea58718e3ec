"""What the fleet actually did during a demo: each UAV's task intervals, from
its status over time, with the task kinds taken from the plans."""

from __future__ import annotations

import dataclasses
from typing import Any


@dataclasses.dataclass
class _Open:
    task_id: str
    kind: str
    start_s: float


class ExecutionRecorder:
    """Feed it fleet and plan snapshots; it keeps ``(start, end, kind)`` per UAV."""

    def __init__(self) -> None:
        self.kinds: dict[str, str] = {}  # task id -> kind, from every plan seen
        self.segments: dict[str, list[tuple[float, float, str]]] = {}
        self._open: dict[str, _Open] = {}

    def plans(self, plans: list[dict[str, Any]]) -> None:
        """Remember the kind of every planned task."""
        for plan in plans:
            for task in plan["tasks"]:
                self.kinds[task["task_id"]] = task["type"]

    def fleet(self, uavs: list[dict[str, Any]], now_s: float) -> None:
        """Close and open intervals where a UAV's current task changed."""
        for uav in uavs:
            task_id = (uav.get("status") or {}).get("task_id")
            current = self._open.get(uav["uav_id"])
            if current and current.task_id == task_id:
                continue
            if current:
                self._close(uav["uav_id"], current, now_s)
            if task_id:
                kind = self.kinds.get(task_id, "?")
                self._open[uav["uav_id"]] = _Open(task_id, kind, now_s)
            else:
                self._open.pop(uav["uav_id"], None)

    def finish(self, now_s: float) -> None:
        """Close every open interval."""
        for uav_id, current in list(self._open.items()):
            self._close(uav_id, current, now_s)
        self._open.clear()

    def count(self, kind: str) -> int:
        """How many intervals of ``kind`` were flown in all."""
        return sum(1 for segs in self.segments.values() for _, _, k in segs if k == kind)

    def _close(self, uav_id: str, current: _Open, now_s: float) -> None:
        self.segments.setdefault(uav_id, []).append((current.start_s, now_s, current.kind))
