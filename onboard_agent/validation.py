"""Checks a plan's tasks against what this agent knows, before it flies them.

A task that names an unknown station, tool station or worker, an
inspection without waypoints, or a target below the site's minimum flight
altitude or too close to the person it serves, is rejected with a failure
outcome instead of failing (or crashing) half-way.
"""

from __future__ import annotations

from proto.plan import (
    DeliverTask,
    GoHomeTask,
    InspectTask,
    LandTask,
    MonitorTask,
    PickTask,
    RechargeTask,
    Task,
    WaitTask,
)
from proto.site import Site


def task_problem(task: Task, site: Site) -> str | None:
    """Why ``task`` cannot be flown here, or None if it can."""
    match task:
        case InspectTask(waypoints=[]):
            return "inspection without waypoints"
        case InspectTask(waypoints=waypoints):
            floor = site.safety.ground_z_m + site.safety.min_altitude_m
            low = [w.index for w in waypoints if w.position.z_m < floor]
            return f"waypoints {low} below the minimum altitude {floor:g} m" if low else None
        case MonitorTask(worker_id=worker) | DeliverTask(worker_id=worker):
            if site.worker(worker) is None:
                return f"unknown worker {worker!r}"
            if isinstance(task, MonitorTask):
                return _monitor_problem(task, site)
            return None
        case PickTask(tool_station_id=station_id):
            if site.tool_station(station_id) is None:
                return f"unknown tool station {station_id!r}"
            return None
        case RechargeTask(station_id=station_id) | GoHomeTask(station_id=station_id):
            if site.station(station_id) is None:
                return f"unknown station {station_id!r}"
            return None
        case WaitTask() | LandTask():
            return None
    return f"unsupported task {type(task).__name__}"


def _monitor_problem(task: MonitorTask, site: Site) -> str | None:
    if task.slot >= task.slots:
        return f"slot {task.slot} out of {task.slots}"
    clearance = site.safety.people_clearance_m
    if (task.standoff_m**2 + task.height_m**2) ** 0.5 < clearance:
        return f"monitoring slot closer than {clearance:g} m to the worker"
    return None
