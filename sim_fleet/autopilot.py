"""ArduCopter's rules for commands: what is accepted, what fails, and why.

Functions over a ``Vehicle`` that return an ``Outcome`` (the MAV_RESULT plus
the STATUSTEXT ArduCopter would send, if any). Results mirror ArduCopter 4.x
(GCS_MAVLink_Copter.cpp, AP_Arming_Copter.cpp): e.g. a takeoff while disarmed
is FAILED, DO_CHANGE_SPEED with a non-positive speed is DENIED, SET_MODE
without the custom-mode flag is DENIED, an unknown command is UNSUPPORTED.
Coordinates arrive already converted to local ENU by the endpoint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from sim_fleet.events import ACCEPTED, Outcome, Result, Severity
from sim_fleet.modes import (
    ARMABLE_MODES,
    FLAG_CUSTOM_MODE_ENABLED,
    TAKEOFF_MODES,
    FlightState,
    Mode,
)
from sim_fleet.physics import Vec3
from sim_fleet.vehicle import AIRBORNE, Vehicle

# MAV_CMD numbers handled here
CMD_NAV_RETURN_TO_LAUNCH = 20
CMD_NAV_LAND = 21
CMD_NAV_TAKEOFF = 22
CMD_DO_SET_MODE = 176
CMD_DO_CHANGE_SPEED = 178
CMD_DO_GRIPPER = 211
CMD_DO_REPOSITION = 192
REPOSITION_CHANGE_MODE = 1  # MAV_DO_REPOSITION_FLAGS_CHANGE_MODE
CMD_COMPONENT_ARM_DISARM = 400

FORCE_MAGIC = 21196  # param2 of ARM_DISARM that skips checks
FRAME_GLOBAL_RELATIVE_ALT = 3
FRAME_GLOBAL_RELATIVE_ALT_INT = 6

FAILED = Outcome(Result.FAILED)
DENIED = Outcome(Result.DENIED)
UNSUPPORTED = Outcome(Result.UNSUPPORTED)


@dataclass(frozen=True, slots=True)
class Command:
    """A COMMAND_LONG or COMMAND_INT, decoded. ``frame`` is None for COMMAND_LONG."""

    command: int
    params: tuple[float, float, float, float, float, float, float]
    frame: int | None = None


class ToolHooks(Protocol):
    """What the world offers a gripper (implemented by ``World``)."""

    def grab(self, vehicle: Vehicle) -> str: ...

    def release(self, vehicle: Vehicle) -> str: ...


def handle_command(cmd: Command, vehicle: Vehicle, tools: ToolHooks) -> Outcome:
    """Apply one command to ``vehicle``; never raises on odd parameters."""
    p = cmd.params
    match cmd.command:
        case 400:  # CMD_COMPONENT_ARM_DISARM
            forced = as_int(p[1]) == FORCE_MAGIC
            if p[0] not in (0.0, 1.0):
                return DENIED
            return arm(vehicle, forced=forced) if p[0] == 1.0 else disarm(vehicle, forced=forced)
        case 176:  # CMD_DO_SET_MODE
            return set_mode(vehicle, as_int(p[0]), as_int(p[1]))
        case 22:  # CMD_NAV_TAKEOFF
            frame_ok = cmd.frame in (None, FRAME_GLOBAL_RELATIVE_ALT, FRAME_GLOBAL_RELATIVE_ALT_INT)
            return takeoff(vehicle, p[6]) if frame_ok else DENIED
        case 178:  # CMD_DO_CHANGE_SPEED
            return change_speed(vehicle, as_int(p[0]), p[1])
        case 21:  # CMD_NAV_LAND
            return _mode_change(vehicle, Mode.LAND)
        case 20:  # CMD_NAV_RETURN_TO_LAUNCH
            return _mode_change(vehicle, Mode.RTL)
        case 211:  # CMD_DO_GRIPPER
            return gripper(vehicle, as_int(p[1]), tools)
        case _:
            return UNSUPPORTED


def as_int(x: float) -> int:
    """A float parameter as an int; NaN and infinities become -1 (never valid)."""
    return int(x) if math.isfinite(x) else -1


def arm(vehicle: Vehicle, *, forced: bool = False) -> Outcome:
    """AP_Arming_Copter::arm: every failing pre-arm check is reported (one
    STATUSTEXT each), the ACK is FAILED. A forced arm skips all but the motors."""
    if vehicle.armed:
        return ACCEPTED
    failures = vehicle.prearm_failures()
    if forced:
        failures = [f for f in failures if f.startswith("PreArm: Motors")]
    if failures:
        return Outcome(Result.FAILED, "\n".join(failures))
    if vehicle.mode not in ARMABLE_MODES:
        return Outcome(Result.FAILED, "Arm: Mode not armable")
    vehicle.arm()
    vehicle.say(Severity.INFO, "Arming motors")
    return ACCEPTED


def disarm(vehicle: Vehicle, *, forced: bool = False) -> Outcome:
    if not vehicle.armed:
        return ACCEPTED
    if vehicle.state in AIRBORNE and not forced:
        return FAILED  # AP_Arming_Copter::disarm: GCS may not disarm a flying copter
    vehicle.disarm()
    return ACCEPTED


def set_mode(vehicle: Vehicle, base_mode: int, custom_mode: int) -> Outcome:
    """SET_MODE / DO_SET_MODE, as GCS_MAVLINK::_set_mode_common."""
    if base_mode < 0 or not base_mode & FLAG_CUSTOM_MODE_ENABLED:
        return DENIED
    try:
        mode = Mode(custom_mode)
    except ValueError:
        return Outcome(Result.FAILED, f"No such mode {custom_mode}")
    return _mode_change(vehicle, mode)


def _mode_change(vehicle: Vehicle, mode: Mode) -> Outcome:
    if vehicle.mode is not mode:
        vehicle.enter_mode(mode)
    return ACCEPTED


def takeoff(vehicle: Vehicle, alt_m: float) -> Outcome:
    """GUIDED takeoff to ``alt_m`` above home (ModeGuided::do_user_takeoff:
    refused unless above the current altitude above home)."""
    if vehicle.mode not in TAKEOFF_MODES or not vehicle.armed:
        return FAILED
    if vehicle.state is not FlightState.LANDED or math.isnan(alt_m):
        return FAILED
    home_z = vehicle.home[2]
    if alt_m <= vehicle.position[2] - home_z:
        return FAILED
    vehicle.start_takeoff(home_z + alt_m)
    return ACCEPTED


def change_speed(vehicle: Vehicle, speed_type: int, speed_mps: float) -> Outcome:
    if not speed_mps > 0.0:
        return DENIED  # "Target speed must be larger than zero"
    if speed_type not in (0, 1, 2, 3):
        return DENIED
    if vehicle.mode not in (Mode.GUIDED, Mode.RTL, Mode.AUTO):
        return FAILED  # the mode has no speed to set
    t = vehicle.type
    if speed_type in (0, 1):
        vehicle.speed_mps = min(speed_mps, 2.0 * t.cruise_speed_mps)
    elif speed_type == 2:
        vehicle.climb_mps = min(speed_mps, 2.0 * t.climb_rate_mps)
    else:
        vehicle.descent_mps = min(speed_mps, 2.0 * t.climb_rate_mps)
    return ACCEPTED


def gripper(vehicle: Vehicle, action: int, tools: ToolHooks) -> Outcome:
    """DO_GRIPPER param2: 0 release, 1 grab. Vehicles without one: UNSUPPORTED."""
    if not vehicle.has_gripper:
        return Outcome(Result.UNSUPPORTED, "Gripper: not fitted")
    if vehicle.parameters.get("GRIP_ENABLE") != 1:
        return Outcome(Result.FAILED, "Gripper: not enabled (GRIP_ENABLE 0)")
    if action not in (0, 1):
        return FAILED
    if vehicle.gripper_failed:
        return ACCEPTED  # a dead gripper acknowledges and does nothing
    text = tools.grab(vehicle) if action == 1 else tools.release(vehicle)
    vehicle.say(Severity.INFO, text)
    return ACCEPTED


def reposition(vehicle: Vehicle, target: Vec3 | None, flags: int) -> Outcome:
    """DO_REPOSITION (GCS_MAVLINK_Copter::handle_command_int_do_reposition):
    outside GUIDED only with the change-mode flag; the vehicle must be flying."""
    change_mode = bool(flags & REPOSITION_CHANGE_MODE)
    if vehicle.mode is not Mode.GUIDED and not change_mode:
        return DENIED
    if target is None:
        return DENIED
    if vehicle.state not in (FlightState.FLYING, FlightState.TAKING_OFF) or not vehicle.armed:
        return FAILED
    if vehicle.mode is not Mode.GUIDED:
        vehicle.enter_mode(Mode.GUIDED)
    vehicle.fly_to(target)
    return ACCEPTED


def set_param(vehicle: Vehicle, name: str, value: float) -> bool:
    """PARAM_SET: store the value and apply the few that act at once."""
    if not math.isfinite(value):
        return False
    p = vehicle.parameters.store(name, value)
    if p is None:
        return False
    t = vehicle.type
    if name == "WPNAV_SPEED" and value > 0:
        vehicle.speed_mps = min(value / 100.0, 2.0 * t.cruise_speed_mps)
    elif name == "WPNAV_SPEED_UP" and value > 0:
        vehicle.climb_mps = min(value / 100.0, 2.0 * t.climb_rate_mps)
    elif name == "WPNAV_SPEED_DN" and value > 0:
        vehicle.descent_mps = min(value / 100.0, 2.0 * t.climb_rate_mps)
    return True


def position_target(vehicle: Vehicle, position: Vec3 | None, velocity: Vec3 | None) -> None:
    """SET_POSITION_TARGET_*: honoured only in GUIDED while flying; else ignored."""
    if vehicle.mode is not Mode.GUIDED:
        return
    if vehicle.state not in (FlightState.FLYING, FlightState.TAKING_OFF):
        return
    if position is not None:
        vehicle.fly_to(position)
    elif velocity is not None:
        vehicle.fly_velocity(velocity)
    else:
        vehicle.fly_to(vehicle.position)  # ModeGuided::init(true): stop


def hold(vehicle: Vehicle) -> None:
    """Bad target input in GUIDED: stop where we are."""
    position_target(vehicle, None, None)
