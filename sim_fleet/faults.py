"""Fault injection: a wire fault command applied to the simulated world."""

from __future__ import annotations

import logging
from collections.abc import Iterable

from proto.errors import InvalidRequest, NotFound
from proto.sim import (
    BatteryFault,
    DrainFault,
    FaultApplied,
    GpsFreeze,
    GripperFailure,
    KillVehicle,
    LinkDrop,
    MotorFailure,
    MoveWorker,
    SimFault,
)
from proto.site import Site
from sim_fleet.world import World

log = logging.getLogger(__name__)


class UnknownTarget(NotFound):
    """A fault aimed at a UAV or worker the simulator does not have. Fix the id."""


class OutsideSite(InvalidRequest):
    """A worker moved outside the site's area (``Site.area``): nobody works
    there, and no UAV may fly there to follow them."""


def apply_fault(world: World, fault: SimFault, site: Site) -> FaultApplied:
    """Apply ``fault`` now (durations are simulated seconds); log and acknowledge it."""
    if isinstance(fault, MoveWorker):
        if fault.worker_id not in world.workers:
            raise UnknownTarget(
                _unknown("worker", fault.worker_id, world.workers), field="worker_id"
            )
        p = fault.position
        if not site.in_area(p):
            raise OutsideSite(
                f"({p.x_m:g}, {p.y_m:g}) is outside the site's area", field="position"
            )
        world.move_worker(fault.worker_id, (p.x_m, p.y_m, p.z_m))
        return _applied(world, fault.worker_id, f"moved to ({p.x_m:g}, {p.y_m:g}, {p.z_m:g})")
    vehicle = world.vehicles.get(fault.uav_id)
    if vehicle is None:
        raise UnknownTarget(_unknown("UAV", fault.uav_id, world.vehicles), field="uav_id")
    match fault:
        case BatteryFault(fraction=fraction):
            vehicle.set_battery_soc(fraction)
            detail = f"battery set to {fraction:.0%}"
        case DrainFault(multiplier=multiplier):
            vehicle.drain_multiplier = multiplier
            detail = f"drain x{multiplier:g}"
        case MotorFailure():
            vehicle.fail_motors()
            detail = "motors failed"
        case KillVehicle():
            vehicle.kill()
            detail = "killed: silent and falling"
        case LinkDrop(duration_s=duration):
            vehicle.drop_link(duration)
            detail = f"MAVLink silent for {duration:g} s"
        case GpsFreeze(duration_s=duration):
            vehicle.freeze_gps(duration)
            detail = f"GPS frozen for {duration:g} s"
        case GripperFailure(failed=failed):
            world.fail_gripper(fault.uav_id, failed)
            detail = "gripper failed" if failed else "gripper repaired"
    return _applied(world, fault.uav_id, detail)


def _applied(world: World, target: str, detail: str) -> FaultApplied:
    log.warning("fault on %s: %s", target, detail, extra={"target": target})
    return FaultApplied(target=target, detail=detail, sim_time_s=world.time_s)


def _unknown(what: str, ident: str, known: Iterable[str]) -> str:
    return f"no {what} {ident!r} (known: {', '.join(known)})"
