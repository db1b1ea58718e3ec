"""Telemetry messages built from a vehicle's state, as ArduCopter fills them.

``encode`` takes the endpoint's pymavlink encoder (``MAVLink`` instance) so
that only ``mavlink_endpoint`` imports pymavlink; enum values are spelled out
as ints here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

from sim_fleet import streams
from sim_fleet.modes import LANDED_STATE, base_mode, system_status
from sim_fleet.physics import Vec3
from sim_fleet.vehicle import Vehicle
from sim_fleet.world import World

MAV_TYPE_QUADROTOR = 2
MAV_AUTOPILOT_ARDUPILOTMEGA = 3
# AUTOPILOT_VERSION: ArduCopter 4.5.0 official
FLIGHT_SW_VERSION = (4 << 24) | (5 << 16) | (0 << 8) | 255
# MAV_PROTOCOL_CAPABILITY: MISSION_INT, COMMAND_INT, SET_POSITION_TARGET_LOCAL_NED,
# SET_POSITION_TARGET_GLOBAL_INT, MAVLINK2
CAPABILITIES = 4 | 8 | 128 | 256 | 8192
SENSOR_GPS = 0x20
SENSOR_AHRS = 0x200000
SENSOR_BATTERY = 0x2000000
SENSOR_PREARM = 0x10000000  # MAV_SYS_STATUS_PREARM_CHECK: healthy when armable
SENSORS = 0x1 | 0x2 | 0x4 | 0x8 | SENSOR_GPS | 0x8000 | SENSOR_AHRS | SENSOR_BATTERY | SENSOR_PREARM
# EKF_STATUS_REPORT flags: attitude, velocities, positions (rel/abs, horiz/vert), predicted
EKF_GOOD = 0x1 | 0x2 | 0x4 | 0x8 | 0x10 | 0x20 | 0x100 | 0x200
EKF_NO_GPS = 0x1 | 0x4 | 0x80  # attitude, vertical velocity, constant position mode
UINT16_MAX = 65535
# MAV_BATTERY_CHARGE_STATE
CHARGE_OK, CHARGE_LOW, CHARGE_CRITICAL, CHARGE_CHARGING = 1, 2, 3, 7
MAV_BATTERY_FUNCTION_ALL = 1
MAV_BATTERY_TYPE_LIPO = 1


class _Now(NamedTuple):
    """What the messages of one ``encode`` read besides the vehicle."""

    boot_ms: int  # mission milliseconds, wrapped to 32 bits
    pos: Vec3  # as the GPS reports it
    vel: Vec3  # as the GPS reports it
    pct: int  # battery remaining, 0-100


_Builder = Callable[[Any, World, Vehicle, _Now], Any]


def encode(m: Any, world: World, v: Vehicle, msg_id: int) -> Any:
    """Build one telemetry message from the vehicle's state (None if unknown)."""
    boot_ms = int(world.time_s * 1000) & 0xFFFFFFFF
    pos, vel = v.reported_position()  # also ends a GPS freeze that is over
    pct = max(0, min(100, round(v.battery.soc * 100)))
    build = _BUILDERS.get(msg_id)
    return build(m, world, v, _Now(boot_ms, pos, vel, pct)) if build is not None else None


def _heartbeat(m: Any, _world: World, v: Vehicle, _now: _Now) -> Any:
    """HEARTBEAT: type, autopilot, mode and system status."""
    critical = v.battery.soc <= v.params.critical_soc
    return m.heartbeat_encode(
        MAV_TYPE_QUADROTOR,
        MAV_AUTOPILOT_ARDUPILOTMEGA,
        base_mode(v.mode, v.armed),
        int(v.mode),
        system_status(v.armed, v.state, critical),
    )


def _global_position_int(m: Any, world: World, v: Vehicle, now: _Now) -> Any:
    """GLOBAL_POSITION_INT: the fused position (zeros until the EKF has one)."""
    boot_ms, pos, vel = now.boot_ms, now.pos, now.vel
    if not v.ekf_ok:  # no position yet: ArduCopter sends zeros
        return m.global_position_int_encode(boot_ms, 0, 0, 0, 0, 0, 0, 0, UINT16_MAX)
    lat, lon, alt = world.geo.to_geodetic(pos)
    return m.global_position_int_encode(
        boot_ms, round(lat * 1e7), round(lon * 1e7), round(alt * 1000),
        round((pos[2] - v.home[2]) * 1000), round(vel[1] * 100), round(vel[0] * 100),
        round(-vel[2] * 100), round(v.heading_deg * 100) % 36000,
    )  # fmt: skip


def _gps_raw_int(m: Any, world: World, v: Vehicle, now: _Now) -> Any:
    """GPS_RAW_INT: a 3D fix, or NO_FIX while the GPS has none."""
    boot_ms, pos, vel = now.boot_ms, now.pos, now.vel
    if not v.gps_fix:
        return m.gps_raw_int_encode(
            boot_ms * 1000, 1, 0, 0, 0, UINT16_MAX, UINT16_MAX, 0, UINT16_MAX, 0
        )  # fix_type 1: NO_FIX
    lat, lon, alt = world.geo.to_geodetic(pos)
    cog = round(v.heading_deg * 100) % 36000
    return m.gps_raw_int_encode(
        boot_ms * 1000, 3, round(lat * 1e7), round(lon * 1e7), round(alt * 1000),
        121, 200, round(math.hypot(vel[0], vel[1]) * 100), cog, 10,
    )  # fmt: skip


