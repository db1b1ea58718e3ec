"""The MAVLink link against a sim_fleet vehicle over real UDP."""

from __future__ import annotations

import pytest

from onboard_agent import CommandDenied, CommandTimeout
from proto.spots import spot_positions
from tests.onboard_agent.conftest import fast_scenario, fly, until

SITE = fast_scenario().site


def test_guided_takeoff_goto_land_with_positions_in_the_site_frame(fleet):
    async def scenario(link):
        c1 = spot_positions(SITE.station("C1"), fast_scenario().fleet)[0]  # uav-1 sits on spot 0
        assert link.state.position.distance_to(c1) < 0.1
        assert link.state.landed and link.state.battery_fraction == 1.0
        await link.set_mode("GUIDED")
        await link.arm()
        await link.takeoff(4.0)
        await until(lambda: link.state.position.z_m > 3.9, what="climb")
        assert link.state.armed and link.state.mode == "GUIDED"
        target = c1.__class__(x_m=-5.0, y_m=10.0, z_m=4.0)
        await link.goto(target)
        await until(lambda: link.state.position.distance_to(target) < 0.2, what="arrival")
        await link.land()
        await until(lambda: link.state.landed and not link.state.armed, what="landing")

    fly(fleet, "uav-1", scenario)


def test_refused_command_carries_the_autopilot_reason(fleet):
    async def scenario(link):
        with pytest.raises(CommandDenied) as denied:
            await link.grab()
        assert denied.value.result == "UNSUPPORTED"
        assert "Gripper: not fitted" in str(denied.value)
        with pytest.raises(CommandDenied, match="takeoff FAILED"):
            await link.takeoff(5.0)  # disarmed

    fly(fleet, "uav-2", scenario)


def test_silent_autopilot_times_out_and_is_reported(fleet):
    vehicle = fleet.fleet.world.vehicle("uav-1")

    async def scenario(link):
        fleet.call(lambda: vehicle.drop_link(1e6))
        with pytest.raises(CommandTimeout):
            await link.arm()
        await until(lambda: not link.state.link_ok, 5.0, "heartbeat loss")
        fleet.call(lambda: setattr(vehicle, "link_down_until", 0.0))  # link back
        await until(lambda: link.state.link_ok, 5.0, "heartbeat back")

    fly(fleet, "uav-1", scenario)
