"""Energy and time model: constant power in flight and in hover.

Energy of a leg = power x time; flight time = distance / cruise speed.
Recharge: battery swap (fixed time, to full) or charging (time proportional
to the missing energy; a partial charge adds capacity x time / full time).
"""

from __future__ import annotations

from math import dist
from operator import add

import msgspec

from ground_station.planner.holds import HoldPoints
from ground_station.planner.model import Airframe, Problem, Station, Uav, Vec3

EPS_S = 1e-6
EPS_WH = 1e-6


class Kin:
    """Per-UAV constants precomputed for the hot path (Wh and s)."""

    __slots__ = (
        "capacity_wh",
        "caps",
        "home",
        "home_pos",
        "hover_whps",
        "reserve_wh",
        "speed_mps",
        "uav_id",
        "wh_per_m",
    )

    def __init__(self, uav: Uav, utype: Airframe, reserve_fraction: float, home: Station) -> None:
        self.uav_id = uav.id
        self.speed_mps = utype.cruise_speed_mps
        self.wh_per_m = utype.flight_power_w / utype.cruise_speed_mps / 3600.0
        self.hover_whps = utype.hover_power_w / 3600.0
        self.capacity_wh = utype.battery_wh
        self.reserve_wh = reserve_fraction * utype.battery_wh
        self.caps = dict(utype.capabilities)
        self.home = home.id
        self.home_pos = home.position_m


def recharge_time_s(station: Station, capacity_wh: float, energy_wh: float) -> float:
    """Seconds to bring ``energy_wh`` to full at ``station``."""
    if station.recharge == "swap":
        return station.swap_s
    missing = max(0.0, capacity_wh - energy_wh)
    return station.full_charge_s * missing / capacity_wh


def energy_after_recharge(
    station: Station, capacity_wh: float, energy_wh: float, duration_s: float
) -> float:
    """Battery after ``duration_s`` on a pad (swap needs its full time)."""
    if station.recharge == "swap":
        return capacity_wh if duration_s >= station.swap_s - EPS_S else energy_wh
    return min(capacity_wh, energy_wh + capacity_wh * duration_s / station.full_charge_s)


class Nearest(msgspec.Struct, frozen=True, gc=False):
    """The charging station nearest a point: its distance and index."""

    distance_m: float
    station: int


class SiteMap:
    """Charging stations (``index`` by id) with memoised distance and
    nearest-station lookups, the end-of-mission policy, and the index of
    each hold point's one-at-a-time reservation timeline in the shared
    :class:`~ground_station.planner.pads.Pads` (after the stations')."""

    __slots__ = (
        "_cand",
        "_dists",
        "_near",
        "_within",
        "by_id",
        "charging",
        "end",
        "index",
        "points",
        "positions",
    )

    def __init__(self, problem: Problem) -> None:
        self.by_id = {s.id: s for s in problem.stations}
        self.charging = [s for s in problem.stations if s.pads > 0]
        self.index = {s.id: i for i, s in enumerate(self.charging)}
        self.positions = [s.position_m for s in self.charging]
        self.end = problem.end
        self.points = HoldPoints(problem, first=len(self.charging))
        self._near: dict[Vec3, Nearest] = {}
        self._dists: dict[Vec3, list[float]] = {}
        self._cand: dict[tuple[Vec3, Vec3], tuple[list[int], list[int], float]] = {}
        self._within: dict[tuple[int, float], list[tuple[int, float]]] = {}

    def dists(self, pos: Vec3) -> list[float]:
        """Distance (m) from ``pos`` to each charging station, by index."""
        hit = self._dists.get(pos)
        if hit is None:
            hit = [dist(pos, sp) for sp in self.positions]
            if len(self._dists) < 200_000:
                self._dists[pos] = hit
        return hit

    def within(self, si: int, reach_m: float) -> list[tuple[int, float]]:
        """(index, distance m) of the other charging stations at most
        ``reach_m`` from station ``si``."""
        key = (si, reach_m)
        hit = self._within.get(key)
        if hit is None:
            row = self.dists(self.positions[si])
            self._within[key] = hit = [
                (j, d) for j, d in enumerate(row) if j != si and d <= reach_m
            ]
        return hit

    def nearest(self, pos: Vec3) -> Nearest:
        """The nearest charging station (index in ``charging``; -1 if none)."""
        hit = self._near.get(pos)
        if hit is None:
            best_d, best_i = float("inf"), -1
            for i, d in enumerate(self.dists(pos)):
                if d < best_d:
                    best_d, best_i = d, i
            self._near[pos] = hit = Nearest(best_d, best_i)
        return hit

    def candidates(self, a: Vec3, b: Vec3, limit: int = 3) -> tuple[list[int], list[int], float]:
        """Charging stations worth trying between ``a`` and ``b`` (detour
        order), the other stations, and the shortest detour a -> station -> b
        (m; inf without stations)."""
        key = (a, b)
        hit = self._cand.get(key)
        if hit is None:
            hit = self._detours(a, b, limit)
            if len(self._cand) < 200_000:
                self._cand[key] = hit
        return hit

    def _detours(self, a: Vec3, b: Vec3, limit: int) -> tuple[list[int], list[int], float]:
        n = len(self.positions)
        detour = list(map(add, self.dists(a), self.dists(b)))
        order = sorted(range(n), key=detour.__getitem__)  # stable: ties by index
        shortest = detour[order[0]] if n else float("inf")
        if n <= limit:
            return list(range(n)), [], shortest
        first = order[:limit]
        near_a = self.nearest(a).station
        if near_a not in first:
            first.append(near_a)
        taken = set(first)
        return first, [i for i in range(n) if i not in taken], shortest
