"""Readiness against a simulator that warms up like ArduCopter (GPS fix, EKF
origin, home; lat = lon = 0 before), streams only what is asked for and
refuses to arm with its pre-arm texts until then."""

from __future__ import annotations

import asyncio
import dataclasses
import time

import pytest

from onboard_agent import Agent, AgentConfig, CommandDenied
from onboard_agent.autopilot.link import MavlinkLink
from proto.geo import SiteFrame
from proto.spots import spot_positions
from proto.telemetry import AgentState, FlightState
from sim_fleet.params import AutopilotParams
from tests.onboard_agent.conftest import (
    fast_scenario,
    sped_up_agent,
    start_fleet,
    until,
)
from tests.onboard_agent.helpers import Rig, inspect_task, plan

SCENARIO = fast_scenario()
SITE = SCENARIO.site
WARMUP_S = 50.0  # simulated: 5 s of wall time at x10
CONFIG = AgentConfig(command_ack_timeout_s=0.3, command_retries=1, heartbeat_timeout_s=1.0)


@pytest.fixture
def warming():
    """The paper's fleet, warming up for WARMUP_S simulated seconds."""
    runner = start_fleet(SCENARIO, params=AutopilotParams(auto_disarm_s=30.0, warmup_s=WARMUP_S))
    try:
        yield runner
    finally:
        runner.stop()


def url(fleet, uav_id: str = "uav-1") -> str:
    return f"udpout:127.0.0.1:{fleet.fleet.ports[uav_id]}"


def sim_time(fleet) -> float:
    return fleet.call(lambda: fleet.fleet.world.time_s)


def test_link_reports_position_and_battery_unknown_and_not_ready_until_warmed_up(warming):
    c1 = spot_positions(SITE.station("C1"), SCENARIO.fleet)[0]  # uav-1 sits on spot 0

    async def main() -> dict:
        link = MavlinkLink(url(warming), SiteFrame(SITE.origin), CONFIG)
        link.start()
        heartbeat = asyncio.create_task(link.run())
        seen: dict = {}
        try:
            await until(lambda: link.state.link_ok, what="heartbeat")
            seen["battery_at_start"] = (link.state.battery_known, link.state.battery_fraction)
            await until(lambda: link.state.gps_fix_type >= 0, what="GPS_RAW_INT")
            await until(lambda: link.state.battery_known, what="battery")
            seen["early"] = link.state
            seen["early_sim_s"] = sim_time(warming)
            with pytest.raises(CommandDenied) as refused:
                await link.arm()
            seen["refused"] = refused.value
            await until(lambda: link.state.ready, 20.0, "ready")
            seen["ready"] = link.state
            seen["ready_sim_s"] = sim_time(warming)
            await link.set_mode("GUIDED")
            await link.arm()
            await until(lambda: link.state.armed, what="armed")
        finally:
            heartbeat.cancel()
            link.close()
        return seen

    seen = asyncio.run(main())
    assert seen["battery_at_start"] == (False, 0.0)  # unknown, not "0 %"
    early = seen["early"]
    assert seen["early_sim_s"] < WARMUP_S
    assert not early.known  # lat = lon = 0 is no position
    assert early.battery_fraction == 1.0
    assert early.home is None and early.prearm_ok is False
    assert early.not_ready_reason in ("GPS: no 3-D fix", "EKF: no absolute position")
    assert "PreArm: AHRS: waiting for home" in str(seen["refused"])  # ArduCopter's reason
    ready = seen["ready"]
    assert seen["ready_sim_s"] >= WARMUP_S
    assert ready.known and ready.position.distance_to(c1) < 0.1
    assert ready.home is not None and ready.gps_fix_type == 3 and ready.prearm_ok


