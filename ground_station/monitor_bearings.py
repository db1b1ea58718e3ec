"""Where the slots of a worker's monitoring actions sit on the stand-off
ring: each action's slot 0 gets the bearing farthest from the slots of the
worker's other monitoring actions in force, so two actions never send their
UAVs to one point (two k = 1 monitors of one worker: opposite sides). A
slot whose UAV was lost in the air (a hung agent's autopilot hovers on at
it) is moved to the bearing farthest from that point and from every other
slot of the worker, so its replacement is not sent into the lost UAV.
Either way a slot is kept nearer its own worker than any other worker by
``CLEAR_M`` where the ring allows: a UAV hovering nearer another worker
watches that one, which the operator (and the simulator's ground truth)
would count against the wrong person."""

from __future__ import annotations

import math
from collections.abc import Callable

import msgspec

from proto.geo import Point
from proto.mission import ActionRecord, MonitorAction
from proto.site import Site

STEP_DEG = 5.0
"""Bearings tried, this far apart."""
CLEAR_M = 1.0
"""A slot this much farther from every other worker than from its own is
clear of them; beyond it, the angle to other slots decides."""


def slot_bearings(action: MonitorAction, moved: dict[int, float] | None = None) -> list[float]:
    """The bearings (degrees) of ``action``'s slots (``moved``: slots moved off their place)."""
    start = action.bearing_deg or 0.0
    places = [(start + 360.0 * s / action.uavs) % 360.0 for s in range(action.uavs)]
    return [(moved or {}).get(s, b) for s, b in enumerate(places)]


def record_bearings(record: ActionRecord) -> list[float]:
    """The bearings of a stored monitoring action's slots, as flown."""
    assert isinstance(record.action, MonitorAction)
    return slot_bearings(record.action, record.slot_bearings_deg)


def task_bearing(record: ActionRecord, slot: int) -> float:
    """``MonitorTask.bearing_deg`` for ``slot`` (the agent adds the slot's place on the ring)."""
    assert isinstance(record.action, MonitorAction)
    return (record_bearings(record)[slot] - 360.0 * slot / record.action.uavs) % 360.0


def _apart(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def _gap(mine: list[float], taken: list[float]) -> float:
    return min(_apart(m, t) for m in mine for t in taken)


def _clearance(action: MonitorAction, workers: dict[str, Point], bearings: list[float]) -> float:
    """How much farther the nearest other worker is from any slot of
    ``action`` at ``bearings`` than its own worker, capped at ``CLEAR_M``
    (an unknown worker: clear)."""
    own = workers.get(action.worker_id)
    out = CLEAR_M
    if own is None:
        return out
    for b in bearings:
        x = own.x_m + action.standoff_m * math.cos(math.radians(b))
        y = own.y_m + action.standoff_m * math.sin(math.radians(b))
        for wid, w in workers.items():
            if wid != action.worker_id:
                out = min(out, math.hypot(w.x_m - x, w.y_m - y) - action.standoff_m)
    return out


def _best(
    starts: list[float],
    slots: Callable[[float], list[float]],
    taken: list[float],
    clearance: Callable[[list[float]], float],
) -> float:
    """The start whose slots are clearest of other workers, then farthest
    from ``taken`` (the smallest angle to any of them, maximised); ties: the
    first."""

    def key(start: float) -> tuple[float, float]:
        mine = slots(start)
        gap = _gap(mine, taken) if taken else 0.0
        return round(clearance(mine), 6), round(gap, 6)

    return max(starts, key=key)


def choose_bearing(
    action: MonitorAction, taken: list[float], workers: dict[str, Point] | None = None
) -> float:
    """The bearing of slot 0 of ``action`` whose slots are clear of the other
    ``workers`` and farthest from the bearings ``taken`` by other slots;
    ties: the smallest bearing."""
    spacing = 360.0 / action.uavs
    starts = [i * STEP_DEG for i in range(round(spacing / STEP_DEG))]

    def slots(start: float) -> list[float]:
        return slot_bearings(msgspec.structs.replace(action, bearing_deg=start))

    return _best(starts, slots, taken, lambda b: _clearance(action, workers or {}, b))


def _worker_slots(worker_id: str, in_force: list[ActionRecord], but: str | None) -> list[float]:
    return [
        b
        for r in in_force
        if isinstance(r.action, MonitorAction)
        and r.action.worker_id == worker_id
        and r.action_id != but
        for b in record_bearings(r)
    ]


def _workers(site: Site) -> dict[str, Point]:
    return {w.id: w.position for w in site.workers}


def with_bearing(action: MonitorAction, in_force: list[ActionRecord], site: Site) -> MonitorAction:
    """``action`` with its bearing chosen, if the operator left it out."""
    if action.bearing_deg is not None:
        return action
    taken = _worker_slots(action.worker_id, in_force, None)
    bearing = choose_bearing(action, taken, _workers(site))
    return msgspec.structs.replace(action, bearing_deg=bearing)


def moved_off(
    record: ActionRecord, slot: int, in_force: list[ActionRecord], site: Site
) -> ActionRecord:
    """``record`` with ``slot`` moved to the bearing clear of other workers
    and farthest from where it is now and from every other slot of the
    worker (this action's and the other actions' in force)."""
    action = record.action
    assert isinstance(action, MonitorAction)
    bearings = record_bearings(record)
    taken = bearings + _worker_slots(action.worker_id, in_force, record.action_id)
    starts = [i * STEP_DEG for i in range(round(360.0 / STEP_DEG))]
    workers = _workers(site)
    best = _best(starts, lambda b: [b], taken, lambda b: _clearance(action, workers, b))
    moved = {**record.slot_bearings_deg, slot: best}
    return msgspec.structs.replace(record, slot_bearings_deg=moved)


def as_requested(stored: MonitorAction, requested: MonitorAction) -> MonitorAction:
    """``stored`` as the operator sent it (the chosen bearing left out if
    they left it out), to compare a repeated request with."""
    if requested.bearing_deg is None:
        return msgspec.structs.replace(stored, bearing_deg=None)
    return stored
