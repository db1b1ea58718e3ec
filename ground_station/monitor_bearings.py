"""Where the slots of a worker's monitoring actions sit on the stand-off
ring: each action's slot 0 gets the bearing farthest from the slots of the
worker's other monitoring actions in force, so two actions never send their
UAVs to one point (two k = 1 monitors of one worker: opposite sides). A
slot whose UAV was lost in the air (a hung agent's autopilot hovers on at
it) is moved to the bearing farthest from that point and from every other
slot of the worker, so its replacement is not sent into the lost UAV."""

from __future__ import annotations

import msgspec

from proto.mission import ActionRecord, MonitorAction

STEP_DEG = 5.0
"""Bearings tried, this far apart."""


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


def choose_bearing(action: MonitorAction, taken: list[float]) -> float:
    """The bearing of slot 0 of ``action`` that keeps its slots farthest
    (the smallest angle to any of ``taken``, maximised; ties: the smallest
    bearing) from the bearings ``taken`` by other slots."""
    if not taken:
        return 0.0
    spacing = 360.0 / action.uavs
    best, best_gap = 0.0, -1.0
    for i in range(round(spacing / STEP_DEG)):
        start = i * STEP_DEG
        gap = _gap(slot_bearings(msgspec.structs.replace(action, bearing_deg=start)), taken)
        if gap > best_gap + 1e-9:
            best, best_gap = start, gap
    return best


def _worker_slots(worker_id: str, in_force: list[ActionRecord], but: str | None) -> list[float]:
    return [
        b
        for r in in_force
        if isinstance(r.action, MonitorAction)
        and r.action.worker_id == worker_id
        and r.action_id != but
        for b in record_bearings(r)
    ]


def with_bearing(action: MonitorAction, in_force: list[ActionRecord]) -> MonitorAction:
    """``action`` with its bearing chosen, if the operator left it out."""
    if action.bearing_deg is not None:
        return action
    taken = _worker_slots(action.worker_id, in_force, None)
    return msgspec.structs.replace(action, bearing_deg=choose_bearing(action, taken))


def moved_off(record: ActionRecord, slot: int, in_force: list[ActionRecord]) -> ActionRecord:
    """``record`` with ``slot`` moved to the bearing farthest from where it
    is now and from every other slot of the worker (this action's and the
    other actions' in force)."""
    action = record.action
    assert isinstance(action, MonitorAction)
    bearings = record_bearings(record)
    taken = bearings + _worker_slots(action.worker_id, in_force, record.action_id)
    best, best_gap = bearings[slot], -1.0
    for i in range(round(360.0 / STEP_DEG)):
        bearing = i * STEP_DEG
        gap = _gap([bearing], taken)
        if gap > best_gap + 1e-9:
            best, best_gap = bearing, gap
    moved = {**record.slot_bearings_deg, slot: best}
    return msgspec.structs.replace(record, slot_bearings_deg=moved)


def as_requested(stored: MonitorAction, requested: MonitorAction) -> MonitorAction:
    """``stored`` as the operator sent it (the chosen bearing left out if
    they left it out), to compare a repeated request with."""
    if requested.bearing_deg is None:
        return msgspec.structs.replace(stored, bearing_deg=None)
    return stored
