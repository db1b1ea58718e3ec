"""Fixtures shared by the simulator's MAVLink tests: a running two-vehicle
fleet (no warm-up, x20) and a pymavlink client connected to uav1."""

from __future__ import annotations

import pytest

from sim_fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.params import AutopilotParams
from tests.sim_fleet.mavclient import SPEEDUP, Client
from tests.sim_fleet.small_world import small_world


@pytest.fixture
def fleet():
    cfg = FleetConfig(
        speedup=SPEEDUP,
        rate_hz=50.0,
        base_port=0,
        params=AutopilotParams(auto_disarm_s=30.0, warmup_s=0.0),
    )
    runner = FleetThread(Fleet(small_world(2), cfg)).start()
    try:
        yield runner
    finally:
        runner.stop()


@pytest.fixture
def client(fleet):
    port = fleet.fleet.ports["uav1"]
    c = Client(port, target_system=1)
    try:
        yield c
    finally:
        c.close()
