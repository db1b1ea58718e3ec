"""Checks an operator action against the site and the fleet before it is
accepted. Every failure is an :class:`InvalidAction` naming the field."""

from __future__ import annotations

import math
from typing import Any

import msgspec

from proto.errors import RequestError
from proto.fleet import Capability, Fleet
from proto.mission import Action, DeliverAction, InspectAction, MonitorAction
from proto.site import Site

MAX_RANGE_M = 100_000.0  # farther than any site: a typo, not a mission
MAX_ALTITUDE_M = 1_000.0
MAX_DURATION_S = 7 * 24 * 3600.0


class InvalidAction(RequestError):
    """An action that the site or fleet cannot accept (unknown worker, tool or
    station, no capable UAV, out-of-range value). ``field`` names it; fix the
    request, do not retry it as is."""

    code = "invalid_action"


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
                _check_position(waypoint.position, f"{field}.waypoints[{i}].position")
            _need(fleet, Capability.INSPECT, 1, field)
        case MonitorAction(worker_id=worker_id, uavs=k):
            _worker(site, worker_id, field)
            _need(fleet, Capability.MONITOR, k, f"{field}.uavs")
            if action.duration_s > MAX_DURATION_S:
                raise InvalidAction("duration over a week", field=f"{field}.duration_s")
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


def _check_position(position: Any, field: str) -> None:
    if max(abs(position.x_m), abs(position.y_m)) > MAX_RANGE_M:
        raise InvalidAction(f"more than {MAX_RANGE_M:.0f} m from the site", field=field)
    if not -100.0 <= position.z_m <= MAX_ALTITUDE_M:
        raise InvalidAction(f"altitude outside -100..{MAX_ALTITUDE_M:.0f} m", field=field)


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
