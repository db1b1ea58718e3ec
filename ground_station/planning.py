"""The boundary between the mission manager and the pure planner library:
wire-side state in, a planner ``Problem`` out; a planner ``Plan`` in,
per-UAV wire ``Task`` lists out (the steps become tasks in
:mod:`ground_station.wire_tasks`; reliefs, take-off leads and the
comparison of task lists are here).

Planner time is relative: the problem's ``now_s`` is 0 and a step's times
are seconds from now; wire tasks carry absolute mission seconds.
Task ids are derived from what a task is (``{action}.wp{i}-{j}``,
``{action}.slot{s}.{uav}.{n}``, ``{uav}.recharge{n}`` ...) so that a replan that
leaves a UAV's work alone yields the same ids, and an agent keeps flying.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Iterable
from typing import TypedDict

import msgspec

from ground_station import planner as pl
from proto.fleet import Fleet, UavSpec
from proto.geo import Point
from proto.mission import ActionRecord, DeliverAction, InspectAction, MonitorAction
from proto.plan import MonitorTask, Plan, Task, WaitTask
from proto.site import BatterySwap, ChargingStation, Safety, Site


@dataclasses.dataclass(frozen=True)
class UavNow:
    """What the ground station knows of one UAV at planning time."""

    uav_id: str
    position: Point
    energy_wh: float
    available: bool
    airborne: bool = False
    tool: str | None = None
    running: pl.RunningTask | None = None
    """The monitoring segment it flies (its action and slot), or the delivery
    whose tool it holds."""


PLANNING_MARGIN = 0.05
"""Fraction of capacity the plans keep above the fleet's reserve. Agents
judge "battery enough" with a safety factor (``energy_margin``, 1.15) over
the next 30 s of monitoring and the way to a station, on a state of charge
MAVLink reports in whole percent; a plan that ran to the bare reserve
would make them leave a slot half a minute before the relief the plan
sent. On the paper's fleet the factor alone takes 1-1.5 % of capacity and
the rounding up to 1 %; at 3 % a 1,500 s monitor was left 30 s early (a
29.5 s gap in the e2e test, measured: 0.28 of charge at 30 s before the
planned end, where the guard needed 0.274), so 5 %."""
TAKEOFF_LEAD_S = 12.0
"""Seconds a UAV leaves early for a monitoring segment (arming, take-off,
climb), and the planner's ``takeoff_s``. Measured on the simulated fleet at
x10: leaving the pad for W2's ring took 6-7 s more than the straight flight
the planner counts, and arming 1-3 s before that."""
DROP_HEIGHT_M = 2.0
"""Height above the worker at which a tool is released (the agent's
``deliver_height_m`` default)."""


def _xyz(p: Point, above_m: float = 0.0) -> tuple[float, float, float]:
    return (p.x_m, p.y_m, p.z_m + above_m)


def capacity_wh(fleet: Fleet, uav_id: str) -> float:
    """The battery capacity of ``uav_id`` (a loaded scenario's fleet gives
    each of its UAVs a type it has)."""
    uav_type = fleet.type_of(uav_id)
    if uav_type is None:
        raise KeyError(f"UAV {uav_id!r} has no type in the fleet")
    return uav_type.battery_wh


def home_station(site: Site, spec: UavSpec) -> ChargingStation:
    """The home station of ``spec`` (a loaded scenario's fleet names
    stations of its site)."""
    station = site.station(spec.home_station)
    if station is None:
        raise KeyError(f"UAV {spec.id!r}: no charging station {spec.home_station!r}")
    return station


def flown_s(segment: MonitorTask, at_s: float) -> float:
    """Seconds of its planned window a monitoring segment being flown has
    behind it at ``at_s`` (the agent counts its time on station within the
    window, so this is what it reports if it arrived in time)."""
    return min(max(0.0, at_s - segment.window_start_s), segment.duration_s)


def build_problem(
    site: Site,
    fleet: Fleet,
    uavs: Iterable[UavNow],
    records: Iterable[ActionRecord],
    now_s: float,
    worker_positions: dict[str, Point] | None = None,
    monitor_starts: dict[str, float] | None = None,
    flying: Iterable[MonitorTask] = (),
) -> pl.Problem:
    """The planner's view of the mission at ``now_s`` (mission seconds).
    ``monitor_starts`` holds the synchronised starts (mission seconds)
    already promised for monitoring actions; future ones are kept if feasible.
    ``flying`` are the monitoring segments being flown: what those whose
    window has begun have flown is no longer asked of the plan (only ended
    segments are in a record's ``monitored_s``), so a replan never starts a
    watch over, and the rest of it starts at once."""
    workers = {w.id: w.position for w in site.workers} | (worker_positions or {})
    behind: dict[str, float] = {}
    for segment in flying:
        if segment.action_id is not None and segment.window_start_s <= now_s:
            share = flown_s(segment, now_s) / segment.slots
            behind[segment.action_id] = behind.get(segment.action_id, 0.0) + share
    specs = {u.id: u for u in fleet.uavs}
    safety = site.safety
    return pl.Problem(
        now_s=0.0,
        reserve_fraction=min(1.0, fleet.reserve_fraction + PLANNING_MARGIN),
        min_altitude_m=safety.ground_z_m + safety.min_altitude_m,
        separation_m=safety.separation_m,
        end=fleet.end.value,
        takeoff_s=TAKEOFF_LEAD_S,
        stations=tuple(
            pl.Station(
                id=s.id,
                position_m=_xyz(s.position),
                pads=s.pads,
                recharge="swap" if isinstance(s.recharge, BatterySwap) else "charge",
                swap_s=getattr(s.recharge, "swap_s", 60.0),
                full_charge_s=getattr(s.recharge, "full_charge_s", 1800.0),
            )
            for s in site.stations
        ),
        tool_stations=tuple(
            pl.ToolDepot(
                id=t.id, position_m=_xyz(t.position), tools=tuple(tool.name for tool in t.tools)
            )
            for t in site.tool_stations
        ),
        uav_types=tuple(
            pl.Airframe(
                id=t.name,
                capabilities={str(c): cost for c, cost in t.capabilities.items()},
                cruise_speed_mps=t.cruise_speed_mps,
                battery_wh=t.battery_wh,
                flight_power_w=t.flight_power_w,
                hover_power_w=t.hover_power_w,
            )
            for t in fleet.types
        ),
        uavs=tuple(
            pl.Uav(
                id=u.uav_id,
                type=specs[u.uav_id].type,
                position_m=_xyz(u.position),
                home_station=specs[u.uav_id].home_station,
                energy_wh=u.energy_wh,
                tool=u.tool,
                available=u.available,
                airborne=u.airborne,
                running=u.running,
            )
            for u in uavs
        ),
        actions=tuple(
            _action(r, workers, safety, now_s, monitor_starts or {}, behind.get(r.action_id))
            for r in records
        ),
    )


class _ActionCommon(TypedDict):
    """The fields every planner action has."""

    id: str
    weight: float
    release_s: float


def _action(
    record: ActionRecord,
    workers: dict[str, Point],
    safety: Safety,
    now_s: float,
    monitor_starts: dict[str, float],
    flying_s: float | None,
) -> pl.Job:
    """The planner's action; a delivery's ``worker_m`` is its drop point,
    ``DROP_HEIGHT_M`` above the worker, where the agent releases the tool; a
    monitor's duration is what is left of it (``flying_s``: flown in the
    segments being flown, None if none is), and one being flown goes on
    now: what is left starts at once (the UAVs on station keep it, unless
    they cannot), never after a gap for a UAV the planner likes better."""
    action = record.action
    common = _ActionCommon(
        id=record.action_id,
        weight=action.priority,
        release_s=max(0.0, action.release_s - now_s) if action.release_s else 0.0,
    )
    match action:
        case InspectAction(waypoints=waypoints):
            return pl.InspectJob(
                **common,
                waypoints=tuple(
                    pl.Viewpoint(position_m=_xyz(w.position), service_s=w.service_s)
                    for w in waypoints
                ),
                done=tuple(record.waypoints_done),
            )
        case MonitorAction():
            return pl.MonitorJob(
                **common,
                worker_m=_xyz(workers[action.worker_id]),
                k=action.uavs,
                standoff_m=action.standoff_m,
                height_m=safety.monitor_height_m,
                bearing_deg=action.bearing_deg or 0.0,
                duration_s=max(1.0, action.duration_s - record.monitored_s - (flying_s or 0.0)),
                start_s=0.0
                if flying_s is not None
                else _promised(monitor_starts.get(record.action_id), now_s),
            )
        case DeliverAction():
            return pl.DeliverJob(
                **common,
                tool=action.tool,
                tool_station=action.tool_station_id,
                worker_m=_xyz(workers[action.worker_id], DROP_HEIGHT_M),
                pick_s=action.pick_s,
                drop_s=action.drop_s,
            )
    raise TypeError(f"unknown action {action!r}")


def _promised(start_s: float | None, now_s: float) -> float | None:
    """A promised start on the planner's clock, if it is still ahead."""
    return start_s - now_s if start_s is not None and start_s > now_s else None


