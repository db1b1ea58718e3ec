"""Geometry: local ENU metres around a geodetic site origin, and WGS84.

The conversion uses :mod:`pymap3d` (ENU <-> geodetic on the WGS84
ellipsoid): exact at kilometre scale, which a flat-earth shortcut is not for
a power-line corridor several kilometres long.
"""

from __future__ import annotations

import math

import pymap3d

from proto.base import Finite, Record


class Point(Record, frozen=True, kw_only=True):
    """A point in the site's local frame: x east, y north, z up, metres."""

    x_m: Finite
    y_m: Finite
    z_m: Finite = 0.0

    def distance_to(self, other: Point) -> float:
        """Euclidean distance in metres."""
        return math.dist((self.x_m, self.y_m, self.z_m), (other.x_m, other.y_m, other.z_m))


class Vector(Record, frozen=True, kw_only=True):
    """A velocity in the local frame, metres per second (east, north, up)."""

    east_mps: Finite = 0.0
    north_mps: Finite = 0.0
    up_mps: Finite = 0.0


class GeoPoint(Record, frozen=True, kw_only=True):
    """A WGS84 position in degrees, and an altitude in metres: above mean sea
    level (AMSL, MAVLink's datum) in a site origin and wherever
    :class:`SiteFrame` made it; above the ellipsoid from :class:`LocalFrame`."""

    lat_deg: Finite = 0.0
    lon_deg: Finite = 0.0
    alt_m: Finite = 0.0


class LocalFrame:
    """Converts between the site's local ENU frame and WGS84 around ``origin``."""

    def __init__(self, origin: GeoPoint) -> None:
        self.origin = origin

    def to_geodetic(self, point: Point) -> GeoPoint:
        """Local ENU metres -> WGS84 (degrees, metres)."""
        o = self.origin
        lat, lon, alt = pymap3d.enu2geodetic(
            point.x_m, point.y_m, point.z_m, o.lat_deg, o.lon_deg, o.alt_m
        )
        return GeoPoint(lat_deg=float(lat), lon_deg=float(lon), alt_m=float(alt))

    def to_local(self, geo: GeoPoint) -> Point:
        """WGS84 (degrees, metres) -> local ENU metres."""
        o = self.origin
        x, y, z = pymap3d.geodetic2enu(
            geo.lat_deg, geo.lon_deg, geo.alt_m, o.lat_deg, o.lon_deg, o.alt_m
        )
        return Point(x_m=float(x), y_m=float(y), z_m=float(z))


class SiteFrame:
    """Site-local points <-> WGS84 positions with AMSL altitudes: the one
    altitude frame of the agent, the simulator and MAVLink.

    x and y are metres east and north of the site origin (ENU on WGS84, by
    :class:`LocalFrame`); z is the height above the origin's
    altitude: ``z = alt - origin.alt_m``. MAVLink's absolute altitudes
    (GLOBAL_POSITION_INT.alt, HOME_POSITION, the GLOBAL(_INT) frames) are AMSL,
    so z is the height the site's pads, towers and workers are given in,
    wherever the autopilot last armed (relative altitudes are above that spot).

    The origin's ``alt_m`` must be in the autopilot's datum (AMSL): a site
    surveyed in ellipsoidal heights converts first. z is not ENU "up", whose
    plane rises above level ground away from the origin (2 m at 5 km).
    """

    def __init__(self, origin: GeoPoint) -> None:
        self.origin = origin
        self._enu = LocalFrame(origin)

    def to_geodetic(self, point: Point) -> GeoPoint:
        """Site-local metres -> degrees and AMSL metres."""
        level = self._enu.to_geodetic(Point(x_m=point.x_m, y_m=point.y_m))
        alt = self.origin.alt_m + point.z_m
        return GeoPoint(lat_deg=level.lat_deg, lon_deg=level.lon_deg, alt_m=alt)

    def to_local(self, geo: GeoPoint) -> Point:
        """Degrees and AMSL metres -> site-local metres."""
        level = GeoPoint(lat_deg=geo.lat_deg, lon_deg=geo.lon_deg, alt_m=self.origin.alt_m)
        p = self._enu.to_local(level)
        return Point(x_m=p.x_m, y_m=p.y_m, z_m=geo.alt_m - self.origin.alt_m)