def test_agent_is_not_ready_not_failed_no_false_emergency_and_flies_once_warmed_up(warming):
    """The by-hand SITL flight: a plan arrives while the autopilot warms up.
    The agent reports not ready (not failed), raises no energy emergency for
    a position it does not have, does not try to arm before it can, and then
    flies the task."""
    config = AgentConfig(
        command_ack_timeout_s=0.3,
        command_retries=1,
        heartbeat_timeout_s=1.0,
    )

    async def main() -> dict:
        link = MavlinkLink(url(warming), SiteFrame(SITE.origin), config)
        agent = sped_up_agent(link, config, SCENARIO)
        agent.ground_station("gs", True)
        link.start()
        heartbeat = asyncio.create_task(link.run())
        seen: dict = {"states": set(), "emergencies": set()}
        try:
            await until(lambda: link.state.link_ok, what="heartbeat")
            agent.offer_plan(plan(inspect_task(n=1, service_s=1.0)))
            deadline = time.monotonic() + 30.0
            while time.monotonic() < deadline:
                agent.tick()
                status = agent.status()
                seen["states"].add(status.state)
                if agent.ctx.emergency:
                    seen["emergencies"].add(agent.ctx.emergency)
                if status.state is AgentState.NOT_READY:
                    seen["not_ready"] = status
                if link.state.flight_state is FlightState.FLYING:
                    seen["flying_sim_s"] = sim_time(warming)
                    break
                await asyncio.sleep(0.05)
            seen["outcomes"] = agent.mission.take_outcomes()
            seen["texts"] = link.reports.texts_since(float("-inf")).split("; ")
        finally:
            heartbeat.cancel()
            link.close()
        return seen

    seen = asyncio.run(main())
    assert seen["emergencies"] == set()  # no "energy too low" from a 0 N 0 E position
    assert AgentState.FAILED not in seen["states"] and AgentState.NOT_READY in seen["states"]
    not_ready = seen["not_ready"]
    assert not not_ready.ready and not_ready.reason.startswith("not ready: ")
    assert not_ready.task_id == "t1" and not_ready.queue_length == 1
    assert seen["outcomes"] == []  # the task was held, not failed
    assert seen["flying_sim_s"] >= WARMUP_S
    assert not any(t.startswith("PreArm:") for t in seen["texts"])  # it never armed too early


def test_with_the_state_off_not_ready_is_reported_as_idle_or_busy_with_ready_false(warming):
    """For a ground station that does not know the not-ready state."""
    config = dataclasses.replace(CONFIG, not_ready_state=False)

    async def main():
        link = MavlinkLink(url(warming), SiteFrame(SITE.origin), config)
        agent = Agent("uav-1", SCENARIO, link, config)
        link.start()
        heartbeat = asyncio.create_task(link.run())
        try:
            await until(lambda: link.state.link_ok and link.state.gps_fix_type >= 0)
            idle = agent.status()
            agent.offer_plan(plan(inspect_task()))
            agent.tick()
            busy = agent.status()
        finally:
            heartbeat.cancel()
            link.close()
        return idle, busy

    idle, busy = asyncio.run(main())
    assert (idle.state, idle.ready) == (AgentState.IDLE, False)
    assert (busy.state, busy.ready) == (AgentState.BUSY, False)
    assert busy.reason.startswith("not ready: ")


def test_a_uav_that_gave_up_arming_is_not_ready_until_its_autopilot_can_arm_again():
    """Motors failed on the pad: the task gives up on arming, and the UAV's work
    must go to others, not come back to it at every replan."""
    rig = Rig()
    rig.tick()
    assert rig.agent.state() == (AgentState.IDLE, "")  # ready once
    rig.autopilot.update(prearm_ok=False, arm_text="PreArm: Motors: check failed")
    rig.agent.offer_plan(plan(inspect_task()))
    assert rig.agent.state()[0] is AgentState.BUSY  # a refusal is passing at first
    rig.run_until(lambda: rig.mission.head is None, max_ticks=2000)  # ready_timeout_s
    [outcome] = rig.outcomes()
    assert outcome.retryable and outcome.reason_code == "not_ready"
    state, why = rig.agent.state()
    assert state is AgentState.NOT_READY and "Motors" in why
    assert not rig.agent.status().ready
    rig.autopilot.update(prearm_ok=True, arm_text="")
    assert rig.agent.state() == (AgentState.IDLE, "")
    rig.autopilot.update(prearm_ok=False)  # a later passing refusal keeps the state
    assert rig.agent.state()[0] is AgentState.IDLE
