"""The ground station's tests: a mission manager with every UAV present."""

from __future__ import annotations

import pytest

from tests.ground_station.harness import ALL, Harness


@pytest.fixture
def gs(tmp_path):
    """A harness whose three UAVs are up; the plans that brought them up are cleared."""
    harness = Harness(str(tmp_path / "gs.db"))
    harness.bring_up(*ALL)
    assert sorted(p.uav_id for p in harness.sent) == list(ALL)  # each gets a fresh plan
    harness.sent.clear()
    return harness
