"""ArduCopter flight modes, flight states and the HEARTBEAT/landed-state mapping.

MAVLink enum values are spelled out here as ints so that only
``mavlink_endpoint`` imports pymavlink.
"""

from __future__ import annotations

from enum import IntEnum, StrEnum


class Mode(IntEnum):
    """ArduCopter custom_mode numbers the simulator implements."""

    STABILIZE = 0  # no sticks here: holds position in the air, armable on ground
    AUTO = 3  # flies the uploaded mission (auto_mission); not armable (AUTO_OPTIONS 0)
    GUIDED = 4
    LOITER = 5  # no sticks here: holds position
    RTL = 6
    LAND = 9
    BRAKE = 17  # stops and holds position (MAVSDK's "hold" on ArduCopter)


ARMABLE_MODES = frozenset({Mode.STABILIZE, Mode.GUIDED, Mode.LOITER})  # ArduCopter allows_arming()
TAKEOFF_MODES = frozenset({Mode.GUIDED})  # has_user_takeoff() in GUIDED


class FlightState(StrEnum):
    LANDED = "landed"
    TAKING_OFF = "taking_off"
    FLYING = "flying"
    LANDING = "landing"
    FALLING = "falling"  # motors stopped in the air
    CRASHED = "crashed"  # hit the ground falling or flying; stays there


# MAV_LANDED_STATE
LANDED_STATE = {
    FlightState.LANDED: 1,  # ON_GROUND
    FlightState.TAKING_OFF: 3,  # TAKEOFF
    FlightState.FLYING: 2,  # IN_AIR
    FlightState.LANDING: 4,  # LANDING
    FlightState.FALLING: 2,  # IN_AIR
    FlightState.CRASHED: 1,  # ON_GROUND
}

# MAV_MODE_FLAG bits
FLAG_CUSTOM_MODE_ENABLED = 1
FLAG_GUIDED_ENABLED = 8
FLAG_STABILIZE_ENABLED = 16
FLAG_MANUAL_INPUT_ENABLED = 64
FLAG_SAFETY_ARMED = 128

# MAV_STATE
STATE_STANDBY = 3
STATE_ACTIVE = 4
STATE_CRITICAL = 5
STATE_EMERGENCY = 6

_GUIDED_LIKE = frozenset({Mode.GUIDED, Mode.RTL, Mode.AUTO})


def base_mode(mode: Mode, armed: bool) -> int:
    """HEARTBEAT.base_mode as GCS_MAVLINK_Copter::base_mode() computes it."""
    bits = FLAG_STABILIZE_ENABLED | FLAG_MANUAL_INPUT_ENABLED | FLAG_CUSTOM_MODE_ENABLED
    if mode in _GUIDED_LIKE:
        bits |= FLAG_GUIDED_ENABLED
    if armed:
        bits |= FLAG_SAFETY_ARMED
    return bits


def system_status(armed: bool, state: FlightState, battery_critical: bool) -> int:
    """HEARTBEAT.system_status (MAV_STATE)."""
    if state in (FlightState.FALLING, FlightState.CRASHED):
        return STATE_EMERGENCY
    if armed and battery_critical:
        return STATE_CRITICAL
    return STATE_ACTIVE if armed else STATE_STANDBY
