"""Energy and time model: constant power in flight and in hover.

Energy of a leg = power x time; flight time = distance / cruise speed.
Recharge: battery swap (fixed time, to full) or charging (time proportional
to the missing energy; a partial charge adds capacity x time / full time).
"""

from __future__ import annotations

from math import dist

from ground_station.planner.model import Problem, Station, Uav, UavType, Vec3

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

    def __init__(self, uav: Uav, utype: UavType, reserve_fraction: float, home: Station) -> None:
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


class Site:
    """Charging stations with a memoised nearest-station lookup."""

    __slots__ = ("_cand", "_near", "by_id", "charging", "positions", "swap_s", "wh_s")

    def __init__(self, problem: Problem) -> None:
        self.by_id = {s.id: s for s in problem.stations}
        self.charging = [s for s in problem.stations if s.pads > 0]
        self.positions = [s.position_m for s in self.charging]
        self._near: dict[Vec3, tuple[float, int]] = {}
        self._cand: dict[tuple[Vec3, Vec3], list[int]] = {}
        swaps = [s.swap_s for s in self.charging if s.recharge == "swap"]
        self.swap_s = min(swaps, default=float("inf"))
        charges = [s.full_charge_s for s in self.charging if s.recharge == "charge"]
        self.wh_s = min(charges, default=float("inf"))

    def min_charge_s(self, capacity_wh: float, missing_wh: float) -> float:
        """A lower bound of the time to recover ``missing_wh`` at any station."""
        if not self.charging:
            return 0.0
        return min(self.swap_s, self.wh_s * missing_wh / capacity_wh)

    def nearest(self, pos: Vec3) -> tuple[float, int]:
        """(distance m, index in ``charging``) of the nearest charging station."""
        hit = self._near.get(pos)
        if hit is None:
            best = (float("inf"), -1)
            for i, sp in enumerate(self.positions):
                d = dist(pos, sp)
                if d < best[0]:
                    best = (d, i)
            self._near[pos] = hit = best
        return hit

    def candidates(self, a: Vec3, b: Vec3, limit: int = 3) -> list[int]:
        """Charging stations worth trying between ``a`` and ``b`` (detour order)."""
        key = (a, b)
        hit = self._cand.get(key)
        if hit is not None:
            return hit
        n = len(self.positions)
        if n <= limit:
            return list(range(n))
        scored = sorted((dist(a, sp) + dist(sp, b), i) for i, sp in enumerate(self.positions))
        near_a = self.nearest(a)[1]
        out = [i for _, i in scored[:limit]]
        if near_a not in out:
            out.append(near_a)
        if len(self._cand) < 200_000:
            self._cand[key] = out
        return out
