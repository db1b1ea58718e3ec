"""The one altitude frame: z is the height above the origin's altitude."""

from __future__ import annotations

import pytest

from proto.geo import GeoPoint, LocalFrame, Point, SiteFrame

ORIGIN = GeoPoint(lat_deg=37.4125, lon_deg=-6.0036, alt_m=10.0)


def test_z_is_the_amsl_altitude_less_the_origins_and_points_round_trip():
    frame = SiteFrame(ORIGIN)
    roof = Point(x_m=-10.0, y_m=10.0, z_m=6.0)
    geo = frame.to_geodetic(roof)
    assert geo.alt_m == pytest.approx(16.0)
    back = frame.to_local(geo)
    assert back.distance_to(roof) < 1e-6


def test_level_ground_far_away_stays_at_z_zero_unlike_enu_up():
    far = GeoPoint(lat_deg=ORIGIN.lat_deg, lon_deg=ORIGIN.lon_deg + 0.06, alt_m=ORIGIN.alt_m)
    site, enu = SiteFrame(ORIGIN).to_local(far), LocalFrame(ORIGIN).to_local(far)
    assert site.z_m == 0.0 and enu.z_m < -0.2  # 5 km east: the ENU plane is above the ground
    assert site.x_m == pytest.approx(enu.x_m, abs=0.01)
