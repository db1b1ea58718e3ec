"""MAVSDK-Python 4.x (a MAVLink client nobody here wrote) against the simulator,
the way it talks to ArduCopter: health and armable after the GPS/EKF warm-up,
the parameter protocol, arm / takeoff / goto_location / hold / land, the gripper,
a MissionRaw upload flown in AUTO.

Like ArduCopter with ``SRx_`` rates at 0, the simulator streams only what is
asked for, so the client sets the rates it needs (``set_rate_*``), as MAVSDK
users of ArduPilot do. Skipped when ``mavsdk`` is not installed.
"""

from __future__ import annotations

import asyncio
import math
import time

import pytest

from sim_fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.auto_mission import WP_RADIUS_M
from sim_fleet.params import AutopilotParams
from tests.sim_fleet.small_world import small_world

mavsdk = pytest.importorskip("mavsdk")
from mavsdk.asyncio.mavsdk import Mavsdk  # noqa: E402
from mavsdk.asyncio.plugins.action.action import ActionAsync  # noqa: E402
from mavsdk.asyncio.plugins.gripper.gripper import GripperAsync  # noqa: E402
from mavsdk.asyncio.plugins.mission_raw.mission_raw import MissionRawAsync  # noqa: E402
from mavsdk.asyncio.plugins.param.param import ParamAsync  # noqa: E402
from mavsdk.asyncio.plugins.telemetry.telemetry import TelemetryAsync  # noqa: E402
from mavsdk.plugins.action.action import ActionError  # noqa: E402
from mavsdk.plugins.gripper.gripper import GripperError  # noqa: E402
from mavsdk.plugins.mission_raw.mission_raw import MissionItem  # noqa: E402

SPEEDUP = 10.0
WARMUP_S = 30.0  # simulated: 3 s of wall time at x10


@pytest.fixture
def fleet():
    cfg = FleetConfig(
        base_port=0,
        speedup=SPEEDUP,
        rate_hz=50.0,
        params=AutopilotParams(warmup_s=WARMUP_S, auto_disarm_s=30.0),
    )
    runner = FleetThread(Fleet(small_world(2), cfg)).start()
    try:
        yield runner
    finally:
        runner.stop()


async def first(gen, pred=lambda _: True, timeout_s: float = 30.0):
    async def scan():
        async for item in gen:
            if pred(item):
                return item
        raise AssertionError("stream ended")

    return await asyncio.wait_for(scan(), timeout_s)


async def connect(gcs, port: int):
    await gcs.add_any_connection(f"udpout://127.0.0.1:{port}")
    system = await gcs.first_autopilot(timeout_s=10.0)
    assert system is not None
    telemetry = TelemetryAsync(system)
    for set_rate in (
        telemetry.set_rate_position,
        telemetry.set_rate_battery,
        telemetry.set_rate_landed_state,
        telemetry.set_rate_raw_gps,
        telemetry.set_rate_home,
        telemetry.set_rate_health,  # SYS_STATUS (pre-arm bit), EKF_STATUS_REPORT
    ):
        await set_rate(5.0)
    return system, telemetry


def fly(port: int, script) -> dict:
    async def main():
        config = mavsdk.Configuration.create_with_component_type(
            mavsdk.ComponentType.GROUND_STATION
        )
        async with Mavsdk(config) as gcs:
            system, telemetry = await connect(gcs, port)
            return await script(system, telemetry)

    return asyncio.run(asyncio.wait_for(main(), 120.0))


def test_health_says_not_armable_during_the_warm_up_then_armable(fleet):
    port = fleet.fleet.ports["uav1"]

    async def script(system, telemetry):
        action = ActionAsync(system)
        early = await first(telemetry.subscribe_health())
        refused = None
        if not early.is_armable:
            with pytest.raises(ActionError) as refused:
                await action.arm()
        ready = await first(telemetry.subscribe_health(), lambda h: h.is_armable)
        gps = await first(telemetry.subscribe_raw_gps(), lambda g: g.latitude_deg != 0)
        home = await first(telemetry.subscribe_home())
        await action.arm()
        armed = await first(telemetry.subscribe_armed(), bool)
        return {"early": early, "refused": refused, "ready": ready, "gps": gps, "home": home,
                "armed": armed, "sim_s": fleet.call(lambda: fleet.fleet.world.time_s)}  # fmt: skip

    seen = fly(port, script)
    assert seen["sim_s"] >= WARMUP_S
    assert not seen["early"].is_armable  # connected well within the 30 s warm-up
    assert "FAILED" in str(seen["refused"].value)
    assert seen["ready"].is_global_position_ok and seen["ready"].is_home_position_ok
    assert seen["gps"].latitude_deg == pytest.approx(37.41099, abs=1e-4)
    assert seen["home"].latitude_deg == pytest.approx(37.41099, abs=1e-4)
    assert seen["armed"]


