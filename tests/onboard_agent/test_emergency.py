"""The emergency protocol: ground station lost, energy too low."""

from __future__ import annotations

from onboard_agent import AgentConfig
from proto.spots import spot_positions
from proto.telemetry import FlightState, OutcomeResult
from tests.onboard_agent.helpers import SCENARIO, Rig, inspect_task, plan, point

C3 = SCENARIO.site.station("C3").position


def airborne_inspection(rig: Rig) -> None:
    rig.agent.offer_plan(plan(inspect_task(n=3, service_s=30.0)))
    rig.run_until(lambda: rig.leaf() == "Inspection")


def test_link_lost_longer_than_the_timeout_empties_the_queue_and_lands():
    rig = Rig(config=AgentConfig(agent_link_timeout_s=3.0))
    airborne_inspection(rig)
    rig.agent.ground_station("gs", False)
    rig.tick(29)  # 2.9 s: not yet
    assert rig.mission.head is not None
    rig.tick(2)
    assert rig.mission.head is None
    status = rig.agent.status()
    assert (status.state, status.reason) == ("emergency", "ground station unreachable")
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.FAILED
    assert outcome.reason == "emergency: ground station unreachable"
    rig.run_until(lambda: rig.autopilot.state.landed)
    position = rig.autopilot.state.position
    nearest = rig.agent.ctx.surroundings.nearest_station(position)
    spots = spot_positions(nearest, SCENARIO.fleet)
    assert any((position.x_m, position.y_m) == (p.x_m, p.y_m) for p in spots)


def test_a_brief_drop_out_changes_nothing():
    rig = Rig(config=AgentConfig(agent_link_timeout_s=3.0))
    airborne_inspection(rig)
    rig.agent.ground_station("gs", False)
    rig.tick(25)
    rig.agent.ground_station("gs", True)
    rig.tick(25)
    assert rig.mission.head is not None and rig.outcomes() == []
    assert rig.agent.status().state == "busy"


def test_the_link_coming_back_ends_the_emergency_and_a_new_plan_flies():
    rig = Rig(config=AgentConfig(agent_link_timeout_s=1.0))
    airborne_inspection(rig)
    rig.agent.ground_station("gs", False)
    rig.tick(15)
    assert rig.agent.status().state == "emergency"
    rig.agent.offer_plan(plan(inspect_task("late"), epoch=2))  # arrives while cut off
    rig.tick()
    assert rig.mission.head is None  # abandoned too
    rig.agent.ground_station("gs", True)
    rig.tick()
    assert rig.agent.status().state != "emergency"
    rig.agent.offer_plan(plan(inspect_task("again", n=1, service_s=0.5), epoch=3))
    rig.run_until(lambda: rig.mission.head is None)
    assert rig.outcomes()[-1].result is OutcomeResult.COMPLETED


def test_no_ground_station_ever_seen_is_not_an_emergency():
    rig = Rig()
    rig.agent.emergency = type(rig.agent.emergency)(rig.agent.ctx)
    rig.tick(100)
    assert rig.agent.status().state == "idle"


def test_energy_below_what_reaching_a_station_needs_abandons_the_queue():
    rig = Rig(battery=0.21)  # reserve is 0.20 of 20 Wh
    rig.autopilot.update(
        position=point(25, 25, 3), flight_state=FlightState.FLYING, armed=True, mode="GUIDED"
    )
    rig.agent.offer_plan(plan(inspect_task()))
    rig.tick()
    status = rig.agent.status()
    assert (status.state, status.reason) == ("emergency", "energy too low to go on")
    assert [o.reason for o in rig.outcomes()] == ["emergency: energy too low to go on"]
    rig.run_until(lambda: rig.autopilot.state.landed)
    rig.tick()
    assert rig.agent.status().state == "idle"  # landed: over, waiting for a plan


def test_silent_autopilot_reports_the_uav_failed():
    rig = Rig()
    rig.tick()  # heard once
    rig.agent.status()
    rig.autopilot.update(link_ok=False)
    rig.tick()
    status = rig.agent.status()
    assert (status.state, status.reason) == ("failed", "no autopilot heartbeat")


def test_an_autopilot_not_heard_yet_is_not_ready_not_failed():
    rig = Rig()
    rig.autopilot.update(link_ok=False)
    rig.tick()
    status = rig.agent.status()
    assert status.state == "not_ready" and "heartbeat" in status.reason


def test_a_refusal_after_the_first_ready_is_passing_not_a_not_ready_state():
    rig = Rig()
    rig.tick()
    assert rig.agent.status().ready  # ready once
    rig.autopilot.update(prearm_ok=False)  # e.g. a low battery on the pad
    rig.tick()
    status = rig.agent.status()
    assert status.state == "idle" and not status.ready and "pre-arm" in status.reason
