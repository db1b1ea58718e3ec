"""Kinematic multirotor: speed, climb/descent rate and acceleration limits.

Pure functions over ``(position, velocity)`` tuples in ENU metres; no state.
Horizontal and vertical axes are limited independently, as an autopilot's
position controller does (WPNAV_SPEED vs WPNAV_SPEED_UP/DN).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Vec3 = tuple[float, float, float]
"""A position or velocity: site metres (east, north, up), or per second."""

GRAVITY_MPS2 = 9.81
ARRIVED_M = 1e-3  # closer than this with no speed: snapped onto the target


@dataclass(frozen=True, kw_only=True)
class Limits:
    horizontal_mps: float
    up_mps: float
    down_mps: float
    accel_mps2: float


def _approach(error: float, v: float, v_max: float, accel: float, dt: float) -> float:
    """1-D speed command that reaches ``error`` away without overshooting."""
    dist = abs(error)
    # fastest speed that can still brake in time with per-step decrements of accel*dt:
    # v^2 / (2a) + v dt / 2 = dist
    brake = accel * (math.sqrt(dt * dt / 4.0 + 2.0 * dist / accel) - dt / 2.0)
    want = min(v_max, brake, dist / dt) * math.copysign(1.0, error)
    return _accel_limited(v, want, accel, dt)


def _accel_limited(v: float, want: float, accel: float, dt: float) -> float:
    dv = want - v
    cap = accel * dt
    if abs(dv) > cap:
        dv = math.copysign(cap, dv)
    return v + dv


def step_to_target(pos: Vec3, vel: Vec3, target: Vec3, lim: Limits, dt: float) -> tuple[Vec3, Vec3]:
    """Advance ``dt`` seconds flying towards ``target``; returns new (pos, vel)."""
    ex, ey = target[0] - pos[0], target[1] - pos[1]
    dist = math.hypot(ex, ey)
    vx, vy = vel[0], vel[1]
    if dist > 0.0:
        # speed along the line of sight, with the lateral component bled off
        ux, uy = ex / dist, ey / dist
        along = vx * ux + vy * uy
        along_new = _approach(dist, along, lim.horizontal_mps, lim.accel_mps2, dt)
        wx, wy = ux * along_new, uy * along_new
        nvx = _accel_limited(vx, wx, lim.accel_mps2, dt)
        nvy = _accel_limited(vy, wy, lim.accel_mps2, dt)
    else:
        nvx = _accel_limited(vx, 0.0, lim.accel_mps2, dt)
        nvy = _accel_limited(vy, 0.0, lim.accel_mps2, dt)
    ez = target[2] - pos[2]
    vz_max = lim.up_mps if ez > 0 else lim.down_mps
    nvz = _approach(ez, vel[2], vz_max, lim.accel_mps2, dt) if ez else 0.0
    new_pos = (pos[0] + nvx * dt, pos[1] + nvy * dt, pos[2] + nvz * dt)
    new_vel = (nvx, nvy, nvz)
    # on the target and slow enough to stop within a step: settle there
    if distance(new_pos, target) < ARRIVED_M and speed(new_vel) <= lim.accel_mps2 * dt:
        return target, (0.0, 0.0, 0.0)
    return new_pos, new_vel


def step_velocity(pos: Vec3, vel: Vec3, want: Vec3, lim: Limits, dt: float) -> tuple[Vec3, Vec3]:
    """Advance ``dt`` seconds tracking a velocity command (clamped to limits)."""
    h = math.hypot(want[0], want[1])
    scale = min(1.0, lim.horizontal_mps / h) if h > 0 else 1.0
    wz = max(-lim.down_mps, min(lim.up_mps, want[2]))
    nv = (
        _accel_limited(vel[0], want[0] * scale, lim.accel_mps2, dt),
        _accel_limited(vel[1], want[1] * scale, lim.accel_mps2, dt),
        _accel_limited(vel[2], wz, lim.accel_mps2, dt),
    )
    return (pos[0] + nv[0] * dt, pos[1] + nv[1] * dt, pos[2] + nv[2] * dt), nv


def step_falling(pos: Vec3, vel: Vec3, dt: float) -> tuple[Vec3, Vec3]:
    """Unpowered: ballistic fall (no drag)."""
    nvz = vel[2] - GRAVITY_MPS2 * dt
    return (pos[0] + vel[0] * dt, pos[1] + vel[1] * dt, pos[2] + nvz * dt), (vel[0], vel[1], nvz)


def distance(a: Vec3, b: Vec3) -> float:
    return math.dist(a, b)


def horizontal_distance(a: Vec3, b: Vec3) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def speed(v: Vec3) -> float:
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
