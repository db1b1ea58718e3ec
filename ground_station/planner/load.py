"""Decoding and checking planning problems and plans (no file I/O)."""

from __future__ import annotations

from typing import Any

import msgspec

from ground_station.planner.errors import PlanningProblemError
from ground_station.planner.model import (
    KINDS,
    DeliverJob,
    InspectJob,
    Job,
    MonitorJob,
    Problem,
)
from ground_station.planner.result import Solution


def _field_of(err: msgspec.ValidationError) -> tuple[str, str]:
    text = str(err)
    if " - at `" in text:
        message, _, path = text.rpartition(" - at `")
        return path.rstrip("`"), message
    return "$", text


def problem_from_obj(obj: Any) -> Problem:
    """Build and check a ``Problem`` from parsed JSON/YAML data.

    Raises ``PlanningProblemError`` naming the field on any invalid input.
    """
    try:
        problem = msgspec.convert(obj, Problem, strict=False)
    except msgspec.ValidationError as err:
        raise PlanningProblemError(*_field_of(err)) from None
    check_problem(problem)
    return problem


def problem_from_json(text: str | bytes) -> Problem:
    """Decode a JSON problem document; raises ``PlanningProblemError``."""
    try:
        obj = msgspec.json.decode(text)
    except msgspec.DecodeError as err:
        raise PlanningProblemError("$", f"not valid JSON: {err}") from None
    return problem_from_obj(obj)


def plan_from_json(text: str | bytes) -> Solution:
    """Decode a JSON plan document; raises ``PlanningProblemError``."""
    try:
        return msgspec.json.decode(text, type=Solution)
    except msgspec.ValidationError as err:
        raise PlanningProblemError(*_field_of(err)) from None
    except msgspec.DecodeError as err:
        raise PlanningProblemError("$", f"not valid JSON: {err}") from None


def _positive(path: str, value: float, *, zero_ok: bool = False) -> None:
    if value != value or value < 0 or (value == 0 and not zero_ok):
        raise PlanningProblemError(path, f"must be {'>= 0' if zero_ok else '> 0'}, got {value}")


def _unique(path: str, ids: list[str]) -> None:
    seen: set[str] = set()
    for i, ident in enumerate(ids):
        if ident in seen:
            raise PlanningProblemError(f"{path}[{i}].id", f"duplicate id {ident!r}")
        seen.add(ident)


def check_problem(p: Problem) -> None:
    """Semantic checks msgspec cannot express; raises ``PlanningProblemError``."""
    if not 0 <= p.reserve_fraction < 1:
        raise PlanningProblemError("$.reserve_fraction", "must be in [0, 1)")
    _positive("$.min_monitor_segment_s", p.min_monitor_segment_s, zero_ok=True)
    _unique("$.stations", [s.id for s in p.stations])
    _unique("$.tool_stations", [s.id for s in p.tool_stations])
    _unique("$.uav_types", [t.id for t in p.uav_types])
    _unique("$.uavs", [u.id for u in p.uavs])
    _unique("$.actions", [a.id for a in p.actions])
    _check_stations(p)
    _check_uav_types(p)
    _check_uavs(p)
    tool_stations = {s.id for s in p.tool_stations}
    for i, a in enumerate(p.actions):
        _check_action(f"$.actions[{i}]", a, tool_stations)
    _check_running(p)


def _check_stations(p: Problem) -> None:
    """Pads, swap and charge times."""
    for i, s in enumerate(p.stations):
        if s.pads < 0:
            raise PlanningProblemError(f"$.stations[{i}].pads", "must be >= 0")
        _positive(f"$.stations[{i}].swap_s", s.swap_s, zero_ok=True)
        _positive(f"$.stations[{i}].full_charge_s", s.full_charge_s)


