"""Where the slots of a worker's monitoring actions sit on the stand-off
ring: each action's slot 0 gets the bearing farthest from the slots of the
worker's other monitoring actions in force, so two actions never send their
UAVs to one point (two k = 1 monitors of one worker: opposite sides)."""

from __future__ import annotations

import msgspec

from proto.mission import ActionRecord, MonitorAction

STEP_DEG = 5.0
"""Bearings tried, this far apart."""


def slot_bearings(action: MonitorAction) -> list[float]:
    """The bearings (degrees) of ``action``'s slots."""
    start = action.bearing_deg or 0.0
    return [(start + 360.0 * s / action.uavs) % 360.0 for s in range(action.uavs)]


def _apart(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def choose_bearing(action: MonitorAction, others: list[MonitorAction]) -> float:
    """The bearing of slot 0 of ``action`` that keeps its slots farthest
    (the smallest angle to any slot of ``others``, maximised; ties: the
    smallest bearing) from the slots of ``others``."""
    taken = [b for other in others for b in slot_bearings(other)]
    if not taken:
        return 0.0
    spacing = 360.0 / action.uavs
    best, best_gap = 0.0, -1.0
    for i in range(round(spacing / STEP_DEG)):
        start = i * STEP_DEG
        mine = slot_bearings(msgspec.structs.replace(action, bearing_deg=start))
        gap = min(_apart(m, t) for m in mine for t in taken)
        if gap > best_gap + 1e-9:
            best, best_gap = start, gap
    return best


def with_bearing(action: MonitorAction, in_force: list[ActionRecord]) -> MonitorAction:
    """``action`` with its bearing chosen, if the operator left it out."""
    if action.bearing_deg is not None:
        return action
    others = [
        r.action
        for r in in_force
        if isinstance(r.action, MonitorAction) and r.action.worker_id == action.worker_id
    ]
    return msgspec.structs.replace(action, bearing_deg=choose_bearing(action, others))


def as_requested(stored: MonitorAction, requested: MonitorAction) -> MonitorAction:
    """``stored`` as the operator sent it (the chosen bearing left out if
    they left it out), to compare a repeated request with."""
    if requested.bearing_deg is None:
        return msgspec.structs.replace(stored, bearing_deg=None)
    return stored
