"""How long each vehicle really watched each worker (ground truth for the
monitoring credit the ground station records).

A vehicle watches a worker while it is flying, hovering (no faster than the
rules' ``hover_speed_mps``), above the worker's head and within
``watch_radius_m`` of them horizontally; each moment counts for the nearest
such worker only. The log is generous on purpose (any hover near a worker
counts, a delivery's too): recorded monitoring seconds above it were not
flown.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from sim_fleet import physics
from sim_fleet.modes import FlightState
from sim_fleet.physics import Vec3
from sim_fleet.rules import InteractionRules
from sim_fleet.vehicle import Vehicle


class Seconds(dict[tuple[str, str], float]):
    """Seconds per (worker id, vehicle id); like a ``Counter``, 0.0 for a
    pair not credited yet, without adding it."""

    def __missing__(self, key: tuple[str, str]) -> float:
        return 0.0


class WatchLog:
    """Watched seconds per (worker id, vehicle id), summed over the run."""

    def __init__(self, rules: InteractionRules) -> None:
        self.rules = rules
        self.seconds = Seconds()

    def step(self, vehicles: Iterable[Vehicle], workers: dict[str, Vec3], dt_s: float) -> None:
        """Credit ``dt_s`` to every vehicle watching a worker now."""
        reach = self.rules.watch_radius_m
        for v in vehicles:
            if v.state is not FlightState.FLYING:
                continue
            if physics.speed(v.velocity) > self.rules.hover_speed_mps:
                continue
            near, who = reach, None
            for wid, wpos in workers.items():
                d = math.hypot(v.position[0] - wpos[0], v.position[1] - wpos[1])
                if d <= near and v.position[2] > wpos[2]:
                    near, who = d, wid
            if who is not None:
                self.seconds[who, v.id] += dt_s
