"""The mission manager with the real planner and a real SQLite file."""

from __future__ import annotations

import msgspec
import pytest

from ground_station.action_book import NotFound
from ground_station.missions import Conflict
from ground_station.validation import InvalidAction
from proto import (
    ActionState,
    AgentState,
    AgentStatus,
    CancelAction,
    Command,
    ControlUav,
    EventKind,
    FlightState,
    InspectTask,
    LandTask,
    ModifyAction,
    MonitorAction,
    OutcomeResult,
    PickTask,
    RequestError,
    SubmitAction,
    TaskOutcome,
    WaitTask,
)
from tests.ground_station.harness import ALL, Harness


def test_a_new_action_is_stored_planned_and_sent_to_the_capable_uav(gs):
    record = gs.submit("deliver-wrench")
    assert record.state == ActionState.PLANNED
    plan = gs.latest("uav-1")
    assert [type(t) for t in plan.tasks][:2] == [PickTask, type(plan.tasks[1])]
    assert plan.tasks[0].action_id == "deliver-wrench"
    assert all(p.uav_id == "uav-1" for p in gs.sent)  # nobody else's work changed
    kinds = [e.kind for e in gs.events]
    assert EventKind.ACTION_ACCEPTED in kinds and EventKind.PLAN_CHANGED in kinds
    assert gs.store.action("deliver-wrench").state == ActionState.PLANNED


def test_submission_is_idempotent_on_the_request_id(gs):
    first = gs.submit("inspect-loop", request_id="same")
    sent = len(gs.sent)
    again = gs.submit("inspect-loop", request_id="same")
    assert again == first and len(gs.sent) == sent
    assert len(gs.store.actions()) == 1
    other = gs.scenario.actions[0].action
    with pytest.raises(Conflict) as caught:
        gs.manager.submit(SubmitAction(request_id="same", action=other))
    assert caught.value.field == "request_id"
    same = gs.store.action(first.action_id).action
    with pytest.raises(Conflict) as caught:  # the same action under another id: not a replay
        gs.manager.submit(SubmitAction(request_id="same", action=same, action_id="other-id"))
    assert caught.value.field == "action_id" and gs.store.action("other-id") is None
    replay = SubmitAction(request_id="same", action=same, action_id=first.action_id)
    assert gs.manager.submit(replay) == first


def test_an_invalid_action_is_refused_and_nothing_is_stored(gs):
    bad = SubmitAction(
        request_id="r",
        action=gs.scenario.actions[2].action.__class__(worker_id="nobody", duration_s=5),
    )
    with pytest.raises(InvalidAction):
        gs.manager.submit(bad)
    assert gs.store.actions() == [] and gs.sent == []


def test_plans_carry_increasing_epochs(gs):
    gs.submit("deliver-wrench")
    gs.submit("inspect-loop")
    epochs = [p.epoch for p in gs.sent]
    assert epochs == sorted(epochs) and len(set(epochs)) >= 2


def test_cancel_removes_the_work_and_is_idempotent(gs):
    gs.submit("inspect-loop")
    owner = gs.sent[-1].uav_id
    record = gs.manager.cancel(CancelAction(request_id="c1", action_id="inspect-loop"))
    gs.settle()
    assert record.state == ActionState.CANCELLED
    assert not [t for t in gs.latest(owner).tasks if t.action_id == "inspect-loop"]
    assert gs.manager.cancel(CancelAction(request_id="c2", action_id="inspect-loop")) == record
    with pytest.raises(NotFound):
        gs.manager.cancel(CancelAction(request_id="c3", action_id="nope"))


def test_modify_changes_priority_and_refuses_finished_actions(gs):
    gs.submit("inspect-loop")
    record = gs.manager.modify(ModifyAction(request_id="m", action_id="inspect-loop", priority=9))
    gs.settle()
    assert record.action.priority == 9
    gs.manager.cancel(CancelAction(request_id="c", action_id="inspect-loop"))
    gs.settle()
    with pytest.raises(Exception, match="cancelled"):
        gs.manager.modify(ModifyAction(request_id="m2", action_id="inspect-loop", priority=1))


