"""Telemetry messages built from a vehicle's state, as ArduCopter fills them.

``encode`` takes the endpoint's pymavlink encoder (``MAVLink`` instance) so
that only ``mavlink_endpoint`` imports pymavlink; enum values are spelled out
as ints here.
"""

from __future__ import annotations

import math
from typing import Any

from sim_fleet import streams
from sim_fleet.modes import LANDED_STATE, base_mode, system_status
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


def encode(m: Any, world: World, v: Vehicle, msg_id: int) -> Any:
    """Build one telemetry message from the vehicle's state (None if unknown)."""
    boot_ms = int(world.time_s * 1000) & 0xFFFFFFFF
    pos, vel = v.reported_position()
    battery = v.battery
    pct = max(0, min(100, round(battery.soc * 100)))
    match msg_id:
        case streams.HEARTBEAT:
            critical = battery.soc <= v.params.critical_soc
            return m.heartbeat_encode(
                MAV_TYPE_QUADROTOR,
                MAV_AUTOPILOT_ARDUPILOTMEGA,
                base_mode(v.mode, v.armed),
                int(v.mode),
                system_status(v.armed, v.state, critical),
            )
        case streams.GLOBAL_POSITION_INT:
            if not v.ekf_ok:  # no position yet: ArduCopter sends zeros
                return m.global_position_int_encode(boot_ms, 0, 0, 0, 0, 0, 0, 0, UINT16_MAX)
            lat, lon, alt = world.geo.to_geodetic(pos)
            return m.global_position_int_encode(
                boot_ms, round(lat * 1e7), round(lon * 1e7), round(alt * 1000),
                round((pos[2] - v.home[2]) * 1000), round(vel[1] * 100), round(vel[0] * 100),
                round(-vel[2] * 100), round(v.heading_deg * 100) % 36000,
            )  # fmt: skip
        case streams.GPS_RAW_INT:
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
        case streams.EKF_STATUS_REPORT:
            if v.ekf_ok:
                return m.ekf_status_report_encode(EKF_GOOD, 0.02, 0.01, 0.01, 0.02, 0.0)
            return m.ekf_status_report_encode(EKF_NO_GPS, 0.0, 0.0, 0.0, 0.02, 0.0)
        case streams.ATTITUDE:
            yaw = math.radians(v.heading_deg)
            yaw = yaw - 2 * math.pi if yaw > math.pi else yaw
            return m.attitude_encode(boot_ms, 0.0, 0.0, yaw, 0.0, 0.0, 0.0)
        case streams.VFR_HUD:
            _, _, alt = world.geo.to_geodetic(pos if v.ekf_ok else (0.0, 0.0, 0.0))
            gs = math.hypot(vel[0], vel[1])
            throttle = 50 if v.armed and v.airborne else 0
            return m.vfr_hud_encode(gs, gs, round(v.heading_deg) % 360, throttle, alt, vel[2])
        case streams.SYS_STATUS:
            return _sys_status(m, v, pct)
        case streams.BATTERY_STATUS:
            return _battery_status(m, world, v, pct)
        case streams.EXTENDED_SYS_STATE:
            return m.extended_sys_state_encode(0, LANDED_STATE[v.state])
        case streams.HOME_POSITION:
            if not v.home_set:
                return None  # ArduPilot sends no HOME_POSITION before home is set
            lat, lon, alt = world.geo.to_geodetic(v.home)
            return m.home_position_encode(
                round(lat * 1e7), round(lon * 1e7), round(alt * 1000), 0.0, 0.0, 0.0,
                [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0, boot_ms * 1000,
            )  # fmt: skip
        case streams.AUTOPILOT_VERSION:
            zeros = [0] * 8
            return m.autopilot_version_encode(
                CAPABILITIES, FLIGHT_SW_VERSION, 0, 0, 0, zeros, zeros, zeros, 0, 0, v.sysid
            )
    return None


def _sys_status(m: Any, v: Vehicle, pct: int) -> Any:
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
        round(battery.current_a() * 100), pct, 0, 0, 0, 0, 0, 0,
    )  # fmt: skip


def _battery_status(m: Any, world: World, v: Vehicle, pct: int) -> Any:
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
        pct,
        remaining_s,
        charge_state,
    )