def _check_uav_types(p: Problem) -> None:
    """Speeds, battery, powers and capabilities (known kinds, costs 0..1)."""
    for i, t in enumerate(p.uav_types):
        base = f"$.uav_types[{i}]"
        _positive(f"{base}.cruise_speed_mps", t.cruise_speed_mps)
        _positive(f"{base}.battery_wh", t.battery_wh)
        _positive(f"{base}.flight_power_w", t.flight_power_w, zero_ok=True)
        _positive(f"{base}.hover_power_w", t.hover_power_w, zero_ok=True)
        for kind, cost in t.capabilities.items():
            if kind not in KINDS:
                raise PlanningProblemError(f"{base}.capabilities.{kind}", "unknown action kind")
            if not 0 <= cost <= 1:
                raise PlanningProblemError(f"{base}.capabilities.{kind}", "must be in [0, 1]")


def _check_uavs(p: Problem) -> None:
    """Each UAV's type, home, battery and running task's remaining time."""
    stations = {s.id for s in p.stations}
    types = {t.id: t for t in p.uav_types}
    for i, u in enumerate(p.uavs):
        base = f"$.uavs[{i}]"
        if u.type not in types:
            raise PlanningProblemError(f"{base}.type", f"unknown UAV type {u.type!r}")
        if u.home_station not in stations:
            raise PlanningProblemError(
                f"{base}.home_station", f"unknown station {u.home_station!r}"
            )
        _positive(f"{base}.energy_wh", u.energy_wh, zero_ok=True)
        if u.energy_wh > types[u.type].battery_wh * (1 + 1e-9):
            raise PlanningProblemError(f"{base}.energy_wh", "exceeds the battery capacity")
        if u.running is not None:
            _positive(f"{base}.running.remaining_s", u.running.remaining_s, zero_ok=True)


def _check_action(base: str, a: Job, tool_stations: set[str]) -> None:
    """One action's fields (``base`` is its path)."""
    _positive(f"{base}.weight", a.weight)
    _positive(f"{base}.release_s", a.release_s, zero_ok=True)
    if isinstance(a, InspectJob):
        if not a.waypoints:
            raise PlanningProblemError(f"{base}.waypoints", "must not be empty")
        for j, w in enumerate(a.waypoints):
            _positive(f"{base}.waypoints[{j}].service_s", w.service_s, zero_ok=True)
        for j, d in enumerate(a.done):
            if not 0 <= d < len(a.waypoints):
                raise PlanningProblemError(f"{base}.done[{j}]", "waypoint index out of range")
    elif isinstance(a, MonitorJob):
        _positive(f"{base}.duration_s", a.duration_s)
        _positive(f"{base}.standoff_m", a.standoff_m, zero_ok=True)
        if a.k < 1:
            raise PlanningProblemError(f"{base}.k", "must be >= 1")
    elif isinstance(a, DeliverJob):
        _positive(f"{base}.pick_s", a.pick_s, zero_ok=True)
        _positive(f"{base}.drop_s", a.drop_s, zero_ok=True)
        if a.tool_station not in tool_stations:
            raise PlanningProblemError(
                f"{base}.tool_station", f"unknown tool station {a.tool_station!r}"
            )


def _check_running(p: Problem) -> None:
    """A running task names a released action the UAV can be running."""
    actions = {a.id: a for a in p.actions}
    for i, u in enumerate(p.uavs):
        if u.running is None:
            continue
        act = actions.get(u.running.action_id)
        if act is None:
            raise PlanningProblemError(f"$.uavs[{i}].running.action_id", "unknown action")
        if act.release_s > p.now_s:
            raise PlanningProblemError(f"$.uavs[{i}].running.action_id", "action not released yet")
        if isinstance(act, InspectJob) and not 0 <= u.running.index < len(act.waypoints):
            raise PlanningProblemError(f"$.uavs[{i}].running.index", "waypoint out of range")
        if isinstance(act, DeliverJob) and u.tool != act.tool:
            raise PlanningProblemError(f"$.uavs[{i}].tool", "running delivery without its tool")