def test_an_edit_that_changes_the_action_kind_is_an_invalid_action(gs):
    gs.submit("inspect-loop")
    watch = MonitorAction(worker_id="W1", uavs=1, standoff_m=3, duration_s=60)
    edit = ModifyAction(request_id="m", action_id="inspect-loop", action=watch)
    with pytest.raises(InvalidAction) as refused:
        gs.manager.modify(edit)
    assert (refused.value.code, refused.value.field) == ("invalid_action", "action.type")


def _inspecting(gs, action_id: str) -> set[str]:
    """The UAVs whose current plans inspect for ``action_id``."""
    return {
        p.uav_id
        for p in gs.replanner.plans.values()
        for t in p.tasks
        if isinstance(t, InspectTask) and t.action_id == action_id
    }


def _inspect_task(gs, action_id: str):
    for plan in reversed(gs.sent):
        for task in plan.tasks:
            if isinstance(task, InspectTask) and task.action_id == action_id:
                return plan, task
    raise AssertionError("no inspection task sent")


def test_outcomes_complete_an_inspection_waypoint_by_waypoint(gs):
    gs.submit("inspect-loop")
    plan, task = _inspect_task(gs, "inspect-loop")
    first_half = [w.index for w in task.waypoints[:4]]
    gs.manager.reports.on_outcome(
        TaskOutcome(
            uav_id=plan.uav_id,
            task_id=task.task_id,
            epoch=plan.epoch,
            result=OutcomeResult.ABORTED,
            progress=0.5,
            waypoints_done=first_half,
        )
    )
    gs.settle()
    record = gs.store.action("inspect-loop")
    assert record.state == ActionState.IN_PROGRESS and record.waypoints_done == first_half
    plan, task = _inspect_task(gs, "inspect-loop")
    assert {w.index for w in task.waypoints}.isdisjoint(first_half)  # resumes, no repeats
    gs.manager.reports.on_outcome(
        TaskOutcome(
            uav_id=plan.uav_id,
            task_id=task.task_id,
            epoch=plan.epoch,
            result=OutcomeResult.COMPLETED,
            waypoints_done=[w.index for w in task.waypoints],
        )
    )
    gs.settle()
    record = gs.store.action("inspect-loop")
    assert record.state == ActionState.COMPLETED and record.progress == 1.0


def test_stale_outcomes_are_recorded_but_change_nothing(gs):
    gs.submit("inspect-loop")
    plan, task = _inspect_task(gs, "inspect-loop")
    other = next(u for u in ALL if u != plan.uav_id)
    gs.manager.reports.on_outcome(
        TaskOutcome(
            uav_id=other,
            task_id=task.task_id,
            epoch=plan.epoch,
            result=OutcomeResult.COMPLETED,
            waypoints_done=list(range(8)),
        )
    )
    gs.settle()
    assert gs.store.action("inspect-loop").state == ActionState.PLANNED
    assert gs.manager.reports.counters.stale_outcomes == 1
    assert gs.events[-1].kind == EventKind.FAULT


def test_a_lost_uav_s_work_goes_to_another_and_it_gets_a_higher_epoch_back(gs):
    gs.submit("inspect-loop")
    plan, _ = _inspect_task(gs, "inspect-loop")
    victim = plan.uav_id
    others = [u for u in ALL if u != victim]
    gs.monitor.on_token(victim, False, gs.now)
    gs.advance(4.0)
    gs.heartbeat(*others)
    assert _inspect_task(gs, "inspect-loop")[0].uav_id == victim  # brief: nothing moved
    gs.advance(1.5)
    gs.heartbeat(*others)
    new_plan, _ = _inspect_task(gs, "inspect-loop")
    assert new_plan.uav_id != victim and new_plan.epoch > plan.epoch
    assert any(e.kind == EventKind.UAV_LOST and e.uav_id == victim for e in gs.events)
    assert gs.replanner.plans[victim].tasks == []
    gs.bring_up(victim)
    back = gs.latest(victim)
    assert back.epoch > new_plan.epoch


def test_nothing_accepted_is_lost_across_a_restart(tmp_path):
    path = str(tmp_path / "gs.db")
    first = Harness(path)
    first.bring_up(*ALL)
    first.submit("deliver-wrench")
    first.submit("inspect-loop")
    last_epoch = max(p.epoch for p in first.sent)
    # no close(): the process "dies" here
    second = Harness(path, now=2000.0)
    assert {r.action_id for r in second.store.actions()} == {"deliver-wrench", "inspect-loop"}
    assert second.replanner.plans.keys() == first.replanner.plans.keys()
    second.bring_up(*ALL)
    assert second.sent and min(p.epoch for p in second.sent) > last_epoch
    assert {t.action_id for p in second.sent for t in p.tasks} >= {"deliver-wrench", "inspect-loop"}
    assert second.events[0].seq > first.events[-1].seq


