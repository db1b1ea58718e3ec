"""What changed between the live planning session's problem and the fleet
now, as planner events (see :mod:`ground_station.live_plan`): actions
added, changed or cancelled, UAVs lost, batteries below plan, and the
visits a UAV finished; a change that is none of these is a ``Rebuild``."""

from __future__ import annotations

import math

from ground_station import planner as pl
from proto.plan import DeliverTask, InspectTask, Task, WaitTask

MOVED_M = 1.0
"""A UAV farther than this from where the session has it has moved: rebuild."""
ENERGY_TOLERANCE = 0.005
"""Battery differences below this fraction of capacity are no change."""


class Rebuild(Exception):
    """The difference is not one the session can apply."""


Visited = tuple[str, str, int | None]
"""A planner visit done: (kind, action id, waypoint index or None)."""


def visits_of(task: Task) -> list[Visited] | None:
    """The planner visits a completed wire task did: those of an inspection
    or a delivery, none for a wait (the session has it wait, as it did);
    None for other tasks (the session cannot take them as finished)."""
    if isinstance(task, InspectTask) and task.action_id is not None:
        return [("inspect", task.action_id, w.index) for w in task.waypoints]
    if isinstance(task, DeliverTask) and task.action_id is not None:
        return [("deliver", task.action_id, None)]
    return [] if isinstance(task, WaitTask) else None


def planned_floor(plan: pl.Solution, at_s: float) -> dict[str, float]:
    """For each UAV with a plan, the lowest battery (Wh) the plan has it at
    by the end of its step in progress at ``at_s`` (planner time; its first
    step if none has begun by then: it may have begun it early): a UAV that
    has flown its plan so far is at or above it."""
    out = {}
    for uav in plan.uavs:
        begun = [s.energy_after_wh for s in uav.steps if s.start_s <= at_s]
        if uav.steps:
            out[uav.uav_id] = min(begun or [uav.steps[0].energy_after_wh])
    return out


def diff(
    old: pl.Problem,
    new: pl.Problem,
    capacities: dict[str, float],
    floors: dict[str, float] | None = None,
) -> list[pl.Event]:
    """The planner events that turn ``old`` into ``new`` (same time base);
    raises ``Rebuild`` when a difference is not such an event (a UAV moved
    off its course, landed, picked a tool, charged or came back). ``floors``
    (:func:`planned_floor`) names the UAVs on their course: one of them may
    have moved and taken off, and used energy down to its floor, as planned;
    the session then has the energy it has now at its start (never more
    than it has: a route added before its current step is planned on the
    safe side)."""
    floors = floors or {}
    events: list[pl.Event] = []
    before = {u.id: u for u in old.uavs}
    if set(before) != {u.id for u in new.uavs} or old.stations != new.stations:
        raise Rebuild("the fleet or the stations changed")
    fleet: list[pl.Event] = []
    for u in new.uavs:
        o = before[u.id]
        if u.available and not o.available:
            raise Rebuild(f"{u.id} back")  # it takes its share of the work, as in a full plan
        if u.available != o.available:
            fleet.append(pl.UavLost(uav_id=u.id))
            continue
        if not u.available:
            continue
        tolerance = ENERGY_TOLERANCE * capacities.get(u.id, 1.0)
        if u.tool != o.tool or u.running != o.running:
            raise Rebuild(f"{u.id} took or left a tool or a monitor slot")
        floor = floors.get(u.id, math.inf)
        if floor - tolerance <= u.energy_wh <= o.energy_wh + tolerance:
            if o.airborne and not u.airborne:
                raise Rebuild(f"{u.id} landed")  # it charges or ended its flight
            if o.energy_wh - u.energy_wh > tolerance:  # as if it had it at its start: safe side
                fleet.append(pl.BatteryLow(uav_id=u.id, energy_wh=u.energy_wh))
            continue  # on its course: the session's start for it still holds
        if math.dist(u.position_m, o.position_m) > MOVED_M or u.airborne != o.airborne:
            raise Rebuild(f"{u.id} moved off its plan")
        if o.energy_wh - u.energy_wh > tolerance:
            fleet.append(pl.BatteryLow(uav_id=u.id, energy_wh=u.energy_wh))
        elif u.energy_wh - o.energy_wh > tolerance:
            raise Rebuild(f"{u.id} charged")  # the session's recharges are wrong now
    old_actions = {a.id: a for a in old.actions}
    new_ids = {a.id for a in new.actions}
    events += [pl.ActionCancelled(action_id=a) for a in old_actions if a not in new_ids]
    events += [
        pl.ActionChanged(action=a)
        for a in new.actions
        if a.id in old_actions and a != old_actions[a.id]
    ]
    events += fleet
    events += [pl.ActionAdded(action=a) for a in new.actions if a.id not in old_actions]
    return events
