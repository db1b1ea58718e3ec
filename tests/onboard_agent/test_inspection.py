"""Inspection Task Tree on a fake autopilot, ticked by hand."""

from __future__ import annotations

from onboard_agent import AgentConfig
from proto.telemetry import OutcomeResult
from tests.onboard_agent.helpers import TICK_S, Rig, inspect_task, plan, point


def test_visits_waypoints_in_order_and_reports_each():
    rig = Rig()
    rig.agent.offer_plan(plan(inspect_task(n=3, service_s=1.0)))
    rig.run_until(lambda: rig.mission.head is None)
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.COMPLETED
    assert outcome.waypoints_done == [0, 1, 2]
    gotos = [arg for name, arg in rig.autopilot.calls if name == "goto"]
    assert [(p.x_m, p.y_m) for p in gotos[:3]] == [(0.0, 7.0), (2.0, 7.0), (4.0, 7.0)]
    assert rig.autopilot.names()[:3] == ["mode", "arm", "takeoff"]


def test_holds_each_waypoint_for_its_service_time():
    rig = Rig()
    rig.agent.offer_plan(plan(inspect_task(n=2, service_s=2.0)))
    rig.run_until(lambda: rig.leaf() == "Inspection")
    rig.tick(15)
    assert rig.mission.waypoints_done("t1") == []
    assert rig.agent.status().state == "busy"
    rig.tick(10)
    assert rig.mission.waypoints_done("t1") == [0]
    assert rig.agent.status().progress == 0.5


def test_flying_back_when_pushed_off_the_waypoint():
    rig = Rig()
    rig.agent.offer_plan(plan(inspect_task(n=1, service_s=5.0)))
    rig.run_until(lambda: rig.leaf() == "Inspection")
    rig.autopilot.update(position=point(10.0, 10.0, 3.0))
    rig.tick(arrive=False)
    assert rig.leaf() == "Go near WP"


def test_resumes_a_split_inspection_where_it_stopped():
    rig = Rig()
    second_half = inspect_task("t2", n=2, first=3)
    rig.agent.offer_plan(plan(second_half))
    rig.run_until(lambda: rig.mission.head is None)
    [outcome] = rig.outcomes()
    assert outcome.waypoints_done == [3, 4]


def test_arm_refusals_are_retried_with_backoff_then_fail_retryable_with_the_reason():
    rig = Rig()
    rig.autopilot.deny["arm"] = "PreArm: Battery 1 below minimum arming capacity"
    rig.agent.offer_plan(plan(inspect_task()))
    rig.tick(25)  # 2.5 s: refused at 0 s and 1 s, the next try not before 3 s
    assert rig.autopilot.names().count("arm") == 2
    assert "capacity; retrying in" in rig.agent.root.tip().feedback_message
    assert rig.outcomes() == []  # the task is not failed on the first refusals
    ticks = rig.run_until(lambda: rig.mission.head is None, max_ticks=600)
    assert (25 + ticks) * TICK_S >= 1 + 2 + 4 + 8 + 16  # the doubling backoff
    assert rig.autopilot.names().count("arm") == AgentConfig().arm_attempts
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.FAILED
    assert outcome.retryable and outcome.reason_code == "arm_refused"
    assert "PreArm: Battery 1 below minimum arming capacity" in outcome.reason
    assert "Go near WP" in outcome.reason


def test_running_while_a_command_is_unacknowledged():
    rig = Rig()
    rig.autopilot.hold.add("arm")
    rig.agent.offer_plan(plan(inspect_task()))
    rig.tick(20)
    assert rig.agent.root.tip().feedback_message == "waiting for arm"
    assert rig.autopilot.names().count("arm") == 1
    assert rig.outcomes() == []
