"""Planning-problem types: the planner's own input model.

All Structs are frozen and keyword-only. Units are in field names (``_m``
metres in the site's local ENU frame, ``_s`` seconds on the problem's clock,
``_wh`` watt-hours, ``_w`` watts, ``_mps`` metres per second); fractions are
0..1. The ground station converts wire types to these at its boundary.
"""

from __future__ import annotations

from math import cos, pi, radians, sin
from typing import Literal

import msgspec

Vec3 = tuple[float, float, float]
"""A point (x, y, z) in metres in the site's local ENU frame."""

KINDS: tuple[str, ...] = ("deliver", "inspect", "monitor")

End = Literal["home", "any_station"]
"""Where UAVs end the mission: ``home``, each at its home station (the
paper's "back to station"); ``any_station``, at home or at a station with a
pad free for good from its landing on, never the last free one."""


class Station(msgspec.Struct, frozen=True, kw_only=True):
    """A charging / battery-swap station (also a landing spot).

    ``pads`` charging pads are shared by the whole fleet: never more UAVs
    recharge here at once. ``pads == 0`` makes it a landing spot only.
    Recharge model: ``"swap"`` takes ``swap_s`` and leaves the battery full;
    ``"charge"`` takes ``full_charge_s`` times the missing fraction.
    """

    id: str
    position_m: Vec3
    pads: int = 1
    recharge: Literal["swap", "charge"] = "charge"
    swap_s: float = 60.0
    full_charge_s: float = 1800.0


class ToolDepot(msgspec.Struct, frozen=True, kw_only=True):
    """A pick-up point holding (any number of copies of) ``tools``."""

    id: str
    position_m: Vec3
    tools: tuple[str, ...] = ()


class Airframe(msgspec.Struct, frozen=True, kw_only=True):
    """A UAV model.

    ``capabilities`` maps an action kind to its suitability cost J1 in 0..1
    (0 ideal, 1 barely acceptable); a missing kind means incapable.
    """

    id: str
    capabilities: dict[str, float]
    cruise_speed_mps: float
    battery_wh: float
    flight_power_w: float
    hover_power_w: float


class RunningTask(msgspec.Struct, frozen=True, kw_only=True):
    """What a UAV is doing right now.

    inspect: servicing waypoint ``index`` with ``remaining_s`` left (kept on
    this UAV, first in its plan). deliver: the UAV holds the tool (kept, the
    drop is first in its plan). monitor: the UAV holds slot ``index``; it goes on
    there first, takes no other slot before, and is preferred for that
    action (J3 continuation bonus).
    """

    action_id: str
    index: int = 0
    remaining_s: float = 0.0


class Uav(msgspec.Struct, frozen=True, kw_only=True):
    """One UAV's state at the problem's ``now_s``."""

    id: str
    type: str
    position_m: Vec3
    home_station: str
    energy_wh: float
    tool: str | None = None
    available: bool = True
    airborne: bool = False
    running: RunningTask | None = None


class Viewpoint(msgspec.Struct, frozen=True, kw_only=True):
    """An inspection point and the time spent servicing it (hovering)."""

    position_m: Vec3
    service_s: float = 0.0


class InspectJob(msgspec.Struct, frozen=True, kw_only=True, tag="inspect", tag_field="kind"):
    """Inspect ordered ``waypoints``; indices in ``done`` are already inspected."""

    id: str
    weight: float = 1.0
    release_s: float = 0.0
    waypoints: tuple[Viewpoint, ...]
    done: tuple[int, ...] = ()


class MonitorJob(msgspec.Struct, frozen=True, kw_only=True, tag="monitor", tag_field="kind"):
    """Watch a worker with ``k`` UAVs starting together, for ``duration_s``.

    Slot ``s`` sits ``standoff_m`` from the worker horizontally at bearing
    ``bearing_deg`` + 360*s/k degrees, ``height_m`` above them (never at a
    person's own height).
    """

    id: str
    weight: float = 1.0
    release_s: float = 0.0
    worker_m: Vec3
    k: int = 1
    standoff_m: float = 5.0
    height_m: float = 3.0
    bearing_deg: float = 0.0
    duration_s: float
    start_s: float | None = None
    """A synchronised start already promised to the UAVs: kept whenever it
    is still feasible, so that a replan does not move a start the fleet is
    waiting for (which would wait again, and again)."""


