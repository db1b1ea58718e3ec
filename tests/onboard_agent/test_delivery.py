"""Tool Delivery Task Tree and Drop Tool Tree."""

from __future__ import annotations

from onboard_agent import AgentConfig
from proto.plan import DeliverTask, PickTask
from proto.telemetry import OutcomeResult
from tests.onboard_agent.helpers import SCENARIO, Rig, inspect_task, plan

RACK = SCENARIO.site.tool_station("tp-wrench").position
W1 = SCENARIO.site.worker("W1").position


def pick(tool: str = "wrench") -> PickTask:
    return PickTask(task_id="p1", tool=tool, tool_station_id="tp-wrench", position=RACK, pick_s=1.0)


def deliver(tool: str = "wrench") -> DeliverTask:
    return DeliverTask(task_id="d1", tool=tool, worker_id="W1", drop_s=1.0)


def test_pick_then_deliver():
    rig = Rig()
    rig.agent.offer_plan(plan(pick(), deliver()))
    rig.run_until(lambda: rig.mission.head is not None and rig.mission.head.task_id == "d1")
    assert rig.agent.ctx.tool == "wrench"
    assert rig.autopilot.grabbed == 1
    grab_at = rig.autopilot.state.position
    assert grab_at.distance_to(RACK) <= 1.5
    rig.run_until(lambda: rig.mission.head is None)
    assert rig.autopilot.released == 1
    assert rig.agent.ctx.tool is None
    assert [(o.task_id, o.result) for o in rig.outcomes()] == [
        ("p1", OutcomeResult.COMPLETED),
        ("d1", OutcomeResult.COMPLETED),
    ]
    telemetry = rig.agent.telemetry()
    assert telemetry.tool is None


def test_deliver_without_the_tool_picks_it_first():
    rig = Rig()
    rig.agent.offer_plan(plan(deliver()))
    rig.run_until(lambda: rig.autopilot.grabbed == 1)
    rig.run_until(lambda: rig.mission.head is None)
    assert rig.autopilot.released == 1


def test_grip_waits_until_hovering():
    rig = Rig()
    rig.agent.offer_plan(plan(pick()))
    rig.run_until(lambda: rig.leaf() == "Pick Tool")
    assert rig.autopilot.grabbed == 1  # the fake hovers at once


def test_refused_gripper_fails_the_task():
    rig = Rig(
        "uav-2", position=SCENARIO.site.station("C2").position, config=AgentConfig(task_attempts=1)
    )
    rig.autopilot.deny["grab"] = "Gripper: not fitted"
    rig.agent.offer_plan(plan(pick(), uav_id="uav-2"))
    rig.run_until(lambda: rig.mission.head is None)
    [outcome] = rig.outcomes()
    assert outcome.result is OutcomeResult.FAILED
    assert "Gripper: not fitted" in outcome.reason


def test_a_tool_nobody_needs_is_dropped_before_the_next_task():
    rig = Rig()
    rig.agent.ctx.tool, rig.agent.ctx.tool_station_id = "hammer", "tp-hammer"
    rig.agent.offer_plan(plan(inspect_task()))
    rig.run_until(lambda: rig.leaf() == "Drop Tool")
    rig.run_until(lambda: rig.agent.ctx.tool is None)
    released_at = dict(rig.autopilot.calls)["release"]
    hammer_point = SCENARIO.site.tool_station("tp-hammer").position
    assert released_at.distance_to(hammer_point) <= 1.5  # back where it was picked
    assert rig.mission.waypoints_done("t1") == []  # dropping came first
    rig.run_until(lambda: rig.mission.head is None)


def test_a_grab_that_got_nothing_fails_the_pick_instead_of_delivering_air():
    rig = Rig(config=AgentConfig(task_attempts=1))
    rig.autopilot.gripper_says = "Gripper: grabbed nothing"
    rig.agent.offer_plan(plan(pick(), deliver()))
    rig.run_until(lambda: rig.mission.head is None)
    assert rig.autopilot.released == 0
    results = {o.task_id: (o.result, o.reason) for o in rig.outcomes()}
    assert results["p1"][0] is OutcomeResult.FAILED
    assert "grabbed nothing" in results["p1"][1]
    assert rig.agent.ctx.tool is None


def test_the_wrong_tool_grabbed_fails_the_pick_and_is_taken_back():
    rig = Rig(config=AgentConfig(task_attempts=1))
    rig.autopilot.gripper_says = "Gripper: grabbed allen-wrench at tp-allen-wrench"
    rig.agent.offer_plan(plan(pick(), deliver()))
    rig.run_until(lambda: rig.autopilot.released == 1)
    [first, *_] = rig.outcomes()
    assert (first.task_id, first.result) == ("p1", OutcomeResult.FAILED)
    assert "grabbed allen-wrench instead of wrench" in first.reason
    released_at = dict(rig.autopilot.calls)["release"]
    assert released_at.distance_to(RACK) <= 1.5  # dropped back at a tool station, not the worker
