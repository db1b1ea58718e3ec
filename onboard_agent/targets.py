"""Where each "go near X" leads and when the UAV counts as near X.

A :class:`Target` locates a point from the context (None when it cannot be
known) and says how close is close enough; the "Is Agent near X?" condition
and the "Go near X" action share it, so they always agree.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import msgspec

from onboard_agent.context import Context
from onboard_agent.surroundings import horizontal_distance
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
from proto.site import ChargingStation


@dataclasses.dataclass(frozen=True)
class Target:
    """A named place; ``horizontal`` targets ignore altitude when judging nearness."""

    label: str
    locate: Callable[[Context], Point | None]
    radius_m: Callable[[Context], float]
    horizontal: bool = False
    settle: bool = False  # near only once hovering (to grab, release or land)
    cleared: Callable[[Context], bool] = lambda _ctx: True  # may the UAV go on once near?
    cruise_z: Callable[[Context], float | None] = lambda _ctx: None  # height to cross at
    keep_clear: Callable[[Context], bool] = lambda _ctx: True  # hold off while another UAV is there

    def distance(self, ctx: Context, point: Point) -> float:
        here = ctx.vehicle.position
        return horizontal_distance(here, point) if self.horizontal else here.distance_to(point)

    def reached(self, ctx: Context) -> bool:
        point = self.locate(ctx)
        if point is None or not ctx.vehicle.known:
            return False
        near = self.distance(ctx, point) <= self.radius_m(ctx)
        slow = ctx.vehicle.speed_mps <= ctx.config.settle_speed_mps
        return near and (slow or not self.settle) and self.cleared(ctx)


def _above(point: Point, height_m: float) -> Point:
    return Point(x_m=point.x_m, y_m=point.y_m, z_m=point.z_m + height_m)


def waypoint(ctx: Context) -> Point | None:
    task = ctx.mission.head
    if not isinstance(task, InspectTask):
        return None
    wp = ctx.mission.next_waypoint(task)
    return wp.position if wp is not None else None


def _safe(ctx: Context, point: Point) -> Point:
    """``point`` raised to the site's minimum flight altitude if below it."""
    safety = ctx.surroundings.site.safety
    floor = safety.ground_z_m + safety.min_altitude_m
    return point if point.z_m >= floor else Point(x_m=point.x_m, y_m=point.y_m, z_m=floor)


def _ring_point(
    ctx: Context, task: MonitorTask, radius_m: float, aside_m: float = 0.0
) -> Point | None:
    """The point ``radius_m`` from the task's worker on its slot's bearing,
    ``height_m`` above them, moved ``aside_m`` along the ring (counter-clockwise)."""
    worker = ctx.surroundings.worker_position(task.worker_id)
    if worker is None:
        return None
    angle = math.radians(task.bearing_deg) + 2 * math.pi * task.slot / task.slots
    x = worker.x_m + radius_m * math.cos(angle) - aside_m * math.sin(angle)
    y = worker.y_m + radius_m * math.sin(angle) + aside_m * math.cos(angle)
    return _safe(ctx, Point(x_m=x, y_m=y, z_m=worker.z_m + task.height_m))


def monitor_slot(ctx: Context) -> Point | None:
    """Slot ``slot`` of ``slots`` on a circle of ``standoff_m`` around the
    worker (counted from the bearing ``bearing_deg``), ``height_m`` above
    them (never at a person's own height). Before the segment's window
    begins (a relief that arrived early, while the UAV it relieves still
    holds the slot) the point lies ``handover_hold_m`` farther out on the
    same bearing, clear of that UAV. Past its end, while the relief is not
    there (:func:`awaiting_relief`), it lies on the ring ``wait_aside_m``
    from the slot (counter-clockwise): the worker stays watched and the slot
    is free for the relief to close in on. Past its end with a relief named
    and not awaited (it is there, or waited for too long) it is where the UAV
    is: the UAV leaves from there, never back into the slot (chaos seed 11:
    a relieved UAV flew back in and passed 0.98 m under its relief)."""
    task = ctx.mission.head
    if not isinstance(task, MonitorTask):
        return None
    if awaiting_relief(ctx):
        chord = min(1.0, ctx.config.wait_aside_m / (2.0 * task.standoff_m))
        turn_deg = 2.0 * math.degrees(math.asin(chord))
        turned = msgspec.structs.replace(task, bearing_deg=task.bearing_deg + turn_deg)
        return _ring_point(ctx, turned, task.standoff_m)
    if task.relieved_by is not None and 0 < task.end_s <= ctx.wall():
        return ctx.vehicle.position if ctx.surroundings.worker_position(task.worker_id) else None
    return _slot_point(ctx, task)