def _ekf_status_report(m: Any, _world: World, v: Vehicle, _now: _Now) -> Any:
    """EKF_STATUS_REPORT: good, or attitude only without GPS."""
    if v.ekf_ok:
        return m.ekf_status_report_encode(EKF_GOOD, 0.02, 0.01, 0.01, 0.02, 0.0)
    return m.ekf_status_report_encode(EKF_NO_GPS, 0.0, 0.0, 0.0, 0.02, 0.0)


def _attitude(m: Any, _world: World, v: Vehicle, now: _Now) -> Any:
    """ATTITUDE: level, yawed to the heading (-pi..pi)."""
    yaw = math.radians(v.heading_deg)
    yaw = yaw - 2 * math.pi if yaw > math.pi else yaw
    return m.attitude_encode(now.boot_ms, 0.0, 0.0, yaw, 0.0, 0.0, 0.0)


def _vfr_hud(m: Any, world: World, v: Vehicle, now: _Now) -> Any:
    """VFR_HUD: speeds, heading, throttle, altitude and climb."""
    pos, vel = now.pos, now.vel
    _, _, alt = world.geo.to_geodetic(pos if v.ekf_ok else (0.0, 0.0, 0.0))
    gs = math.hypot(vel[0], vel[1])
    throttle = 50 if v.armed and v.airborne else 0
    return m.vfr_hud_encode(gs, gs, round(v.heading_deg) % 360, throttle, alt, vel[2])


def _extended_sys_state(m: Any, _world: World, v: Vehicle, _now: _Now) -> Any:
    """EXTENDED_SYS_STATE: the landed state."""
    return m.extended_sys_state_encode(0, LANDED_STATE[v.state])


def _home_position(m: Any, world: World, v: Vehicle, now: _Now) -> Any:
    """HOME_POSITION, once home is set."""
    if not v.home_set:
        return None  # ArduPilot sends no HOME_POSITION before home is set
    lat, lon, alt = world.geo.to_geodetic(v.home)
    return m.home_position_encode(
        round(lat * 1e7), round(lon * 1e7), round(alt * 1000), 0.0, 0.0, 0.0,
        [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0, now.boot_ms * 1000,
    )  # fmt: skip


def _autopilot_version(m: Any, _world: World, v: Vehicle, _now: _Now) -> Any:
    """AUTOPILOT_VERSION: ArduCopter's capabilities and version."""
    zeros = [0] * 8
    return m.autopilot_version_encode(
        CAPABILITIES, FLIGHT_SW_VERSION, 0, 0, 0, zeros, zeros, zeros, 0, 0, v.sysid
    )


def _sys_status(m: Any, _world: World, v: Vehicle, now: _Now) -> Any:
    """SYS_STATUS: sensors present, enabled and healthy; the battery."""
    battery = v.battery
    health = SENSORS
    if battery.soc <= v.params.critical_soc:
        health &= ~SENSOR_BATTERY
    if not v.gps_fix:
        health &= ~SENSOR_GPS
    if not v.ekf_ok:
        health &= ~SENSOR_AHRS
    if v.prearm_failures():
        health &= ~SENSOR_PREARM
    return m.sys_status_encode(
        SENSORS, SENSORS, health, 0, round(battery.voltage_v() * 1000),
        round(battery.current_a() * 100), now.pct, 0, 0, 0, 0, 0, 0,
    )  # fmt: skip


def _battery_status(m: Any, world: World, v: Vehicle, now: _Now) -> Any:
    """BATTERY_STATUS: voltage, current, consumption and charge state."""
    b = v.battery
    docked = world.station_status(v.id)
    if docked is not None and docked[1] == "charging":
        charge_state = CHARGE_CHARGING
    elif b.soc <= v.params.critical_soc:
        charge_state = CHARGE_CRITICAL
    elif b.soc <= v.params.low_soc:
        charge_state = CHARGE_LOW
    else:
        charge_state = CHARGE_OK
    remaining_s = round(b.energy_wh * 3600 / b.load_w) if b.load_w > 0 else 0
    voltages = [min(round(b.voltage_v() * 1000), UINT16_MAX - 1)] + [UINT16_MAX] * 9
    return m.battery_status_encode(
        0,
        MAV_BATTERY_FUNCTION_ALL,
        MAV_BATTERY_TYPE_LIPO,
        32767,  # temperature unknown (INT16_MAX)
        voltages,
        round(b.current_a() * 100),  # cA
        round(b.consumed_mah()),  # mAh
        round(b.consumed_wh * 36),  # hJ
        now.pct,
        remaining_s,
        charge_state,
    )


_BUILDERS: dict[int, _Builder] = {
    streams.HEARTBEAT: _heartbeat,
    streams.GLOBAL_POSITION_INT: _global_position_int,
    streams.GPS_RAW_INT: _gps_raw_int,
    streams.EKF_STATUS_REPORT: _ekf_status_report,
    streams.ATTITUDE: _attitude,
    streams.VFR_HUD: _vfr_hud,
    streams.SYS_STATUS: _sys_status,
    streams.BATTERY_STATUS: _battery_status,
    streams.EXTENDED_SYS_STATE: _extended_sys_state,
    streams.HOME_POSITION: _home_position,
    streams.AUTOPILOT_VERSION: _autopilot_version,
}
"""Message id -> how the message is built (ids not here: none is)."""
