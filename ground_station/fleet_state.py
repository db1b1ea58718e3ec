"""The fleet's state as the planner needs it, read from the watchdog's latest
reports and the plans held: where each UAV is, its energy, whether it can
take work, and the action it is in the middle of."""

from __future__ import annotations

import math

from ground_station import planner as pl
from ground_station.fleet_monitor import FleetMonitor
from ground_station.planning import UavNow, capacity_wh, home_station
from proto.plan import DeliverTask, GoHomeTask, MonitorTask, Plan, Task
from proto.scenario import Scenario
from proto.site import ChargingStation
from proto.spots import spot_positions
from proto.telemetry import FlightState, Telemetry

ON_PAD_M = 1.0
"""A landed UAV this close (horizontally) to a spot of a station is on it."""

AIRBORNE = frozenset({FlightState.FLYING, FlightState.TAKING_OFF, FlightState.LANDING})


def uavs_now(
    scenario: Scenario,
    docks: Docks,
    monitor: FleetMonitor,
    plans: dict[str, Plan],
    in_force: set[str],
    controlled: frozenset[str] = frozenset(),
) -> list[UavNow]:
    """Every UAV of the fleet as of its latest telemetry (at home, full, if
    none; docked on a spot: at its station); one under an operator's command
    (``controlled``) takes no work."""
    site, fleet = scenario.site, scenario.fleet
    uavs = []
    for spec in fleet.uavs:
        telemetry = monitor.telemetry(spec.id)
        capacity = capacity_wh(fleet, spec.id)
        docked = docks.under(telemetry, spec.home_station)
        where = telemetry.position if telemetry else home_station(site, spec).position
        uavs.append(
            UavNow(
                uav_id=spec.id,
                position=docked.position if docked is not None else where,
                energy_wh=min(capacity, telemetry.battery_wh) if telemetry else capacity,
                available=monitor.available(spec.id) and spec.id not in controlled,
                airborne=bool(telemetry and telemetry.flight_state in AIRBORNE),
                tool=monitor.tool(spec.id),
                running=running_task(monitor, plans.get(spec.id), in_force),
            )
        )
    return uavs


def reported_task(monitor: FleetMonitor, plan: Plan | None, in_force: set[str]) -> Task | None:
    """The task of ``plan`` its UAV's latest status says it is executing, if
    that task belongs to an action in force."""
    if plan is None:
        return None
    status = monitor.status(plan.uav_id)
    if status is None or status.task_id is None:
        return None
    for task in plan.tasks:
        if task.task_id == status.task_id and task.action_id in in_force:
            return task
    return None


def running_task(
    monitor: FleetMonitor, plan: Plan | None, in_force: set[str]
) -> pl.RunningTask | None:
    """The monitoring segment of an action in force the UAV of ``plan`` is
    flying (its slot: the planner keeps the UAV on it), or the delivery whose
    tool it holds, if any."""
    task = reported_task(monitor, plan, in_force)
    if task is None or plan is None or task.action_id is None:
        return None
    if isinstance(task, MonitorTask):
        return pl.RunningTask(action_id=task.action_id, index=task.slot)
    if isinstance(task, DeliverTask) and monitor.tool(plan.uav_id) == task.tool:
        return pl.RunningTask(action_id=task.action_id)
    return None


def flying_segments(
    monitor: FleetMonitor, plans: dict[str, Plan], in_force: set[str]
) -> dict[str, MonitorTask]:
    """The monitoring segments of actions in force that their UAVs report
    flying now, by task id."""
    flying: dict[str, MonitorTask] = {}
    for plan in plans.values():
        task = reported_task(monitor, plan, in_force)
        if isinstance(task, MonitorTask):
            flying[task.task_id] = task
    return flying


def drop_done_home(
    docks: Docks, monitor: FleetMonitor, uav_id: str, tasks: list[Task]
) -> list[Task]:
    """A plan that only sends a UAV to the pad it already sits on asks
    nothing: it is empty (else the agent would "complete" it at once, over
    and over)."""
    telemetry = monitor.telemetry(uav_id)
    if len(tasks) != 1 or not isinstance(tasks[0], GoHomeTask) or telemetry is None:
        return tasks
    station = docks.under(telemetry, tasks[0].station_id)
    return [] if station is not None and station.id == tasks[0].station_id else tasks


class Docks:
    """Where UAVs sit at the stations (every station's spots, found once):
    a landed UAV on a spot is at that station, for a planner whose stations
    are points."""

    def __init__(self, scenario: Scenario) -> None:
        self._spots = [(s, spot_positions(s, scenario.fleet)) for s in scenario.site.stations]

    def under(self, telemetry: Telemetry | None, first: str = "") -> ChargingStation | None:
        """The station a landed UAV sits on a spot of, if any; station
        ``first`` before the others (where the rows of spots of two
        stations cross, as on a site resized to 100 UAVs, a UAV on its home
        spot is at home, not at the other station: it was sent home again
        and again)."""
        if telemetry is None or telemetry.flight_state != FlightState.LANDED:
            return None
        p = telemetry.position
        for station, spots in sorted(self._spots, key=lambda entry: entry[0].id != first):
            if any(math.hypot(p.x_m - q.x_m, p.y_m - q.y_m) <= ON_PAD_M for q in spots):
                return station
        return None
