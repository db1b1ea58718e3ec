"""The site description shared by the ground station and the simulator:
geodetic origin, towers and lines, charging stations with pads, tool
stations, workers. Positions are local ENU metres (see :mod:`proto.geo`).
"""

from __future__ import annotations

from proto.base import Count, Finite, Id, Message, NonNegative, Positive, PositiveCount, Record
from proto.geo import GeoPoint, Point


class Tower(Record, frozen=True, kw_only=True):
    """A transmission tower; ``position`` is its top (where the wires hang)."""

    id: Id
    position: Point


class Line(Record, frozen=True, kw_only=True):
    """A power line strung through ``tower_ids`` in order."""

    id: Id
    tower_ids: list[Id]


class BatterySwap(Record, frozen=True, kw_only=True, tag="swap"):
    """Recharge by swapping the pack: always ``swap_s`` seconds."""

    swap_s: NonNegative


class Charging(Record, frozen=True, kw_only=True, tag="charge"):
    """Recharge on a pad: ``full_charge_s`` seconds from empty to full,
    proportional to the missing energy."""

    full_charge_s: Positive


RechargeModel = BatterySwap | Charging


class ChargingStation(Record, frozen=True, kw_only=True):
    """Landing pads where UAVs recharge; at most ``pads`` at once."""

    id: Id
    position: Point
    pads: Count = 1
    recharge: RechargeModel = Charging(full_charge_s=1800.0)


class Tool(Record, frozen=True, kw_only=True):
    """A tool a gripper UAV can carry; the station holds ``count`` of them."""

    name: Id
    mass_kg: NonNegative = 0.0
    count: PositiveCount = 1


class ToolStation(Record, frozen=True, kw_only=True):
    """A pick-up point holding tools."""

    id: Id
    position: Point
    tools: list[Tool] = []

    def stock(self, tool: str) -> int:
        """How many ``tool`` the station holds at the start of a mission."""
        return sum(t.count for t in self.tools if t.name == tool)


class TimedPoint(Record, frozen=True, kw_only=True):
    """Where a scripted worker is ``at_s`` seconds after the simulation starts."""

    at_s: NonNegative
    position: Point


class Worker(Record, frozen=True, kw_only=True):
    """A human worker; ``position`` is where they start. A simulated worker
    follows ``path`` (straight lines between its points, e.g. climbing a
    tower); a real one is wherever the human tracker says."""

    id: Id
    position: Point
    path: list[TimedPoint] = []


class Safety(Record, frozen=True, kw_only=True):
    """The site's safe-geometry rules, in metres (flat ground at ``ground_z_m``).

    Every target a UAV is flown to (inspection waypoints, monitoring slots,
    pick and drop points) keeps at least ``min_altitude_m`` above the ground;
    a monitoring slot is ``monitor_height_m`` above the worker (at the
    action's horizontal stand-off); no UAV comes closer to a person than
    ``people_clearance_m`` (3-D) nor to another UAV than ``separation_m``.
    Take-off and landing happen on pads only. Targets farther than
    ``area_margin_m`` outside the box around the site's features are refused.
    """

    ground_z_m: Finite = 0.0
    min_altitude_m: NonNegative = 2.0
    monitor_height_m: NonNegative = 3.0
    people_clearance_m: NonNegative = 1.5
    separation_m: NonNegative = 1.0
    area_margin_m: NonNegative = 200.0


class Site(Message, frozen=True, kw_only=True):
    """Everything static about a work site."""

    id: Id = "default"
    origin: GeoPoint
    towers: list[Tower] = []
    lines: list[Line] = []
    stations: list[ChargingStation] = []
    tool_stations: list[ToolStation] = []
    workers: list[Worker] = []
    safety: Safety = Safety()

    def station(self, station_id: str) -> ChargingStation | None:
        """The charging station with this id, if any."""
        return next((s for s in self.stations if s.id == station_id), None)

    def tool_station(self, station_id: str) -> ToolStation | None:
        """The tool station with this id, if any."""
        return next((s for s in self.tool_stations if s.id == station_id), None)

    def worker(self, worker_id: str) -> Worker | None:
        """The worker with this id, if any."""
        return next((w for w in self.workers if w.id == worker_id), None)

    def area(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """The box ``((x0, y0), (x1, y1))`` around the site's features, widened
        by ``safety.area_margin_m``; None for a site with no feature."""
        points = [
            *(t.position for t in self.towers),
            *(s.position for s in self.stations),
            *(t.position for t in self.tool_stations),
            *(w.position for w in self.workers),
        ]
        if not points:
            return None
        m = self.safety.area_margin_m
        xs, ys = [p.x_m for p in points], [p.y_m for p in points]
        return (min(xs) - m, min(ys) - m), (max(xs) + m, max(ys) + m)

    def in_area(self, point: Point) -> bool:
        """Whether ``point`` lies inside :meth:`area` (a site with none has no inside)."""
        box = self.area()
        if box is None:
            return False
        (x0, y0), (x1, y1) = box
        return x0 <= point.x_m <= x1 and y0 <= point.y_m <= y1


__all__ = [
    "BatterySwap",
    "Charging",
    "ChargingStation",
    "Line",
    "RechargeModel",
    "Safety",
    "Site",
    "Tool",
    "ToolStation",
    "Tower",
    "Worker",
]