def monitor_starts(plans: Iterable[Plan]) -> dict[str, float]:
    """The synchronised start (mission seconds) of each monitoring action in
    ``plans``: the earliest moment one of its segments begins on station."""
    starts: dict[str, float] = {}
    for plan in plans:
        for task in plan.tasks:
            if isinstance(task, MonitorTask) and task.action_id is not None:
                begin = task.window_start_s
                starts[task.action_id] = min(begin, starts.get(task.action_id, begin))
    return starts


def name_reliefs(tasks: dict[str, list[Task]]) -> dict[str, list[Task]]:
    """Each UAV's tasks with every monitoring segment naming the UAV whose
    segment of the same slot begins where it ends (within
    ``SAME_SEGMENT_S``), if any: the agent keeps watching until that relief
    is there, so a late relief leaves no gap."""
    starts = [
        (t.action_id, t.slot, t.window_start_s, uav_id)
        for uav_id, listed in tasks.items()
        for t in listed
        if isinstance(t, MonitorTask)
    ]

    def relief(task: MonitorTask, uav_id: str) -> str | None:
        return next(
            (
                other
                for action_id, slot, start_s, other in starts
                if other != uav_id
                and (action_id, slot) == (task.action_id, task.slot)
                and abs(start_s - task.end_s) <= SAME_SEGMENT_S
            ),
            None,
        )

    return {
        uav_id: [
            msgspec.structs.replace(t, relieved_by=relief(t, uav_id))
            if isinstance(t, MonitorTask)
            else t
            for t in listed
        ]
        for uav_id, listed in tasks.items()
    }


