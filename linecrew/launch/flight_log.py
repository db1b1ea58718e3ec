"""What the UAVs reported during a local run, for ``linecrew report``:
``RUN_DIR/flight.jsonl``, one JSON object a line.

The ground station's store keeps actions, plans and events but not where
the UAVs flew nor their batteries, so the launcher listens to the bus as
any operator tool could and keeps the smallest record that draws tracks,
battery curves and the executed timeline:

- ``telemetry``: position (ENU m), battery and flight state, written when
  the UAV moved 0.5 m, its battery changed by half a percent, its flight
  state, mode or tool changed, or 5 wall seconds passed (and the last one
  of each UAV when the log closes);
- ``status``: the agent's state, current task and epoch, on change only;
- ``outcome``: every task outcome, as sent.

Telemetry, not the simulator's ground truth: it is what the ground station
saw and decided on, and it exists with real vehicles too. Times are mission
seconds (``t``).
"""

from __future__ import annotations

import json
import math
import pathlib
import threading
import time
from typing import Any

import msgspec

from linecrew_runtime.bus import Bus
from proto.keys import KeySpace, UavTopic
from proto.telemetry import AgentStatus, TaskOutcome, Telemetry

MOVED_M = 0.5
BATTERY_STEP = 0.005
QUIET_S = 5.0  # wall seconds


class FlightLog:
    """Subscribes to every UAV's telemetry, status and outcomes; appends lines."""

    def __init__(self, bus: Bus, keys: KeySpace, path: pathlib.Path) -> None:
        self.path = path
        self._lock = threading.Lock()
        self._file = open(path, "a", encoding="utf-8")  # noqa: SIM115 (closed in close())
        self._last_tel: dict[str, tuple[float, Telemetry]] = {}  # the last written
        self._latest: dict[str, Telemetry] = {}  # the last received
        self._last_status: dict[str, tuple[Any, ...]] = {}
        self._subs = [
            bus.subscribe(keys.all_uavs(UavTopic.TELEMETRY), Telemetry, self._telemetry),
            bus.subscribe(keys.all_uavs(UavTopic.STATUS), AgentStatus, self._status),
            bus.subscribe(keys.all_uavs(UavTopic.OUTCOME), TaskOutcome, self._outcome),
        ]

    def close(self) -> None:
        """Stop listening and close the file."""
        for sub in self._subs:
            sub.close()
        self._subs = []
        for uav_id, tel in list(self._latest.items()):  # where each UAV ended
            written = self._last_tel.get(uav_id)
            if written is None or written[1] is not tel:
                self._write(_telemetry_line(tel))
        with self._lock:
            self._file.close()

    def _write(self, line: dict[str, Any]) -> None:
        with self._lock:
            if not self._file.closed:
                self._file.write(json.dumps(line, separators=(",", ":")) + "\n")
                self._file.flush()

    def _telemetry(self, _key: str, tel: Telemetry) -> None:
        now = time.monotonic()
        self._latest[tel.uav_id] = tel
        last = self._last_tel.get(tel.uav_id)
        if last is not None and not _worth_writing(last[1], tel, now - last[0]):
            return
        self._last_tel[tel.uav_id] = (now, tel)
        self._write(_telemetry_line(tel))

    def _status(self, _key: str, status: AgentStatus) -> None:
        state = (str(status.state), status.task_id, status.epoch)
        if self._last_status.get(status.uav_id) == state:
            return
        self._last_status[status.uav_id] = state
        self._write(
            {
                "kind": "status",
                "uav_id": status.uav_id,
                "t": status.stamp_s,
                "state": str(status.state),
                "task_id": status.task_id,
                "epoch": status.epoch,
                "reason": status.reason,
            }
        )

    def _outcome(self, _key: str, outcome: TaskOutcome) -> None:
        line = msgspec.to_builtins(outcome)
        line.pop("schema_version", None)
        self._write({"kind": "outcome", "t": outcome.stamp_s, **line})


def _telemetry_line(tel: Telemetry) -> dict[str, Any]:
    p = tel.position
    return {
        "kind": "telemetry",
        "uav_id": tel.uav_id,
        "t": tel.stamp_s,
        "x": round(p.x_m, 2),
        "y": round(p.y_m, 2),
        "z": round(p.z_m, 2),
        "battery": round(tel.battery_fraction, 4),
        "battery_wh": round(tel.battery_wh, 3),
        "flight_state": str(tel.flight_state),
        "mode": tel.mode,
        "tool": tel.tool,
    }


def _worth_writing(last: Telemetry, tel: Telemetry, wall_s: float) -> bool:
    a, b = last.position, tel.position
    return (
        wall_s >= QUIET_S
        or math.dist((a.x_m, a.y_m, a.z_m), (b.x_m, b.y_m, b.z_m)) >= MOVED_M
        or abs(last.battery_fraction - tel.battery_fraction) >= BATTERY_STEP
        or (last.flight_state, last.mode, last.tool) != (tel.flight_state, tel.mode, tel.tool)
    )
