"""An external MAVLink client nobody here wrote (MAVSDK-Python 4.x) flies a simulated copter.

Skipped when ``mavsdk`` is not installed (it is an optional test dependency).
"""

from __future__ import annotations

import asyncio

import pytest

from sim_fleet import Fleet, FleetConfig, FleetThread
from tests.sim_fleet.small_world import small_world

mavsdk = pytest.importorskip("mavsdk")
from mavsdk.asyncio.mavsdk import Mavsdk  # noqa: E402
from mavsdk.asyncio.plugins.action.action import ActionAsync  # noqa: E402
from mavsdk.asyncio.plugins.telemetry.telemetry import TelemetryAsync  # noqa: E402


async def first(gen, pred=lambda _: True):
    async for item in gen:
        if pred(item):
            return item
    raise AssertionError("stream ended")


async def fly(port: int) -> dict:
    seen: dict = {}
    config = mavsdk.Configuration.create_with_component_type(mavsdk.ComponentType.GROUND_STATION)
    async with Mavsdk(config) as gcs:
        await gcs.add_any_connection(f"udpout://127.0.0.1:{port}")
        system = await gcs.first_autopilot(timeout_s=10.0)
        assert system is not None
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        await telemetry.set_rate_position(5.0)  # streams only what is asked for, as ArduCopter
        await telemetry.set_rate_battery(1.0)
        await telemetry.set_rate_health(1.0)  # SYS_STATUS, EKF_STATUS_REPORT
        await first(telemetry.subscribe_health(), lambda h: h.is_armable)  # warmed up
        seen["position"] = await first(telemetry.subscribe_position())
        seen["battery"] = await first(telemetry.subscribe_battery())
        await action.arm()
        await action.takeoff()
        seen["up"] = await first(
            telemetry.subscribe_position(), lambda p: p.relative_altitude_m > 1.5
        )
        await action.land()
        seen["landed"] = await first(
            telemetry.subscribe_landed_state(),
            lambda s: int(s) == 1,  # LandedState.ON_GROUND
        )
        seen["disarmed"] = await first(telemetry.subscribe_armed(), lambda armed: not armed)
    return seen


def test_mavsdk_discovers_reads_arms_takes_off_and_lands():
    cfg = FleetConfig(base_port=0, speedup=10.0, rate_hz=50.0)
    runner = FleetThread(Fleet(small_world(1), cfg)).start()
    try:
        seen = asyncio.run(asyncio.wait_for(fly(runner.fleet.ports["uav1"]), 60.0))
    finally:
        runner.stop()
    assert seen["position"].latitude_deg == pytest.approx(37.4109, abs=1e-3)
    assert seen["battery"].remaining_percent == pytest.approx(100.0)
    assert seen["up"].relative_altitude_m > 1.5
    assert runner.fleet.world.vehicle("uav1").position[2] == 0.0
