from __future__ import annotations

import pytest

from proto.geo import GeoPoint
from sim_fleet import frames, streams
from sim_fleet.geo import GeoFrame


def test_only_the_heartbeat_streams_until_asked_like_arducopter_with_sr_rates_at_0():
    s = streams.StreamSchedule(streams.TelemetryRates())
    assert s.due(0.0) == [streams.HEARTBEAT]
    assert s.interval_us(streams.GLOBAL_POSITION_INT) == -1
    assert s.set_interval(streams.GLOBAL_POSITION_INT, 0)  # "default rate": 5 Hz
    assert s.interval_us(streams.GLOBAL_POSITION_INT) == 200_000


def test_request_data_stream_switches_arducopter_stream_groups():
    s = streams.StreamSchedule(streams.TelemetryRates())
    assert s.request_data_stream(2, 2.0, True)  # EXTENDED_STATUS
    assert {streams.SYS_STATUS, streams.GPS_RAW_INT} <= set(s.due(0.0))
    assert s.interval_us(streams.GPS_RAW_INT) == 500_000
    assert s.request_data_stream(0, 4.0, True)  # ALL
    assert s.interval_us(streams.EKF_STATUS_REPORT) == 250_000
    assert s.request_data_stream(12, 4.0, False)  # EXTRA3 off
    assert s.interval_us(streams.EKF_STATUS_REPORT) == -1
    assert s.interval_us(streams.GLOBAL_POSITION_INT) == 250_000
    assert not s.request_data_stream(99, 1.0, True)


def test_default_rates_and_message_interval_changes():
    s = streams.StreamSchedule(streams.TelemetryRates(stream_by_default=True))
    assert s.interval_us(streams.HEARTBEAT) == 1_000_000
    sent = [streams.GLOBAL_POSITION_INT in s.due(t / 10) for t in range(0, 11)]
    assert sum(sent) == 6  # 5 Hz over 1 s, both ends included
    assert s.set_interval(streams.GLOBAL_POSITION_INT, -1)
    assert s.interval_us(streams.GLOBAL_POSITION_INT) == -1
    assert s.set_interval(streams.GLOBAL_POSITION_INT, 0)  # back to default
    assert s.interval_us(streams.GLOBAL_POSITION_INT) == 200_000
    assert s.set_interval(streams.HOME_POSITION, 500_000)
    assert not s.set_interval(9999, 1000)


def test_coarse_ticks_send_once_per_tick_without_bursts():
    s = streams.StreamSchedule(streams.TelemetryRates(position_hz=50.0, stream_by_default=True))
    counts = [s.due(t * 1.0).count(streams.GLOBAL_POSITION_INT) for t in range(5)]
    assert counts == [1, 1, 1, 1, 1]


GEO = GeoFrame(GeoPoint(lat_deg=37.41, lon_deg=-6.0, alt_m=10.0))


def test_global_frames_round_trip():
    lat, lon, alt = GEO.to_geodetic((100.0, -50.0, 20.0))
    amsl = frames.global_to_enu(GEO, frames.GLOBAL_INT, lat, lon, alt)
    assert amsl == pytest.approx((100.0, -50.0, 20.0), abs=1e-3)
    rel = frames.global_to_enu(GEO, frames.GLOBAL_RELATIVE_ALT_INT, lat, lon, 20.0)
    assert rel == pytest.approx((100.0, -50.0, 20.0), abs=1e-2)
    assert frames.global_to_enu(GEO, frames.LOCAL_NED, lat, lon, 1.0) is None
    assert frames.global_to_enu(GEO, frames.GLOBAL_INT, 91.0, 0.0, 1.0) is None


def test_local_frames():
    home, here = (10.0, 20.0, 0.0), (15.0, 25.0, 5.0)
    assert frames.local_to_enu(frames.LOCAL_NED, (1.0, 2.0, -3.0), home, here, 0.0) == (
        12.0,
        21.0,
        3.0,
    )
    assert frames.local_to_enu(frames.LOCAL_OFFSET_NED, (1.0, 0.0, 0.0), home, here, 0.0) == (
        15.0,
        26.0,
        5.0,
    )
    # body frame, heading east: forward is +east
    body = frames.local_to_enu(frames.BODY_OFFSET_NED, (2.0, 0.0, 0.0), home, here, 90.0)
    assert body == pytest.approx((17.0, 25.0, 5.0))
    assert frames.local_to_enu(12, (0.0, 0.0, 0.0), home, here, 0.0) is None
    assert frames.local_velocity_to_enu(frames.LOCAL_NED, (1.0, 2.0, 3.0), 0.0) == (2.0, 1.0, -3.0)
