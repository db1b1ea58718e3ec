"""MAVLink coordinate frames -> site ENU, for position and velocity targets.

Local NED frames are relative to the vehicle's EKF origin, which (as in SITL)
is where it was powered on: its home pad. GLOBAL(_INT) altitudes are AMSL;
relative altitudes are above home (the endpoint adds home's height). There
is no terrain database, so terrain altitudes are taken as relative too.
"""

from __future__ import annotations

import math

from sim_fleet.geo import GeoFrame
from sim_fleet.physics import Vec3

# MAV_FRAME
GLOBAL = 0
LOCAL_NED = 1
GLOBAL_RELATIVE_ALT = 3
GLOBAL_INT = 5
GLOBAL_RELATIVE_ALT_INT = 6
LOCAL_OFFSET_NED = 7
BODY_NED = 8
BODY_OFFSET_NED = 9
GLOBAL_TERRAIN_ALT = 10
GLOBAL_TERRAIN_ALT_INT = 11

_AMSL = frozenset({GLOBAL, GLOBAL_INT})
_RELATIVE = frozenset(
    {GLOBAL_RELATIVE_ALT, GLOBAL_RELATIVE_ALT_INT, GLOBAL_TERRAIN_ALT, GLOBAL_TERRAIN_ALT_INT}
)
LOCAL_FRAMES = frozenset({LOCAL_NED, LOCAL_OFFSET_NED, BODY_NED, BODY_OFFSET_NED})


def global_to_enu(
    geo: GeoFrame, frame: int, lat_deg: float, lon_deg: float, alt_m: float
) -> Vec3 | None:
    """A global-frame point in ENU, or None for a frame we do not take."""
    if not (math.isfinite(lat_deg) and math.isfinite(lon_deg) and math.isfinite(alt_m)):
        return None
    if abs(lat_deg) > 90.0 or abs(lon_deg) > 180.0:
        return None
    if frame in _AMSL:
        return geo.to_enu(lat_deg, lon_deg, alt_m)
    if frame in _RELATIVE:
        e, n, _ = geo.to_enu(lat_deg, lon_deg, geo.origin.alt_m)
        return e, n, alt_m
    return None


def ned_to_enu(v: Vec3) -> Vec3:
    return v[1], v[0], -v[2]


def _body_to_earth(x: float, y: float, heading_deg: float) -> tuple[float, float]:
    """Body (forward, right) -> (north, east)."""
    h = math.radians(heading_deg)
    return x * math.cos(h) - y * math.sin(h), x * math.sin(h) + y * math.cos(h)


def local_to_enu(frame: int, ned: Vec3, home: Vec3, here: Vec3, heading_deg: float) -> Vec3 | None:
    """A SET_POSITION_TARGET_LOCAL_NED position in ENU (as ArduCopter reads it)."""
    if frame not in LOCAL_FRAMES or not all(math.isfinite(c) for c in ned):
        return None
    n, e, d = ned
    if frame in (BODY_NED, BODY_OFFSET_NED):
        n, e = _body_to_earth(n, e, heading_deg)
    base = home if frame == LOCAL_NED else here
    return base[0] + e, base[1] + n, base[2] - d


def local_velocity_to_enu(frame: int, ned: Vec3, heading_deg: float) -> Vec3 | None:
    if frame not in LOCAL_FRAMES or not all(math.isfinite(c) and abs(c) < 1000 for c in ned):
        return None
    n, e, d = ned
    if frame in (BODY_NED, BODY_OFFSET_NED):
        n, e = _body_to_earth(n, e, heading_deg)
    return e, n, -d
