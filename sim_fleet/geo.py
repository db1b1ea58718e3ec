"""Local ENU metres <-> geodetic lat/lon/alt around the site origin (pymap3d)."""

from __future__ import annotations

import pymap3d

from sim_fleet.scenario import GeoOrigin, Vec3


class GeoFrame:
    """Converts between the site's ENU frame and WGS84 (degrees, metres AMSL-ish).

    ``alt`` is ellipsoidal height in pymap3d; the simulator treats it as the
    MAVLink AMSL altitude, which is consistent as long as both directions go
    through this class.
    """

    def __init__(self, origin: GeoOrigin) -> None:
        self.origin = origin

    def to_geodetic(self, enu: Vec3) -> tuple[float, float, float]:
        """ENU metres -> (lat_deg, lon_deg, alt_m)."""
        o = self.origin
        lat, lon, alt = pymap3d.enu2geodetic(*enu, o.lat_deg, o.lon_deg, o.alt_m)
        return float(lat), float(lon), float(alt)

    def to_enu(self, lat_deg: float, lon_deg: float, alt_m: float) -> Vec3:
        """(lat_deg, lon_deg, alt_m) -> ENU metres."""
        o = self.origin
        e, n, u = pymap3d.geodetic2enu(lat_deg, lon_deg, alt_m, o.lat_deg, o.lon_deg, o.alt_m)
        return float(e), float(n), float(u)
