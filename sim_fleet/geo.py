"""The simulator's view of the site frame: tuples in, tuples out, with the
conversion itself done by :class:`linecrew.site_frame.SiteFrame` (the one
altitude frame every process uses)."""

from __future__ import annotations

from proto.geo import GeoPoint, Point, SiteFrame
from sim_fleet.scenario import GeoOrigin, Vec3


class GeoFrame:
    """Site metres <-> WGS84 around ``origin``. ``alt`` is the MAVLink AMSL
    altitude: the origin's altitude plus the site z."""

    def __init__(self, origin: GeoOrigin) -> None:
        self.origin = origin
        self._frame = SiteFrame(
            GeoPoint(lat_deg=origin.lat_deg, lon_deg=origin.lon_deg, alt_m=origin.alt_m)
        )

    def to_geodetic(self, enu: Vec3) -> tuple[float, float, float]:
        """Site metres -> (lat_deg, lon_deg, alt_m)."""
        geo = self._frame.to_geodetic(Point(x_m=enu[0], y_m=enu[1], z_m=enu[2]))
        return geo.lat_deg, geo.lon_deg, geo.alt_m

    def to_enu(self, lat_deg: float, lon_deg: float, alt_m: float) -> Vec3:
        """(lat_deg, lon_deg, alt_m) -> site metres."""
        p = self._frame.to_local(GeoPoint(lat_deg=lat_deg, lon_deg=lon_deg, alt_m=alt_m))
        return p.x_m, p.y_m, p.z_m