def lead_departures(tasks: list[Task]) -> list[Task]:
    """End each wait before a monitoring segment ``TAKEOFF_LEAD_S`` early
    (never before the wait's start): the planner counts no time for
    arming, take-off and climb, and a relief must be on station before the
    UAV it relieves departs. A wait left shorter than ``SAME_WAIT_S`` is
    dropped: it asks nothing (a monitoring segment holds for its window
    itself), and one ending as it is sent ended at once, over and over
    (chaos seed 15: 62,000 plans, each a wait until now the UAV finished
    and the replan gave back)."""
    out: list[Task] = []
    for task, after in itertools.zip_longest(tasks, tasks[1:]):
        if isinstance(task, WaitTask):
            if isinstance(after, MonitorTask):
                until = max(task.start_s, task.until_s - TAKEOFF_LEAD_S)
                task = msgspec.structs.replace(task, until_s=until, end_s=until)
            if task.until_s - task.start_s < SAME_WAIT_S:
                continue
        out.append(task)
    return out


SAME_WAIT_S = 1.0
"""Wait deadlines this close ask the same of a UAV."""

SAME_SEGMENT_S = 5.0
"""Monitoring segments whose start and end move by no more than this ask the
same: estimates jitter from replan to replan; a segment cut short (the UAV
must leave earlier, another takes the rest) is new work and must be sent, or
two UAVs would hold the slot at once."""


def same_work(a: list[Task], b: list[Task]) -> bool:
    """Whether two task lists ask the same of a UAV (ids in order, wait
    deadlines and monitoring windows within their slack): if so, nothing is
    re-sent."""
    return [t.task_id for t in a] == [t.task_id for t in b] and all(map(_same_task, a, b))


def _same_task(a: Task, b: Task) -> bool:
    if isinstance(a, WaitTask) and isinstance(b, WaitTask):
        return abs(a.until_s - b.until_s) <= SAME_WAIT_S
    if isinstance(a, MonitorTask) and isinstance(b, MonitorTask):
        starts = (a.window_start_s, b.window_start_s)
        return (
            abs(a.end_s - b.end_s) <= SAME_SEGMENT_S
            and abs(starts[0] - starts[1]) <= SAME_SEGMENT_S
            and a.bearing_deg == b.bearing_deg  # a slot moved: its UAV must hear it
            and a.relieved_by == b.relieved_by  # whom to wait for before leaving
        )
    return True
