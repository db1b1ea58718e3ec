"""Fault injection: a wire fault command applied to the simulated world."""

from __future__ import annotations

from proto.errors import RequestError
from proto.sim import BatteryFault, FaultApplied, GpsFreeze, LinkDrop, MotorFailure, SimFault
from sim_fleet.world import World


class UnknownVehicle(RequestError):
    """A fault aimed at a UAV the simulator does not have. Fix the id."""

    code = "not_found"


def apply_fault(world: World, fault: SimFault) -> FaultApplied:
    """Apply ``fault`` now; durations are simulated seconds."""
    vehicle = world.vehicles.get(fault.uav_id)
    if vehicle is None:
        known = ", ".join(world.vehicles)
        raise UnknownVehicle(f"no UAV {fault.uav_id!r} (known: {known})", field="uav_id")
    match fault:
        case BatteryFault(fraction=fraction):
            vehicle.set_battery_soc(fraction)
            detail = f"battery set to {fraction:.0%}"
        case MotorFailure():
            vehicle.fail_motors()
            detail = "motors failed"
        case LinkDrop(duration_s=duration):
            vehicle.drop_link(duration)
            detail = f"MAVLink silent for {duration:g} s"
        case GpsFreeze(duration_s=duration):
            vehicle.freeze_gps(duration)
            detail = f"GPS frozen for {duration:g} s"
    return FaultApplied(uav_id=fault.uav_id, detail=detail, sim_time_s=world.time_s)
