"""GsConfig: settings that follow the mission clock's speed-up."""

from __future__ import annotations

import pytest

from ground_station.config import GsConfig


@pytest.mark.parametrize(("speedup", "period"), [(1.0, 0.5), (5.0, 0.1), (10.0, 0.05), (100, 0.05)])
def test_traffic_reports_keep_their_rate_in_mission_time_up_to_20_hz(speedup, period):
    """Agents keep clear of where the report says others are: at x10 a
    report every 0.5 wall s would be 5 mission s (10 m of flight) old."""
    assert GsConfig().traffic_period(speedup) == pytest.approx(period)
