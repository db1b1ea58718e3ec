"""Safety violations the simulator sees (ground truth, like the deliveries).

``SafetyMonitor`` records one ``Violation`` each time a condition *begins*:

- ``ground_contact``: a flying vehicle touched the ground (a crash);
- ``off_pad_landing``: a landing touched down farther than the dock radius
  (horizontally) from every station;
- ``people_proximity``: an airborne vehicle closer than ``people_clearance_m``
  (3-D) to a worker, debounced per (vehicle, worker); ``detail`` is the worker;
- ``separation``: two vehicles, at least one airborne, closer than
  ``separation_m`` (3-D: a landing onto a taken spot counts), debounced per
  pair, recorded under the lower id; ``detail`` is the other id.

A condition that stays true (hovering next to a worker) is one record; it
begins again once it has ended (moved away, landed).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from proto.site import Safety
from sim_fleet.modes import FlightState
from sim_fleet.physics import Vec3, horizontal_distance
from sim_fleet.vehicle import Vehicle

GROUND_CONTACT = "ground_contact"
OFF_PAD_LANDING = "off_pad_landing"
PEOPLE_PROXIMITY = "people_proximity"
SEPARATION = "separation"


@dataclass(frozen=True, slots=True)
class Violation:
    """Something that must never happen, as the simulator saw it."""

    kind: str
    vehicle_id: str
    time_s: float
    position: Vec3
    detail: str = ""


def _pair(a: Vehicle, b: Vehicle, gap_m: float) -> str:
    """Where two vehicles too close to each other were, for the record."""

    def one(v: Vehicle) -> str:
        x, y, z = v.position
        return f"{v.id} {v.state.name.lower()} {v.mode.name} at ({x:.1f}, {y:.1f}, {z:.1f})"

    return f"{gap_m:.2f} m apart: {one(a)}, {one(b)}"


class SafetyMonitor:
    """Watches state transitions and distances; appends to ``violations``."""

    def __init__(self, rules: Safety, pads: Iterable[Vec3], dock_radius_m: float) -> None:
        self.rules = rules
        self.pads = tuple(pads)
        self.dock_radius_m = dock_radius_m
        self.violations: list[Violation] = []
        self._near_people: set[tuple[str, str]] = set()
        self._too_close: set[tuple[str, str]] = set()

    def _record(self, kind: str, v: Vehicle, time_s: float, detail: str = "") -> None:
        self.violations.append(Violation(kind, v.id, time_s, v.position, detail))

    def transition(self, v: Vehicle, before: FlightState, time_s: float) -> None:
        """``v`` went from ``before`` to ``v.state`` during a physics step."""
        if before is FlightState.FLYING and v.state is FlightState.CRASHED:
            self._record(GROUND_CONTACT, v, time_s, f"flown into the ground in {v.mode.name}")
        elif before is FlightState.LANDING and v.state is FlightState.LANDED:
            near = min((horizontal_distance(v.position, p) for p in self.pads), default=math.inf)
            if near > self.dock_radius_m:
                self._record(OFF_PAD_LANDING, v, time_s, f"nearest pad {near:.1f} m away")

    def check(self, vehicles: Iterable[Vehicle], workers: dict[str, Vec3], time_s: float) -> None:
        """Distances after a physics step: people proximity and separation."""
        vehicles = list(vehicles)
        self._people([v for v in vehicles if v.airborne], workers, time_s)
        self._separation(vehicles, time_s)

    def _people(self, flying: list[Vehicle], workers: dict[str, Vec3], time_s: float) -> None:
        clearance = self.rules.people_clearance_m
        near: set[tuple[str, str]] = set()
        for v in flying:
            for wid, wpos in workers.items():
                if math.dist(v.position, wpos) < clearance:
                    near.add((v.id, wid))
                    if (v.id, wid) not in self._near_people:
                        self._record(PEOPLE_PROXIMITY, v, time_s, wid)
        self._near_people = near

    def _separation(self, vehicles: list[Vehicle], time_s: float) -> None:
        sep = self.rules.separation_m
        close: set[tuple[str, str]] = set()
        # sweep along x: only pairs less than ``sep`` apart in x can be too close
        vehicles.sort(key=lambda v: v.position[0])
        for i, a in enumerate(vehicles):
            for b in vehicles[i + 1 :]:
                if b.position[0] - a.position[0] >= sep:
                    break
                if not (a.airborne or b.airborne):
                    continue  # two on the ground: side by side on a station
                if (gap := math.dist(a.position, b.position)) < sep:
                    lo, hi = (a, b) if a.id < b.id else (b, a)
                    close.add((lo.id, hi.id))
                    if (lo.id, hi.id) not in self._too_close:
                        self._record(SEPARATION, lo, time_s, f"{hi.id} {_pair(lo, hi, gap)}")
        self._too_close = close
