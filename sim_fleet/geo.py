"""The simulator's view of the site frame: tuples in, tuples out, with the
conversion itself done by :class:`proto.geo.SiteFrame` (the one altitude
frame every process uses). ``vec`` and ``point`` are the one place proto
points become the physics' tuples and back."""

from __future__ import annotations

from proto.geo import GeoPoint, Point, SiteFrame
from sim_fleet.physics import Vec3


def vec(p: Point) -> Vec3:
    """A proto point as site metres ``(x, y, z)``."""
    return (p.x_m, p.y_m, p.z_m)


def point(v: Vec3) -> Point:
    """Site metres as a proto point."""
    return Point(x_m=v[0], y_m=v[1], z_m=v[2])


class GeoFrame:
    """Site metres <-> WGS84 around ``origin``. ``alt`` is the MAVLink AMSL
    altitude: the origin's altitude plus the site z."""

    def __init__(self, origin: GeoPoint) -> None:
        self.origin = origin
        self._frame = SiteFrame(origin)

    def to_geodetic(self, enu: Vec3) -> tuple[float, float, float]:
        """Site metres -> (lat_deg, lon_deg, alt_m)."""
        geo = self._frame.to_geodetic(point(enu))
        return geo.lat_deg, geo.lon_deg, geo.alt_m

    def to_enu(self, lat_deg: float, lon_deg: float, alt_m: float) -> Vec3:
        """(lat_deg, lon_deg, alt_m) -> site metres."""
        p = self._frame.to_local(GeoPoint(lat_deg=lat_deg, lon_deg=lon_deg, alt_m=alt_m))
        return vec(p)
