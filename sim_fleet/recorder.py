"""A flight recorder: where each vehicle was and where it was sent over the
last seconds, so that a separation violation in the log shows how the two
vehicles came together (which one moved, towards what) and not only where
they met.
"""

from __future__ import annotations

import collections
from collections.abc import Iterable

from sim_fleet.modes import FlightState
from sim_fleet.physics import Vec3
from sim_fleet.vehicle import Vehicle

EVERY_S = 0.5
"""Simulated seconds between two snapshots."""
KEEP_S = 20.0
"""Simulated seconds of history kept."""


def _xyz(p: Vec3 | None) -> str:
    return "-" if p is None else f"({p[0]:.1f}, {p[1]:.1f}, {p[2]:.1f})"


Snapshot = tuple[Vec3, Vec3 | None, FlightState]
"""A vehicle's position, position target and flight state."""


class FlightRecorder:
    """Snapshots of every vehicle's position, target and flight state, kept
    raw (the world steps often; the log reads them rarely) and written out
    only by :meth:`track`."""

    def __init__(self) -> None:
        self._frames: collections.deque[tuple[float, dict[str, Snapshot]]] = collections.deque()
        self._next_s = 0.0

    def step(self, vehicles: Iterable[Vehicle], time_s: float) -> None:
        """Take a snapshot if one is due at ``time_s``."""
        if time_s < self._next_s:
            return
        self._next_s = time_s + EVERY_S
        frame = {v.id: (v.position, v.target, v.state) for v in vehicles}
        self._frames.append((time_s, frame))
        while self._frames and self._frames[0][0] < time_s - KEEP_S:
            self._frames.popleft()

    def track(self, vehicle_ids: Iterable[str]) -> list[str]:
        """One line per snapshot kept: time, then each vehicle's position -> target."""
        ids = list(vehicle_ids)
        return [
            f"{t:8.1f} " + "; ".join(f"{v} {_snapshot(frame.get(v))}" for v in ids)
            for t, frame in self._frames
        ]


def _snapshot(snapshot: Snapshot | None) -> str:
    if snapshot is None:
        return "?"
    position, target, state = snapshot
    return f"{_xyz(position)} -> {_xyz(target)} {state.name.lower()}"
