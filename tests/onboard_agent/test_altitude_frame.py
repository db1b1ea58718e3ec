"""One altitude frame on a site whose pads stand at different heights: uav-1
starts on a roof pad 6 m up, C3 is a platform 2.5 m up, the terrain is at
the origin's height. Targets and reports are site heights (above the site
origin), whatever the autopilot's home; the simulator's state is the truth."""

from __future__ import annotations

import asyncio
import time

import msgspec
import pytest

from onboard_agent.autopilot.link import MavlinkLink
from proto.geo import Point, SiteFrame
from proto.plan import GoHomeTask, InspectTask, Waypoint
from proto.telemetry import OutcomeResult
from tests.onboard_agent.conftest import (
    LINK_CONFIG,
    fast_scenario,
    fly,
    sped_up_agent,
    start_fleet,
    until,
)
from tests.onboard_agent.helpers import plan

ROOF_Z, PLATFORM_Z = 6.0, 2.5
HEIGHTS = {"C1": ROOF_Z, "C3": PLATFORM_Z}
TARGET = Point(x_m=0.0, y_m=7.0, z_m=4.0)  # below the roof pad, above the terrain


def uneven_scenario():
    """The fast paper scenario with uav-1 alone, one pad per station, C1
    and C3 raised."""
    scenario = fast_scenario()
    stations = [
        msgspec.structs.replace(
            s, pads=1, position=msgspec.structs.replace(s.position, z_m=HEIGHTS.get(s.id, 0.0))
        )
        for s in scenario.site.stations
    ]
    site = msgspec.structs.replace(scenario.site, stations=stations)
    fleet = msgspec.structs.replace(scenario.fleet, uavs=scenario.fleet.uavs[:1])
    return msgspec.structs.replace(scenario, site=site, fleet=fleet)


SCENARIO = uneven_scenario()
C3 = SCENARIO.site.station("C3").position


@pytest.fixture
def uneven():
    runner = start_fleet(SCENARIO)
    try:
        yield runner
    finally:
        runner.stop()


def truth(fleet) -> tuple[tuple[float, float, float], str, bool]:
    """uav-1's (position, flight state, armed) in the simulator."""
    v = fleet.fleet.world.vehicle("uav-1")
    return fleet.call(lambda: (v.position, str(v.state), v.armed))


def at(fleet, point: Point, within_m: float = 0.2) -> bool:
    (x, y, z), _, _ = truth(fleet)
    return Point(x_m=x, y_m=y, z_m=z).distance_to(point) < within_m


def agrees(link, fleet) -> bool:
    """The link's position is the simulator's, height included."""
    (x, y, z), _, _ = truth(fleet)
    return link.state.position.distance_to(Point(x_m=x, y_m=y, z_m=z)) < 0.05


def test_link_flies_from_a_roof_pad_to_site_heights_and_lands_on_a_platform(uneven):
    above_c3 = Point(x_m=C3.x_m, y_m=C3.y_m, z_m=PLATFORM_Z + 3.0)

    async def scenario(link):
        assert truth(uneven)[0][2] == ROOF_Z and agrees(link, uneven)
        await link.set_mode("GUIDED")
        await link.arm()
        await until(lambda: link.state.home is not None, what="home")
        assert SiteFrame(SCENARIO.site.origin).to_local(link.state.home).z_m == pytest.approx(6.0)
        await link.takeoff(ROOF_Z + 3.0)
        await until(lambda: truth(uneven)[1] == "flying", what="takeoff")
        assert truth(uneven)[0][2] == pytest.approx(ROOF_Z + 3.0, abs=0.05)
        for point in (TARGET, above_c3):
            await link.goto(point)
            await until(lambda p=point: at(uneven, p), 30.0, f"truth at {point}")
            await until(lambda: agrees(link, uneven), what="the link agreeing")
        await link.land()
        await until(lambda: truth(uneven)[1:] == ("landed", False), 30.0, "landing")
        assert truth(uneven)[0][2] == PLATFORM_Z
        await until(lambda: link.state.landed and agrees(link, uneven), what="reported landed")

    fly(uneven, "uav-1", scenario, site=SCENARIO.site)
    assert uneven.call(lambda: list(uneven.fleet.world.violations)) == []


def test_agent_takes_off_from_the_roof_inspects_at_site_height_and_lands_on_the_platform(uneven):
    """The behaviour tree over the real link: it climbs off the roof before
    flying, reaches the waypoint's site height, lands on C3's deck, and what
    it reports stays the simulator's position all along."""
    inspect = InspectTask(
        task_id="i1", action_id="a1", waypoints=[Waypoint(index=0, position=TARGET, service_s=1.0)]
    )
    home = GoHomeTask(task_id="h1", station_id="C3", position=C3)
    seen = asyncio.run(run_agent(uneven, plan(inspect, home)))
    assert seen["results"] == {"i1": OutcomeResult.COMPLETED, "h1": OutcomeResult.COMPLETED}
    assert seen["left_roof_at_z"] >= ROOF_Z + 2.0  # climbed before flying off
    assert seen["closest_to_target_m"] < LINK_CONFIG.near_waypoint_m
    assert seen["worst_disagreement_m"] < 0.5  # sampled while moving: telemetry lags a little
    position, state, armed = truth(uneven)
    assert (state, armed, position[2]) == ("landed", False, PLATFORM_Z)
    assert seen["final_z"] == pytest.approx(PLATFORM_Z, abs=0.05)
    assert uneven.call(lambda: list(uneven.fleet.world.violations)) == []


async def run_agent(fleet, the_plan, timeout_s: float = 60.0) -> dict:
    """Tick an agent on a link to uav-1 until every task of ``the_plan`` has
    an outcome, sampling the truth against what the agent believes."""
    url = f"udpout:127.0.0.1:{fleet.fleet.ports['uav-1']}"
    link = MavlinkLink(url, SiteFrame(SCENARIO.site.origin), LINK_CONFIG)
    agent = sped_up_agent(link, LINK_CONFIG, SCENARIO)
    agent.ground_station("gs", True)
    link.start()
    heartbeat = asyncio.create_task(link.run())
    seen = {"results": {}, "closest_to_target_m": 1e9, "worst_disagreement_m": 0.0}
    try:
        await until(lambda: link.state.known and link.state.ready, what="a ready autopilot")
        agent.offer_plan(the_plan)
        deadline = time.monotonic() + timeout_s
        while len(seen["results"]) < len(the_plan.tasks) and time.monotonic() < deadline:
            agent.tick()
            sample(seen, fleet, link)
            seen["results"] |= {o.task_id: o.result for o in agent.mission.take_outcomes()}
            await asyncio.sleep(0.05)
        seen["final_z"] = link.state.position.z_m
    finally:
        heartbeat.cancel()
        link.close()
    return seen


def sample(seen: dict, fleet, link) -> None:
    (x, y, z), state, _ = truth(fleet)
    here = Point(x_m=x, y_m=y, z_m=z)
    seen["closest_to_target_m"] = min(seen["closest_to_target_m"], here.distance_to(TARGET))
    seen["worst_disagreement_m"] = max(
        seen["worst_disagreement_m"], link.state.position.distance_to(here)
    )
    if state == "flying" and "left_roof_at_z" not in seen:
        seen["left_roof_at_z"] = z
