"""Simulator control: fault injection (queries on ``sim/fault``) and the
simulator's ground truth (queries on ``sim/state``)."""

from __future__ import annotations

from proto.base import Finite, Fraction, Id, Message, Positive, Record, Text
from proto.geo import Point


class BatteryFault(Message, frozen=True, kw_only=True, tag="battery"):
    """Set ``uav_id``'s battery to ``fraction`` of capacity at once."""

    uav_id: Id
    fraction: Fraction


class MotorFailure(Message, frozen=True, kw_only=True, tag="motor"):
    """``uav_id`` loses thrust: it falls if airborne."""

    uav_id: Id


class LinkDrop(Message, frozen=True, kw_only=True, tag="link"):
    """``uav_id``'s MAVLink endpoint goes silent for ``duration_s``."""

    uav_id: Id
    duration_s: Positive


class GpsFreeze(Message, frozen=True, kw_only=True, tag="gps"):
    """``uav_id`` reports a frozen position for ``duration_s``."""

    uav_id: Id
    duration_s: Positive


class DrainFault(Message, frozen=True, kw_only=True, tag="drain"):
    """``uav_id`` draws ``multiplier`` times its modelled power from now on."""

    uav_id: Id
    multiplier: Positive


class KillVehicle(Message, frozen=True, kw_only=True, tag="kill"):
    """``uav_id`` is lost: no more heartbeats, and it falls."""

    uav_id: Id


class GripperFailure(Message, frozen=True, kw_only=True, tag="gripper"):
    """``uav_id``'s gripper stops working (``failed=False`` repairs it)."""

    uav_id: Id
    failed: bool = True


class MoveWorker(Message, frozen=True, kw_only=True, tag="move_worker"):
    """Put worker ``worker_id`` at ``position`` (a worker without a scripted path)."""

    worker_id: Id
    position: Point


SimFault = (
    BatteryFault
    | MotorFailure
    | LinkDrop
    | GpsFreeze
    | DrainFault
    | KillVehicle
    | GripperFailure
    | MoveWorker
)


class FaultApplied(Message, frozen=True, kw_only=True):
    """The simulator's reply to a fault: on what (a UAV or worker id), what it
    did, at which simulated time."""

    target: Id
    detail: Text
    sim_time_s: Finite


class GetSimState(Message, frozen=True, kw_only=True, tag="sim_state"):
    """Ask the simulator for its ground truth, on ``sim/state``."""


class DeliveryRecord(Record, frozen=True, kw_only=True):
    """A tool released within reach of a worker (the simulator's truth)."""

    tool: Text
    uav_id: Id
    worker_id: Id
    sim_time_s: Finite


class SafetyViolation(Record, frozen=True, kw_only=True):
    """Something the simulator saw that must never happen.

    ``kind``: ``ground_contact`` (touched the ground while flying, away from a
    controlled landing: a crash), ``off_pad_landing`` (landed away from every
    charging pad), ``people_proximity`` (airborne within the site's
    ``people_clearance_m`` of a worker), ``separation`` (two UAVs, one at least airborne,
    closer than ``separation_m``). One record each time a condition begins.
    """

    kind: Text
    uav_id: Id
    sim_time_s: Finite
    position: Point
    detail: Text = ""


class WatchRecord(Record, frozen=True, kw_only=True):
    """Seconds ``uav_id`` hovered above ``worker_id`` within the simulator's
    watch radius (its truth for monitoring; generous: any such hover counts)."""

    worker_id: Id
    uav_id: Id
    seconds: Finite


class VehicleTruth(Record, frozen=True, kw_only=True):
    """A vehicle as the simulator knows it."""

    uav_id: Id
    position: Point
    battery_fraction: Fraction
    state: Text
    armed: bool
    tool: Text | None = None
    docked_at: Id | None = None


class SimState(Message, frozen=True, kw_only=True):
    """The simulator's ground truth: time, vehicles, deliveries, safety
    violations and watched seconds."""

    sim_time_s: Finite
    speedup: Finite
    vehicles: list[VehicleTruth] = []
    deliveries: list[DeliveryRecord] = []
    violations: list[SafetyViolation] = []
    watched: list[WatchRecord] = []