def _slot_point(ctx: Context, task: MonitorTask) -> Point | None:
    early = task.end_s > 0 and ctx.wall() < task.window_start_s
    radius = task.standoff_m + (ctx.config.handover_hold_m if early else 0.0)
    return _ring_point(ctx, task, radius)


def awaiting_relief(ctx: Context) -> bool:
    """Whether the head segment is past its end and the relief it names is
    not at the slot yet (not within ``relief_there_m`` of it in the traffic
    report: one holding farther out, or coming down from above, is not
    watching yet), for at most ``relief_wait_s``."""
    task, config = ctx.mission.head, ctx.config
    if not isinstance(task, MonitorTask) or task.relieved_by is None or task.end_s <= 0:
        return False
    if not task.end_s <= ctx.wall() < task.end_s + config.relief_wait_s:
        return False
    slot = _slot_point(ctx, task)
    there = ctx.traffic.position(task.relieved_by, ctx.link_clock())
    return slot is not None and (there is None or there.distance_to(slot) > config.relief_there_m)


def wait_aside(ctx: Context) -> Point | None:
    """Where an airborne wait that follows a monitoring segment hovers:
    ``wait_aside_m`` along the ring from the slot it left, clear of the
    relief that takes the slot over (coming in along the bearing). None
    for any other wait, on the ground, or once the wait is over."""
    task, left = ctx.mission.head, ctx.mission.left_slot
    if not isinstance(task, WaitTask) or left is None or ctx.vehicle.landed:
        return None
    if ctx.wall() >= task.until_s:
        return None
    return _ring_point(ctx, left, left.standoff_m, ctx.config.wait_aside_m)


def drop_point(ctx: Context) -> Point | None:
    """Above the worker of the head delivery task: ``deliver_height_m``, and
    never nearer them than the site's people clearance."""
    task = ctx.mission.head
    if not isinstance(task, DeliverTask):
        return None
    worker = ctx.surroundings.worker_position(task.worker_id)
    if worker is None:
        return None
    height = max(ctx.config.deliver_height_m, ctx.surroundings.site.safety.people_clearance_m)
    return _safe(ctx, _above(worker, height))


def pick_point(ctx: Context) -> Point | None:
    """Above the tool station of the head pick task (or one stocking the tool)."""
    task = ctx.mission.head
    station = None
    if isinstance(task, PickTask):
        station = ctx.surroundings.tool_station(task.tool_station_id)
    elif isinstance(task, DeliverTask):
        station = ctx.surroundings.tool_station_for(task.tool)
    return _above(station.position, ctx.config.pick_height_m) if station is not None else None


def return_point(ctx: Context) -> Point | None:
    """Above the tool station where the held tool came from (else the nearest)."""
    station = None
    if ctx.tool_station_id is not None:
        station = ctx.surroundings.tool_station(ctx.tool_station_id)
    if station is None:
        station = ctx.surroundings.nearest_tool_station(ctx.vehicle.position)
    return _above(station.position, ctx.config.pick_height_m) if station is not None else None


