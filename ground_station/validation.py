"""Checks an operator action against the site and the fleet before it is
accepted. Every failure is an :class:`InvalidAction` naming the field.

Physically absurd requests are refused here, not discovered in flight:
targets below the site's minimum flight altitude or outside its area, a
monitoring slot closer to the worker than the people clearance, and a
monitoring duration longer than the capable fleet could cover even with
hand-overs and recharges."""

from __future__ import annotations

import math
from typing import Any

import msgspec

from proto.errors import InvalidAction
from proto.fleet import Capability, Fleet
from proto.mission import Action, DeliverAction, InspectAction, MonitorAction
from proto.site import BatterySwap, Site

MAX_RANGE_M = 100_000.0  # farther than any site: a typo, not a mission
MAX_ALTITUDE_M = 1_000.0
MAX_DURATION_S = 7 * 24 * 3600.0


def validate(action: Action, site: Site, fleet: Fleet, field: str = "action") -> None:
    """Raise :class:`InvalidAction` if ``action`` cannot be accepted."""
    _check_numbers(msgspec.to_builtins(action), field)
    match action:
        case InspectAction(waypoints=waypoints):
            if not waypoints:
                raise InvalidAction(
                    "an inspection needs at least one waypoint", field=f"{field}.waypoints"
                )
            for i, waypoint in enumerate(waypoints):
                _check_position(waypoint.position, f"{field}.waypoints[{i}].position", site)
            _need(fleet, Capability.INSPECT, 1, field)
        case MonitorAction(worker_id=worker_id, uavs=k):
            _worker(site, worker_id, field)
            _need(fleet, Capability.MONITOR, k, f"{field}.uavs")
            if action.duration_s > MAX_DURATION_S:
                raise InvalidAction("duration over a week", field=f"{field}.duration_s")
            clearance = site.safety.people_clearance_m
            if math.hypot(action.standoff_m, site.safety.monitor_height_m) < clearance:
                raise InvalidAction(
                    f"the slot would be closer than {clearance:g} m to the worker",
                    field=f"{field}.standoff_m",
                )
            longest = coverable_s(site, fleet, k)
            if action.duration_s > longest:
                raise InvalidAction(
                    f"{k} UAV(s) cannot cover {action.duration_s:.0f} s even with hand-overs "
                    f"(at most about {longest:.0f} s with this fleet)",
                    field=f"{field}.duration_s",
                )
        case DeliverAction():
            station = site.tool_station(action.tool_station_id)
            if station is None:
                raise InvalidAction(
                    f"unknown tool station {action.tool_station_id!r}",
                    field=f"{field}.tool_station_id",
                )
            if action.tool not in {tool.name for tool in station.tools}:
                raise InvalidAction(
                    f"tool {action.tool!r} is not at {station.id}", field=f"{field}.tool"
                )
            _worker(site, action.worker_id, field)
            _need(fleet, Capability.DELIVER, 1, field)


def _worker(site: Site, worker_id: str, field: str) -> None:
    if site.worker(worker_id) is None:
        known = ", ".join(w.id for w in site.workers) or "none"
        raise InvalidAction(
            f"unknown worker {worker_id!r} (known: {known})", field=f"{field}.worker_id"
        )


def _need(fleet: Fleet, capability: Capability, count: int, field: str) -> None:
    types = {t.name: t for t in fleet.types}
    capable = [
        u
        for u in fleet.uavs
        if capability in types[u.type].capabilities
        and (capability != Capability.DELIVER or types[u.type].gripper)
    ]
    if len(capable) < count:
        raise InvalidAction(
            f"needs {count} UAV(s) able to {capability}; the fleet has {len(capable)}",
            field=field,
        )


def _check_position(position: Any, field: str, site: Site) -> None:
    safety = site.safety
    floor = safety.ground_z_m + safety.min_altitude_m
    if position.z_m < floor:
        raise InvalidAction(
            f"z {position.z_m:g} m is below the minimum flight altitude {floor:g} m "
            f"({safety.min_altitude_m:g} m above the ground at {safety.ground_z_m:g} m)",
            field=f"{field}.z_m",
        )
    if position.z_m > MAX_ALTITUDE_M:
        raise InvalidAction(f"z above {MAX_ALTITUDE_M:.0f} m", field=f"{field}.z_m")
    box = site.area()
    if box is not None:
        if not site.in_area(position):
            (x0, y0), (x1, y1) = box
            raise InvalidAction(
                f"outside the site's area (x {x0:g}..{x1:g}, y {y0:g}..{y1:g} m)", field=field
            )
    elif max(abs(position.x_m), abs(position.y_m)) > MAX_RANGE_M:
        raise InvalidAction(f"more than {MAX_RANGE_M:.0f} m from the site", field=field)


def coverable_s(site: Site, fleet: Fleet, k: int) -> float:
    """An upper bound on how long ``k`` slots can be watched without a gap.

    Each monitor-capable UAV hovers ``E`` seconds per charge (usable energy
    over hover power) and then needs ``R`` seconds on the fastest pad, so in
    the long run it covers at most ``E / (E + R)`` of the time. If those
    shares add up to ``k`` or more the bound is infinite; otherwise over a
    duration ``D`` the fleet has ``sum(E) + D * sum(share)`` seconds of
    hovering for the ``k * D`` needed: ``D <= sum(E) / (k - sum(share))``.
    Transit is ignored, so the bound never refuses a feasible request.
    """
    recharge_s = (
        min(
            s.recharge.swap_s if isinstance(s.recharge, BatterySwap) else s.recharge.full_charge_s
            for s in site.stations
        )
        if site.stations
        else math.inf
    )
    types = {t.name: t for t in fleet.types}
    endurance, share = 0.0, 0.0
    for uav in fleet.uavs:
        t = types[uav.type]
        if Capability.MONITOR not in t.capabilities:
            continue
        if t.hover_power_w <= 0:
            return math.inf
        e_s = t.battery_wh * (1.0 - fleet.reserve_fraction) * 3600.0 / t.hover_power_w
        endurance += e_s
        share += e_s / (e_s + recharge_s) if math.isfinite(recharge_s) else 0.0
    if share >= k:
        return math.inf
    return endurance / (k - share)


def _check_numbers(value: Any, field: str) -> None:
    """Reject NaN and infinities anywhere in the action."""
    if isinstance(value, float) and not math.isfinite(value):
        raise InvalidAction("not a finite number", field=field)
    if isinstance(value, dict):
        for key, item in value.items():
            _check_numbers(item, f"{field}.{key}")
    elif isinstance(value, list):
        for i, item in enumerate(value):
            _check_numbers(item, f"{field}[{i}]")
