"""What the agent knows about the site: stations, tool stations and where
the workers are (their last tracked pose, else where the site puts them)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from proto.geo import Point
from proto.site import ChargingStation, Site, ToolStation
from proto.telemetry import POSE_FUTURE_S, HumanPose


def horizontal_distance(a: Point, b: Point) -> float:
    """Distance in the horizontal plane, metres."""
    return math.hypot(a.x_m - b.x_m, a.y_m - b.y_m)


class Surroundings:
    """The site plus the latest human poses."""

    def __init__(self, site: Site, clock: Callable[[], float] = time.time) -> None:
        self.site = site
        self.clock = clock  # the mission clock, as poses are stamped
        self._poses: dict[str, HumanPose] = {}
        self.refused = 0  # poses stamped beyond POSE_FUTURE_S ahead

    def update_pose(self, pose: HumanPose) -> None:
        """Keep the newest pose of each worker (older stamps are ignored, and
        stamps from the future beyond :data:`POSE_FUTURE_S` are refused)."""
        if pose.stamp_s > self.clock() + POSE_FUTURE_S:
            self.refused += 1
            return
        known = self._poses.get(pose.worker_id)
        if known is None or pose.stamp_s >= known.stamp_s:
            self._poses[pose.worker_id] = pose

    def worker_position(self, worker_id: str) -> Point | None:
        """Tracked position of a worker, else the site's; None if unknown."""
        pose = self._poses.get(worker_id)
        if pose is not None:
            return pose.position
        worker = self.site.worker(worker_id)
        return worker.position if worker is not None else None

    def people(self) -> list[Point]:
        """Where every worker of the site is (tracked, else as the site says)."""
        known = [self.worker_position(w.id) for w in self.site.workers]
        return [p for p in known if p is not None]

    def station(self, station_id: str) -> ChargingStation | None:
        return self.site.station(station_id)

    def nearest_station(
        self, where: Point, among: list[ChargingStation] | None = None
    ) -> ChargingStation | None:
        """The charging station (of ``among``, else of the site) closest
        (horizontally) to ``where``."""
        stations = self.site.stations if among is None else among
        if not stations:
            return None
        return min(stations, key=lambda s: horizontal_distance(s.position, where))

    def tool_station(self, station_id: str) -> ToolStation | None:
        return self.site.tool_station(station_id)

    def tool_station_for(self, tool: str) -> ToolStation | None:
        """A tool station stocking ``tool`` (the first one), if any."""
        return next(
            (ts for ts in self.site.tool_stations if any(t.name == tool for t in ts.tools)), None
        )

    def nearest_tool_station(self, where: Point) -> ToolStation | None:
        stations = self.site.tool_stations
        if not stations:
            return None
        return min(stations, key=lambda s: where.distance_to(s.position))
