"""One UAV's planner steps as wire tasks: relative planner times become
absolute mission seconds, and task ids are derived from what a task is (see
:mod:`ground_station.planning`), so that a replan that leaves a UAV's work
alone yields the same ids."""

from __future__ import annotations

from typing import TypedDict

import msgspec

from ground_station import planner as pl
from ground_station.monitor_bearings import task_bearing
from ground_station.planning import capacity_wh, flown_s, lead_departures
from proto.fleet import Fleet
from proto.geo import Point
from proto.mission import ActionRecord, DeliverAction, InspectAction, MonitorAction
from proto.plan import (
    DeliverTask,
    GoHomeTask,
    InspectTask,
    MonitorTask,
    PickTask,
    RechargeTask,
    Task,
    WaitTask,
    Waypoint,
)
from proto.site import ChargingStation, Safety, Site


class Times(TypedDict):
    """The planner's estimates every wire task carries (mission seconds)."""

    start_s: float
    end_s: float
    energy_after_wh: float


def to_tasks(
    uav_plan: pl.UavPlan,
    site: Site,
    fleet: Fleet,
    records: dict[str, ActionRecord],
    now_s: float,
    flying: dict[str, MonitorTask] | None = None,
) -> list[Task]:
    """One UAV's planner steps as wire tasks (absolute mission seconds). A
    segment that goes on one of ``flying`` (by task id) keeps its window's
    start: its duration counts what was flown before ``now_s`` too, so the
    agent ends it, and the ground station credits it, as one segment."""
    capacity = capacity_wh(fleet, uav_plan.uav_id)
    stations = {s.id: s for s in site.stations}
    tasks: list[Task] = []
    counts: dict[str, int] = {}
    steps = list(uav_plan.steps)
    i = 0
    while i < len(steps):
        step = steps[i]
        times = Times(
            start_s=now_s + step.start_s,
            end_s=now_s + step.end_s,
            energy_after_wh=step.energy_after_wh,
        )
        record = records.get(step.action_id) if step.action_id else None
        action = record.action if record else None
        if step.kind == "inspect" and isinstance(action, InspectAction):
            j = i
            while (
                j + 1 < len(steps)
                and steps[j + 1].kind == "inspect"
                and steps[j + 1].action_id == step.action_id
            ):
                j += 1
            group = steps[i : j + 1]
            times["end_s"] = now_s + group[-1].end_s
            times["energy_after_wh"] = group[-1].energy_after_wh
            tasks.append(
                InspectTask(
                    task_id=f"{step.action_id}.wp{group[0].index}-{group[-1].index}",
                    action_id=step.action_id,
                    waypoints=_waypoints(action, group),
                    **times,
                )
            )
            i = j + 1
            continue
        task = _simple_task(
            step, record, uav_plan.uav_id, stations, site.safety, capacity, counts, times
        )
        going_on = (flying or {}).get(task.task_id)
        if isinstance(task, MonitorTask) and going_on is not None:
            duration = task.duration_s + flown_s(going_on, now_s)
            task = msgspec.structs.replace(task, duration_s=duration)
        tasks.append(task)
        i += 1
    return lead_departures(tasks)


def _waypoints(action: InspectAction, group: list[pl.Step]) -> list[Waypoint]:
    """The waypoints of ``action`` a run of its inspect steps visits."""
    waypoints = []
    for s in group:
        if s.index is None:
            raise ValueError(f"an inspect step of {s.action_id!r} has no waypoint index")
        spec = action.waypoints[s.index]
        waypoints.append(Waypoint(index=s.index, position=spec.position, service_s=spec.service_s))
    return waypoints


def _simple_task(
    step: pl.Step,
    record: ActionRecord | None,
    uav_id: str,
    stations: dict[str, ChargingStation],
    safety: Safety,
    capacity: float,
    counts: dict[str, int],
    times: Times,
) -> Task:
    """A wire task for a planner step other than inspect; a ``ValueError``
    if the step lacks what its task needs (its action, slot or station)."""
    action = record.action if record is not None else None

    def ordinal(kind: str) -> int:
        counts[kind] = counts.get(kind, 0) + 1
        return counts[kind]

    match step.kind:
        case "monitor" if (
            record is not None
            and isinstance(action, MonitorAction)
            and step.action_id is not None
            and step.index is not None
        ):
            done = record.segments.get(uav_id, 0)
            return MonitorTask(
                task_id=f"{step.action_id}.slot{step.index}.{uav_id}."
                f"{done + ordinal('monitor:' + step.action_id)}",
                action_id=step.action_id,
                worker_id=action.worker_id,
                slot=step.index,
                slots=action.uavs,
                standoff_m=action.standoff_m,
                height_m=safety.monitor_height_m,
                bearing_deg=task_bearing(record, step.index),
                duration_s=max(0.001, step.end_s - step.arrive_s),
                **times,
            )
        case "pick" if isinstance(action, DeliverAction):
            return PickTask(
                task_id=f"{step.action_id}.pick",
                action_id=step.action_id,
                tool=action.tool,
                tool_station_id=action.tool_station_id,
                position=_point(step.position_m),
                pick_s=action.pick_s,
                **times,
            )
        case "deliver" if isinstance(action, DeliverAction):
            return DeliverTask(
                task_id=f"{step.action_id}.drop",
                action_id=step.action_id,
                tool=action.tool,
                worker_id=action.worker_id,
                drop_s=action.drop_s,
                **times,
            )
        case "recharge" if step.station is not None:
            return RechargeTask(
                task_id=f"{uav_id}.recharge{ordinal('recharge')}",
                station_id=step.station,
                position=stations[step.station].position,
                until_fraction=min(1.0, step.energy_after_wh / capacity),
                **times,
            )
        case "wait":
            return WaitTask(
                task_id=f"{uav_id}.wait{ordinal('wait')}", until_s=times["end_s"], **times
            )
        case "home" if step.station is not None:
            return GoHomeTask(
                task_id=f"{uav_id}.home",
                station_id=step.station,
                position=stations[step.station].position,
                **times,
            )
    raise ValueError(f"planner step {step.kind!r} ({step.action_id}) has no wire task")


def _point(xyz: tuple[float, float, float]) -> Point:
    return Point(x_m=xyz[0], y_m=xyz[1], z_m=xyz[2])