def test_params_list_read_and_set_with_effect(fleet):
    port = fleet.fleet.ports["uav1"]
    vehicle = fleet.fleet.world.vehicle("uav1")

    async def script(system, _telemetry):
        param = ParamAsync(system)
        every = await param.get_all_params()
        names = {p.name for p in every.int_params} | {p.name for p in every.float_params}
        grip = await param.get_param_int("GRIP_ENABLE")
        rtl = await param.get_param_int("RTL_ALT")
        await param.set_param_float("WPNAV_SPEED", 250.0)
        speed = await param.get_param_float("WPNAV_SPEED")
        return {"names": names, "grip": grip, "rtl": rtl, "speed": speed}

    seen = fly(port, script)
    assert {"GRIP_ENABLE", "RTL_ALT", "WPNAV_SPEED", "SYSID_THISMAV"} <= seen["names"]
    assert seen["grip"] == 1 and seen["rtl"] == 1500
    assert seen["speed"] == pytest.approx(250.0)
    assert fleet.call(lambda: vehicle.speed_mps) == pytest.approx(2.5)


async def ready(telemetry):
    await first(telemetry.subscribe_health(), lambda h: h.is_armable, timeout_s=30.0)


def test_arm_takeoff_goto_location_hold_and_land(fleet):
    port = fleet.fleet.ports["uav1"]
    world = fleet.fleet.world
    lat, lon, amsl = world.geo.to_geodetic((-10.0, 16.0, 5.0))  # 6 m north of C1, 5 m up

    async def script(system, telemetry):
        action = ActionAsync(system)
        await ready(telemetry)
        await action.set_takeoff_altitude(4.0)
        await action.arm()
        await action.takeoff()
        await first(telemetry.subscribe_position(), lambda p: p.relative_altitude_m > 3.8)
        await action.goto_location(lat, lon, amsl, 0.0)
        await first(
            telemetry.subscribe_position(),
            lambda p: abs(p.latitude_deg - lat) < 2e-6 and abs(p.relative_altitude_m - 5) < 0.2,
        )
        await action.hold()
        mode = fleet.call(lambda: world.vehicle("uav1").mode.name)
        held_at = fleet.call(lambda: world.vehicle("uav1").position)
        await asyncio.sleep(0.5)
        still = fleet.call(lambda: world.vehicle("uav1").position)
        await action.land()
        await first(telemetry.subscribe_landed_state(), lambda s: int(s) == 1)  # ON_GROUND
        await first(telemetry.subscribe_armed(), lambda armed: not armed)
        return {"mode": mode, "held_at": held_at, "still": still}

    seen = fly(port, script)
    assert seen["mode"] == "BRAKE"  # MAVSDK's hold on ArduCopter
    assert seen["held_at"] == pytest.approx((-10.0, 16.0, 5.0), abs=0.3)
    assert seen["still"] == pytest.approx(seen["held_at"], abs=0.3)
    vehicle = world.vehicle("uav1")
    assert fleet.call(lambda: vehicle.position) == pytest.approx((-10.0, 16.0, 0.0), abs=0.3)
    assert fleet.call(lambda: world.violations) == [] or all(
        v.kind == "off_pad_landing" for v in fleet.call(lambda: list(world.violations))
    )


