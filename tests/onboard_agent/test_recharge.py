"""Recharge Tree (battery low), planned recharges, Wait and Go Home tasks."""

from __future__ import annotations

from proto.plan import GoHomeTask, RechargeTask, WaitTask
from proto.telemetry import FlightState, OutcomeResult
from tests.onboard_agent.helpers import SCENARIO, Rig, on_a_spot, plan, point

C3 = SCENARIO.site.station("C3").position
H = SCENARIO.site.station("C2").position


def test_planned_recharge_lands_on_its_station_and_waits_for_the_fraction():
    rig = Rig(battery=0.5)
    task = RechargeTask(task_id="r1", station_id="C3", position=C3, until_fraction=0.9)
    rig.agent.offer_plan(plan(task))
    rig.run_until(lambda: rig.leaf() == "Recharge")
    state = rig.autopilot.state
    assert state.landed and on_a_spot(state.position, "C3")
    assert rig.agent.status().state == "recharging"
    rig.tick(50)
    assert rig.mission.head is task
    rig.autopilot.update(battery_fraction=0.9)
    rig.tick(2)
    [outcome] = rig.outcomes()
    assert (outcome.task_id, outcome.result) == ("r1", OutcomeResult.COMPLETED)


def test_wait_task_holds_on_the_pad_until_its_time():
    rig = Rig()
    rig.agent.offer_plan(plan(WaitTask(task_id="w1", until_s=rig.wall() + 5.0)))
    rig.tick(40)
    assert rig.mission.head is not None
    assert rig.autopilot.calls == []  # nothing sent: it stays on the pad
    rig.run_until(lambda: rig.mission.head is None, max_ticks=20)
    assert [o.result for o in rig.outcomes()] == [OutcomeResult.COMPLETED]


def test_go_home_flies_to_the_station_and_lands():
    rig = Rig(position=point(0, 7, 3))
    rig.autopilot.update(flight_state=FlightState.FLYING, armed=True, mode="GUIDED")
    rig.agent.offer_plan(plan(GoHomeTask(task_id="h1", station_id="C2", position=H)))
    rig.run_until(lambda: rig.mission.head is None)
    state = rig.autopilot.state
    assert state.landed and on_a_spot(state.position, "C2")
    assert [o.result for o in rig.outcomes()] == [OutcomeResult.COMPLETED]


def test_a_landing_uav_reports_the_ground_below_it_as_its_target():
    """Others keep out of the column a landing UAV comes down through (chaos
    seed 15): its telemetry's target is the ground right below it."""
    rig = Rig(position=point(0, 7, 3))
    rig.autopilot.update(flight_state=FlightState.FLYING, armed=True, mode="GUIDED")
    rig.autopilot.hold.add("land")  # LAND sent, the vehicle still coming down
    rig.agent.offer_plan(plan(GoHomeTask(task_id="h1", station_id="C2", position=H)))
    rig.run_until(lambda: "land" in rig.autopilot.names())
    here, target = rig.autopilot.state.position, rig.agent.telemetry().target
    assert target is not None and here.z_m > 0
    assert (target.x_m, target.y_m, target.z_m) == (here.x_m, here.y_m, 0.0)