WAIT_ASIDE_M = 3.0
"""A UAV that waits airborne after a monitoring segment hovers this far
along the ring (counter-clockwise) from its slot, clear of its relief."""


def slot_position(a: MonitorJob, slot: int, aside_m: float = 0.0) -> Vec3:
    """Stand-off position of ``slot`` (bearing ``bearing_deg`` + 360*slot/k
    degrees, ``height_m`` above the worker), ``aside_m`` along the ring."""
    x, y, z = a.worker_m
    ang = radians(a.bearing_deg) + 2 * pi * slot / a.k
    r = a.standoff_m
    return (
        x + r * cos(ang) - aside_m * sin(ang),
        y + r * sin(ang) + aside_m * cos(ang),
        z + a.height_m,
    )


class DeliverJob(msgspec.Struct, frozen=True, kw_only=True, tag="deliver", tag_field="kind"):
    """Pick ``tool`` at ``tool_station`` and bring it to the worker."""

    id: str
    weight: float = 1.0
    release_s: float = 0.0
    tool: str
    tool_station: str
    worker_m: Vec3
    pick_s: float = 10.0
    drop_s: float = 10.0


Job = InspectJob | MonitorJob | DeliverJob


class CostWeights(msgspec.Struct, frozen=True, kw_only=True):
    """Weights of the allocation cost w1*J1 + w2*J2 + w3*J3.

    J1 is the 0..1 suitability of the UAV type, J2 the time (s) at which the
    part would be finished counted from ``now_s`` (travel, queueing and
    recharge detours included), J3 the interruption term (a bonus of -1 for
    the UAV that is already running the action). Defaults: one unit of
    unsuitability is worth 120 s of delay, so an ideal UAV wins unless an
    acceptable one finishes minutes earlier; continuing a running task is
    worth 30 s (avoids needless hand-overs on replans). ``approach`` adds,
    per second of flight from where the UAV is to the part's start, that many
    seconds: the battery a transit burns must be recharged later (about 1.4 s
    on a pad per second of flight for the bench fleets) and pads are scarce,
    which a finish-time J2 alone does not see. 5 was the best of 0/2/3/5/8
    on the corridor bench (1 % to 14 % better makespan + mean completion
    than 0); the paper's distance-only J2 is the other extreme.
    """

    suitability_s: float = 120.0
    travel: float = 1.0
    interruption_s: float = 30.0
    approach: float = 5.0


class Problem(msgspec.Struct, frozen=True, kw_only=True):
    """A planning problem: fleet state, stations and the actions in force."""

    now_s: float = 0.0
    reserve_fraction: float = 0.2
    stations: tuple[Station, ...]
    tool_stations: tuple[ToolDepot, ...] = ()
    uav_types: tuple[Airframe, ...]
    uavs: tuple[Uav, ...]
    actions: tuple[Job, ...] = ()
    weights: CostWeights = CostWeights()
    min_monitor_segment_s: float = 20.0
    min_altitude_m: float = 0.0
    """Lowest z of any service position (waypoint, slot, pick, drop); the
    validator reports a step below it as ``too_low``."""
    separation_m: float = 1.0
    """No two UAVs hover closer than this at once (metres, 3-D): points
    nearer each other are held one UAV at a time; the validator reports
    ``separation``."""
    end: End = "home"
    """End-of-mission policy (``End``), reached with as many recharges on the
    way as needed; the validator reports ``not_home`` / ``end_station``."""
    takeoff_s: float = 0.0
    """Seconds a UAV on the ground needs before it flies (arming, take-off,
    climb). Legs are flown as if it took none; only a synchronised
    monitoring start counts it, so that a UAV leaving a pad for the ring is
    there when the watch begins."""