def test_battery_below_the_plan_replans_once_per_epoch(gs):
    gs.submit("inspect-loop")
    plan, _ = _inspect_task(gs, "inspect-loop")
    landed = gs.telemetry(plan.uav_id, battery_wh=1.0)
    gs.manager.reports.on_telemetry(landed)  # on a pad it draws nothing: not a battery fault
    gs.settle()
    assert gs.manager.reports.counters.battery_replans == 0
    low = msgspec.structs.replace(landed, flight_state=FlightState.FLYING)
    gs.manager.reports.on_telemetry(low)
    gs.settle()
    gs.manager.reports.on_telemetry(low)
    gs.settle()
    assert gs.manager.reports.counters.battery_replans == 1


def test_a_status_ahead_of_telemetry_does_not_break_replanning(gs):
    gs.submit("deliver-wrench")
    drop = next(t for t in gs.latest("uav-1").tasks if t.task_id.endswith(".drop"))
    # the status says "dropping" while telemetry does not (yet) show the tool held
    gs.monitor.on_status(
        AgentStatus(uav_id="uav-1", stamp_s=gs.now, state=AgentState.BUSY, task_id=drop.task_id)
    )
    replans = gs.replanner.stats.count
    gs.manager.replan("status ahead of telemetry")
    assert gs.replanner.stats.count == replans + 1
    assert not [e for e in gs.events if e.kind == EventKind.FAULT and "refused" in e.detail]
    assert gs.store.action("deliver-wrench").state == ActionState.PLANNED


def test_a_status_naming_a_finished_action_does_not_break_replanning(gs):
    gs.submit("monitor-w2")
    plan = next(p for p in reversed(gs.sent) if p.tasks)
    watch = next(t for t in plan.tasks if t.action_id == "monitor-w2")
    gs.monitor.on_status(
        AgentStatus(
            uav_id=plan.uav_id, stamp_s=gs.now, state=AgentState.BUSY, task_id=watch.task_id
        )
    )
    gs.manager.cancel(CancelAction(request_id="c", action_id="monitor-w2"))
    gs.settle()
    refused = [e for e in gs.events if e.kind == EventKind.FAULT and "refused" in e.detail]
    assert refused == []
    assert gs.store.action("monitor-w2").state == ActionState.CANCELLED


def test_an_operator_command_takes_a_uav_out_of_the_plan_until_resume(gs):
    gs.submit("inspect-loop")
    plan, _ = _inspect_task(gs, "inspect-loop")
    held = plan.uav_id
    gs.manager.control(ControlUav(uav_id=held, command=Command.LAND))
    gs.settle()
    [land] = gs.latest(held).tasks
    assert isinstance(land, LandTask)
    assert _inspect_task(gs, "inspect-loop")[0].uav_id != held  # its work went to another
    fleet = {u.uav_id: u for u in gs.manager.fleet().uavs}
    assert fleet[held].control == Command.LAND
    gs.manager.reports.on_outcome(
        TaskOutcome(
            uav_id=held,
            task_id=land.task_id,
            epoch=gs.latest(held).epoch,
            result=OutcomeResult.COMPLETED,
        )
    )
    gs.manager.request_replan("test")
    gs.settle()
    assert gs.replanner.plans[held].tasks == []  # landed: it waits for the operator
    gs.manager.control(ControlUav(command=Command.HOLD))  # every UAV: a fleet stop
    gs.settle()
    assert all(isinstance(gs.latest(u).tasks[0], WaitTask) for u in ALL)
    assert not _inspecting(gs, "inspect-loop")
    gs.manager.control(ControlUav(command=Command.RESUME))
    gs.settle()
    assert {u.control for u in gs.manager.fleet().uavs} == {None}
    assert _inspecting(gs, "inspect-loop")  # planned again
    with pytest.raises(RequestError) as unknown:
        gs.manager.control(ControlUav(uav_id="uav-9", command=Command.HOLD))
    assert unknown.value.code == "not_found"