def _landing(ctx: Context, station: ChargingStation) -> Point:
    """Above the spot of ``station`` granted to this UAV; above its hold
    point while the claim waits for the grant (see :mod:`onboard_agent.spots`)."""
    spot = ctx.spots.landing_point(station, ctx.clock())
    if spot is None:
        return ctx.spots.hold_point(station, ctx.config.approach_alt_m)
    return _above(spot, ctx.config.approach_alt_m)


def task_station(ctx: Context) -> ChargingStation | None:
    """The station of the head recharge / go-home task."""
    task = ctx.mission.head
    if not isinstance(task, RechargeTask | GoHomeTask):
        return None
    return ctx.surroundings.station(task.station_id)


def landing_station(ctx: Context) -> ChargingStation | None:
    """Where to land off the plan (battery low, mission over, emergency): the
    station granted already; cut off from every spot controller, home (its
    home spot is the one spot no other UAV can be on) if the energy reaches
    it with the reserve; else the nearest with room, else the nearest.
    None while the autopilot has no position: "nearest" to the placeholder
    it reports until its first fix (the origin) would claim a spot at a
    station the UAV is not near, a grant that then sticks (issue 21)."""
    stations = ctx.surroundings.site.stations
    granted = [s for s in stations if ctx.spots.granted(s.id) is not None]
    if granted:
        return granted[0]
    if not ctx.vehicle.known:
        return None
    here = ctx.vehicle.position
    home = ctx.surroundings.station(ctx.spots.home_station or "")
    if home is not None and ctx.spots.cut_off() and _reaches(ctx, home.position):
        return home
    roomy = [s for s in stations if ctx.spots.has_room(s.id)]
    return ctx.surroundings.nearest_station(here, roomy or stations)


def _reaches(ctx: Context, where: Point) -> bool:
    """Whether the energy left flies the UAV to ``where`` with the reserve
    (an unknown battery: assumed so)."""
    vehicle = ctx.vehicle
    return not vehicle.battery_known or ctx.energy.reaches(
        vehicle.battery_fraction, vehicle.position, where
    )


def station_target(pick: Callable[[Context], ChargingStation | None]) -> Target:
    """Above a landing spot at the station ``pick`` names: near once over
    the spot granted to this UAV (or no controller gates it), flown to at
    the UAV's own hold height there. The point above the spot is kept clear
    of like any other (a UAV hovering 1 m from it, at an inspection
    waypoint, chaos seed 15); the hold point is not (spots keep UAVs
    waiting apart, at heights of their own)."""

    def locate(ctx: Context) -> Point | None:
        station = pick(ctx)
        return _landing(ctx, station) if station is not None else None

    def cleared(ctx: Context) -> bool:
        station = pick(ctx)
        return station is None or ctx.spots.cleared(station.id)

    def cruise_z(ctx: Context) -> float | None:
        station = pick(ctx)
        if station is None:
            return None
        return ctx.spots.hold_point(station, ctx.config.approach_alt_m).z_m

    def radius(ctx: Context) -> float:
        return ctx.config.near_station_m

    def landing(ctx: Context) -> bool:
        station = pick(ctx)
        return station is not None and ctx.spots.cleared(station.id)

    return Target(
        "Charging Station",
        locate,
        radius,
        True,
        cleared=cleared,
        cruise_z=cruise_z,
        keep_clear=landing,
    )


WAYPOINT = Target("WP", waypoint, lambda c: c.config.near_waypoint_m)
HUMAN_SLOT = Target("Human Target", monitor_slot, lambda c: c.config.near_slot_m)
WAIT_ASIDE = Target("Aside", wait_aside, lambda c: c.config.near_slot_m)
HUMAN_DROP = Target("Human Target", drop_point, lambda c: c.config.near_human_m, settle=True)
TOOL_STATION = Target("Station", pick_point, lambda c: c.config.near_tool_station_m, settle=True)
TOOL_RETURN = Target("Station", return_point, lambda c: c.config.near_tool_station_m, settle=True)
TASK_STATION = station_target(task_station)
NEAREST_STATION = station_target(landing_station)
