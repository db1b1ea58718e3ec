"""Energy judgements: is there enough to do the next step and still reach a
station with the reserve, and is there even enough to reach one now?

"The next step" is the part of the head task up to its next checkpoint: the
next inspection waypoint with its service time, the next
``MONITOR_LOOKAHEAD_S`` of monitoring, never past the segment's planned end
(a long watch is not one step: the UAV keeps its slot while it can and
leaves for a station when it must, and the ground station hands the slot
over at the planned end), the leg to the tool station or the
worker, the leg to the station of a recharge / go-home task, or hovering
until a wait ends when airborne (at most ``MONITOR_LOOKAHEAD_S`` of it).
"""

from __future__ import annotations

from onboard_agent import targets
from onboard_agent.context import Context
from proto.geo import Point
from proto.plan import (
    DeliverTask,
    GoHomeTask,
    InspectTask,
    MonitorTask,
    PickTask,
    RechargeTask,
    WaitTask,
)

MONITOR_LOOKAHEAD_S = 30.0
"""Monitoring (or airborne waiting) seconds that must fit in the battery
before and while doing it."""


def available_wh(ctx: Context) -> float:
    """Energy in the pack now, from the autopilot's state of charge."""
    return ctx.energy.energy_wh(ctx.vehicle.battery_fraction)


def to_station_wh(ctx: Context, where: Point) -> float:
    """Energy to fly from ``where`` to the nearest charging station and land."""
    station = ctx.surroundings.nearest_station(where)
    if station is None:
        return 0.0
    return ctx.energy.travel_wh(where, station.position)


def step_wh(ctx: Context) -> tuple[float, Point]:
    """Energy of the head task's next step, and where that step ends."""
    here = ctx.vehicle.position
    task = ctx.mission.head
    energy = ctx.energy
    match task:
        case InspectTask():
            wp = ctx.mission.next_waypoint(task)
            if wp is None:
                return 0.0, here
            return energy.travel_wh(here, wp.position) + energy.hover_wh(wp.service_s), wp.position
        case MonitorTask(duration_s=duration):
            slot = targets.monitor_slot(ctx) or here
            left = duration - ctx.mission.monitored_s(task.task_id)
            if task.end_s > 0:  # a planned window: the plan says when to leave
                left = min(left, task.end_s - ctx.wall())
            look_ahead = max(0.0, min(left, MONITOR_LOOKAHEAD_S))
            return energy.travel_wh(here, slot) + energy.hover_wh(look_ahead), slot
        case PickTask(pick_s=service) | DeliverTask(drop_s=service):
            point = (targets.pick_point if isinstance(task, PickTask) else targets.drop_point)(ctx)
            point = point or here
            return energy.travel_wh(here, point) + energy.hover_wh(service), point
        case RechargeTask() | GoHomeTask():
            station = ctx.surroundings.station(task.station_id)
            point = station.position if station is not None else here
            return energy.travel_wh(here, point), point
        case WaitTask(until_s=until) if not ctx.vehicle.landed:  # a hold is no one step either
            return energy.hover_wh(min(until - ctx.wall(), MONITOR_LOOKAHEAD_S)), here
    return 0.0, here


def battery_enough(ctx: Context) -> bool:
    """Enough energy for the next step, then the nearest station, with the
    reserve. An unknown battery or position is no verdict: a UAV that does
    not know them is not ready and stays on the ground (see "Go near")."""
    if not ctx.vehicle.battery_known or not ctx.vehicle.known:
        return True
    step, end = step_wh(ctx)
    needed = step + to_station_wh(ctx, end) + ctx.energy.reserve_wh
    return available_wh(ctx) >= needed


def can_reach_station(ctx: Context) -> bool:
    """Enough energy to reach the nearest station now and keep the reserve."""
    vehicle = ctx.vehicle
    if not vehicle.known or not vehicle.battery_known or vehicle.landed:
        return True  # unknown is no emergency; a landed UAV draws nothing: it recharges instead
    station = ctx.surroundings.nearest_station(vehicle.position)
    where = station.position if station is not None else vehicle.position
    return ctx.energy.reaches(vehicle.battery_fraction, vehicle.position, where)