def test_gripper_needs_grip_enable_then_grabs_and_delivers(fleet):
    port = fleet.fleet.ports["uav1"]
    world = fleet.fleet.world
    pick = world.geo.to_geodetic((-2.0, 5.0, 4.5))  # above the hammer's station (z 3)
    drop = world.geo.to_geodetic((0.0, 9.0, 5.5))  # above worker W1 (z 3)

    async def script(system, telemetry):
        action, gripper, param = ActionAsync(system), GripperAsync(system), ParamAsync(system)
        await param.set_param_int("GRIP_ENABLE", 0)
        with pytest.raises(GripperError):
            await gripper.grab(1)
        await param.set_param_int("GRIP_ENABLE", 1)
        await ready(telemetry)
        await action.set_takeoff_altitude(4.5)
        await action.arm()
        await action.takeoff()
        await first(telemetry.subscribe_position(), lambda p: p.relative_altitude_m > 4.3)
        for lat, lon, amsl in (pick, drop):
            await action.goto_location(lat, lon, amsl, 0.0)
            await first(
                telemetry.subscribe_position(),
                lambda p, lat=lat, lon=lon: (
                    abs(p.latitude_deg - lat) < 2e-6 and abs(p.longitude_deg - lon) < 2e-6
                ),
            )
            deadline = time.monotonic() + 5.0  # settle to hover speed before the gripper acts
            while time.monotonic() < deadline:
                v = fleet.call(lambda: world.vehicle("uav1").velocity)
                if max(abs(c) for c in v) < 0.1:
                    break
                await asyncio.sleep(0.05)
            if (lat, lon, amsl) == pick:
                await gripper.grab(1)
                held = fleet.call(lambda: world.vehicle("uav1").holding)
            else:
                await gripper.release(1)
        return {"held": held}

    seen = fly(port, script)
    assert seen["held"] is not None and seen["held"].name == "hammer"
    [delivery] = fleet.call(lambda: list(world.deliveries))
    assert (delivery.tool_id, delivery.worker_id) == ("hammer", "W1")


def test_mission_raw_upload_arm_start_flies_the_waypoints_and_lands(fleet):
    port = fleet.fleet.ports["uav1"]
    world = fleet.fleet.world
    auto = fleet.fleet.endpoints["uav1"].auto
    wps = [(-10.0, 16.0, 5.0), (-4.0, 16.0, 6.0)]  # site metres; z above the pad

    def item(seq, command, xyz=None, current=0):
        x = y = 0
        if xyz is not None:
            lat, lon, _ = world.geo.to_geodetic(xyz)
            x, y = round(lat * 1e7), round(lon * 1e7)
        z = xyz[2] if xyz is not None else 0.0
        return MissionItem(seq, 6, command, current, 1, 0.0, 0.0, 0.0, 0.0, x, y, z, 0)

    items = [
        item(0, 16, current=1),  # home's place, as ArduPilot missions start
        MissionItem(1, 6, 22, 0, 1, 0.0, 0.0, 0.0, 0.0, 0, 0, 4.0, 0),  # takeoff to 4 m
        item(2, 16, wps[0]),
        item(3, 16, wps[1]),
        item(4, 21),  # land where it is
    ]

    async def script(system, telemetry):
        mission, action = MissionRawAsync(system), ActionAsync(system)
        await ready(telemetry)
        await mission.upload_mission(items)
        downloaded = await mission.download_mission()
        await action.arm()
        await mission.start_mission()
        await first(telemetry.subscribe_in_air(), bool)
        await first(telemetry.subscribe_landed_state(), lambda s: int(s) == 1, 120.0)
        await first(telemetry.subscribe_armed(), lambda armed: not armed)
        return {"downloaded": downloaded}

    seen = fly(port, script)
    assert [i.command for i in seen["downloaded"]] == [16, 22, 16, 16, 21]
    log = {seq: pos for seq, _, pos in fleet.call(lambda: list(auto.log))}
    assert sorted(log) == [1, 2, 3, 4]
    for seq, wp in zip((2, 3), wps, strict=True):
        assert math.dist(log[seq], wp) <= WP_RADIUS_M
    vehicle = world.vehicle("uav1")
    landed = fleet.call(lambda: vehicle.position)
    assert landed[2] == pytest.approx(0.0, abs=1e-3)
    assert math.dist(landed, (wps[1][0], wps[1][1], 0.0)) <= WP_RADIUS_M + 0.5
    assert fleet.call(lambda: (vehicle.mode.name, vehicle.armed)) == ("AUTO", False)
