"""Local ENU metres <-> WGS84 around the site origin."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from proto.geo import GeoPoint, LocalFrame, Point

ORIGIN = GeoPoint(lat_deg=37.4125, lon_deg=-6.0036, alt_m=12.0)
metres = st.floats(-20_000, 20_000, allow_nan=False)


@given(x=metres, y=metres, z=st.floats(-50, 500, allow_nan=False))
def test_local_to_geodetic_and_back_is_exact_to_a_millimetre(x, y, z):
    frame = LocalFrame(ORIGIN)
    back = frame.to_local(frame.to_geodetic(Point(x_m=x, y_m=y, z_m=z)))
    assert back.distance_to(Point(x_m=x, y_m=y, z_m=z)) < 1e-3


def test_origin_maps_to_itself():
    geo = LocalFrame(ORIGIN).to_geodetic(Point(x_m=0, y_m=0, z_m=0))
    assert geo.lat_deg == pytest.approx(ORIGIN.lat_deg, abs=1e-12)
    assert geo.lon_deg == pytest.approx(ORIGIN.lon_deg, abs=1e-12)
    assert geo.alt_m == pytest.approx(ORIGIN.alt_m, abs=1e-6)


def test_axes_point_east_north_up():
    frame = LocalFrame(ORIGIN)
    north = frame.to_geodetic(Point(x_m=0, y_m=1000, z_m=0))
    east = frame.to_geodetic(Point(x_m=1000, y_m=0, z_m=0))
    # One degree of latitude is about 111 km; of longitude, 111 km * cos(lat).
    assert (north.lat_deg - ORIGIN.lat_deg) * 111_000 == pytest.approx(1000, rel=0.01)
    lon_scale = 111_320 * math.cos(math.radians(ORIGIN.lat_deg))
    assert (east.lon_deg - ORIGIN.lon_deg) * lon_scale == pytest.approx(1000, rel=0.01)
    assert north.lon_deg == pytest.approx(ORIGIN.lon_deg, abs=1e-9)
