"""Tool stations, and the records of what grippers picked, dropped and delivered.

The delivery records are the simulator's ground truth for task outcomes: tests
and benchmarks read them from ``World.deliveries``, never from telemetry.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from proto.site import Tool
from sim_fleet.physics import Vec3, horizontal_distance
from sim_fleet.rules import InteractionRules


@dataclass(frozen=True, slots=True)
class Delivery:
    """A tool released within reach of a worker."""

    tool_id: str
    vehicle_id: str
    worker_id: str
    time_s: float
    position: Vec3


@dataclass(frozen=True, slots=True)
class Drop:
    """A tool released away from any worker: back at a tool station or lost."""

    tool_id: str
    vehicle_id: str
    time_s: float
    position: Vec3
    tool_station_id: str | None  # None: dropped on the ground


class ToolStation:
    """A pick-up point at ``position``, holding one entry per tool (a
    ``count`` of 3 is three entries)."""

    def __init__(self, station_id: str, position: Vec3, tools: Iterable[Tool]) -> None:
        self.id = station_id
        self.position = position
        self.tools: list[Tool] = [tool for tool in tools for _ in range(tool.count)]

    def take(self) -> Tool | None:
        return self.tools.pop(0) if self.tools else None

    def put(self, tool: Tool) -> None:
        self.tools.append(tool)


def within_grab_reach(pos: Vec3, station: ToolStation, rules: InteractionRules) -> bool:
    """Close enough horizontally and at most ``grab_height_m`` above the tools."""
    dz = pos[2] - station.position[2]
    return (
        horizontal_distance(pos, station.position) <= rules.grab_radius_m
        and -0.5 <= dz <= rules.grab_height_m
    )


def station_in_reach(
    pos: Vec3, stations: list[ToolStation], rules: InteractionRules
) -> ToolStation | None:
    """The nearest tool station in grab reach, empty or not."""
    best: ToolStation | None = None
    best_d = float("inf")
    for s in stations:
        if within_grab_reach(pos, s, rules):
            d = horizontal_distance(pos, s.position)
            if d < best_d:
                best, best_d = s, d
    return best


def worker_in_reach(pos: Vec3, workers: dict[str, Vec3], rules: InteractionRules) -> str | None:
    """The nearest worker within delivery reach of ``pos``, if any."""
    best: str | None = None
    best_d = float("inf")
    for wid, wpos in workers.items():
        d = horizontal_distance(pos, wpos)
        near = d <= rules.delivery_radius_m and abs(pos[2] - wpos[2]) <= rules.delivery_height_m
        if near and d < best_d:
            best, best_d = wid, d
    return best
