"""The mission manager's rules for a running fleet: which outcomes replan,
synchronised starts that stay put, task ids that are never reused, tool
stock, deliveries confirmed by telemetry, crashes handled at once."""

from __future__ import annotations

import itertools

import msgspec
import pytest

from ground_station.agent_reports import MAX_RETRYABLE_FAILURES
from proto import (
    ActionState,
    AgentState,
    AgentStatus,
    CancelAction,
    Command,
    ControlUav,
    DeliverAction,
    DeliverTask,
    EventKind,
    FlightState,
    GoHomeTask,
    MonitorAction,
    MonitorTask,
    OutcomeResult,
    PickTask,
    Point,
    SubmitAction,
    TaskOutcome,
    WaitTask,
)
from proto.errors import ToolOutOfStock
from tests.ground_station.harness import ALL, Harness


def submit(gs: Harness, action, action_id: str):
    gs.manager.submit(SubmitAction(request_id=action_id, action=action, action_id=action_id))
    gs.settle()
    return gs.store.action(action_id)


def outcome(gs: Harness, uav_id: str, task, result=OutcomeResult.COMPLETED, **extra) -> None:
    plan = gs.replanner.plans[uav_id]
    gs.manager.reports.on_outcome(
        TaskOutcome(
            uav_id=uav_id,
            task_id=task.task_id,
            action_id=task.action_id,
            epoch=plan.epoch,
            result=result,
            **extra,
        )
    )
    gs.settle()


def pair_monitor(gs: Harness) -> dict[str, list]:
    submit(gs, MonitorAction(worker_id="W2", uavs=2, standoff_m=4, duration_s=120), "watch")
    return {u: list(gs.replanner.plans[u].tasks) for u in ALL}


def test_a_finished_wait_replans_nothing_and_the_synchronised_start_stays(gs):
    plans = pair_monitor(gs)
    waiting = next((u for u, tasks in plans.items() if tasks and isinstance(tasks[0], WaitTask)))
    starts = {
        t.end_s - t.duration_s
        for tasks in plans.values()
        for t in tasks
        if isinstance(t, MonitorTask)
    }
    epoch = gs.store.counter("epoch")
    gs.now = plans[waiting][0].until_s  # the wait ends, shortly before the start
    outcome(gs, waiting, plans[waiting][0])
    assert gs.store.counter("epoch") == epoch, "a finished wait is not a trigger"
    gs.manager.replan("some other trigger")
    again = {
        t.end_s - t.duration_s
        for u in ALL
        for t in gs.replanner.plans[u].tasks
        if isinstance(t, MonitorTask)
    }
    assert again == starts, "the promised start did not move"


def test_a_finished_wait_replans_nothing_while_an_action_waits_for_a_uav(gs, monkeypatch):
    """Chaos seed 15: with an action waiting for a UAV, every finished wait
    replanned, and the replan gave the UAV a wait until now again: 62,000
    plans, and the UAV never left its pad. A wait it finishes changes
    nothing (a recharge does: the UAV may now take the action)."""
    plans = pair_monitor(gs)
    monkeypatch.setattr(gs.manager.reports, "_waiting_for_a_uav", lambda: True)
    waiting = next((u for u, tasks in plans.items() if tasks and isinstance(tasks[0], WaitTask)))
    replans = gs.replanner.stats.count
    gs.now = plans[waiting][0].until_s
    outcome(gs, waiting, plans[waiting][0])
    assert gs.replanner.stats.count == replans, "a finished wait is not a trigger"


def test_a_replan_that_changes_nothing_bumps_no_epoch_and_emits_no_event(gs):
    pair_monitor(gs)
    epoch, events = gs.store.counter("epoch"), len(gs.events)
    gs.manager.replan("nothing new")
    gs.manager.replan("still nothing")
    assert gs.store.counter("epoch") == epoch
    assert gs.events[events:] == []
    assert gs.replanner.stats.unchanged >= 2


def test_a_monitoring_segment_never_gets_the_id_of_one_already_flown(gs):
    plans = pair_monitor(gs)
    uav, segment = next(
        (u, t) for u, tasks in plans.items() for t in tasks if isinstance(t, MonitorTask)
    )
    gs.now = segment.end_s - 60  # half of the window flown, then the segment ends early
    outcome(gs, uav, segment, OutcomeResult.ABORTED, progress=0.5, flown_s=60.0)
    record = gs.store.action("watch")
    assert record.segments == {uav: 1}
    assert record.monitored_s == pytest.approx(30.0)  # 60 s on one of two slots
    later = [t for t in gs.replanner.plans[uav].tasks if isinstance(t, MonitorTask)]
    assert all(t.task_id != segment.task_id for t in later)


def test_the_last_copy_of_a_tool_is_reserved_and_given_back_on_cancel(gs):
    wrench = DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1")
    submit(gs, wrench, "first")
    with pytest.raises(ToolOutOfStock) as refused:
        submit(gs, msgspec.structs.replace(wrench, worker_id="W2"), "second")
    assert refused.value.code == "tool_out_of_stock" and refused.value.field == "action.tool"
    assert gs.store.action("second") is None
    gs.manager.cancel(CancelAction(request_id="c", action_id="first"))
    gs.settle()
    assert submit(gs, wrench, "third").state == ActionState.PLANNED


def test_a_drop_without_the_tool_seen_in_telemetry_is_not_a_delivery(gs):
    submit(gs, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    tasks = gs.replanner.plans["uav-1"].tasks
    pick, drop = tasks[0], tasks[1]
    outcome(gs, "uav-1", pick)
    outcome(gs, "uav-1", drop)  # telemetry never showed the wrench held
    assert gs.store.action("d").state != ActionState.COMPLETED
    faults = [e.detail for e in gs.events if e.kind == EventKind.FAULT]
    assert any("not confirmed" in d and "no tool" in d for d in faults), faults


def test_a_drop_with_the_tool_carried_to_the_worker_completes(gs):
    submit(gs, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    pick, drop = gs.replanner.plans["uav-1"].tasks[:2]
    outcome(gs, "uav-1", pick)
    worker = gs.scenario.site.worker("W1").position
    carrying = msgspec.structs.replace(
        gs.telemetry("uav-1"), tool="wrench", position=worker, flight_state=FlightState.FLYING
    )
    gs.monitor.on_telemetry(carrying, gs.now)
    gs.manager.reports.on_telemetry(carrying)
    gs.settle()
    drop = next(t for t in gs.replanner.plans["uav-1"].tasks if t.task_id == drop.task_id)
    outcome(gs, "uav-1", drop)
    assert gs.store.action("d").state == ActionState.COMPLETED


def test_a_tool_picked_before_telemetry_shows_it_is_not_picked_again(gs):
    """The pick's outcome comes before the telemetry that shows the tool
    held: the replan it triggers keeps the drop and sends no new pick (a
    new pick, done at once on board, triggered the next replan, and so on)."""
    submit(gs, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    pick = gs.replanner.plans["uav-1"].tasks[0]
    sent = len(gs.sent)
    gs.now += 1.0  # telemetry so far: landed, no tool
    outcome(gs, "uav-1", pick, stamp_s=gs.now)
    tasks = gs.replanner.plans["uav-1"].tasks
    assert not any(isinstance(t, PickTask) for t in tasks), tasks
    assert any(isinstance(t, DeliverTask) for t in tasks), tasks
    assert len(gs.sent) == sent  # nothing new to fly: no new epoch


def test_a_segment_handed_over_names_its_relief_and_the_last_names_none(gs):
    """1,500 s of W2 take three segments on alternating UAVs: each but the
    last names the UAV that takes the slot over where it ends, which the
    agent waits for before it leaves."""
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=1500), "long")
    segments = sorted(
        ((t, u) for u in ALL for t in gs.replanner.plans[u].tasks if isinstance(t, MonitorTask)),
        key=lambda s: s[0].end_s,
    )
    assert len(segments) >= 3
    for (task, uav), (after, relief) in itertools.pairwise(segments):
        assert task.relieved_by == relief != uav
        assert abs(after.window_start_s - task.end_s) <= 5.0
    assert segments[-1][0].relieved_by is None


def test_a_crashed_uav_is_declared_at_once_and_its_work_goes_elsewhere(gs):
    plans = pair_monitor(gs)
    victim = next(u for u, tasks in plans.items() if any(isinstance(t, MonitorTask) for t in tasks))
    crashed = msgspec.structs.replace(gs.telemetry(victim), flight_state=FlightState.CRASHED)
    gs.monitor.on_telemetry(crashed, gs.now)
    gs.advance(0.1)  # far less than the 5 s grace
    assert (EventKind.UAV_CRASHED, victim) in [(e.kind, e.uav_id) for e in gs.events]
    watchers = {
        u for u in ALL if any(isinstance(t, MonitorTask) for t in gs.replanner.plans[u].tasks)
    }
    assert victim not in watchers and len(watchers) == 2


def test_a_failed_task_given_back_unchanged_is_sent_again_with_a_new_epoch(gs):
    submit(gs, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    pick = gs.replanner.plans["uav-1"].tasks[0]
    epoch = gs.replanner.plans["uav-1"].epoch
    gs.sent.clear()
    outcome(
        gs,
        "uav-1",
        pick,
        OutcomeResult.FAILED,
        reason="arming refused: GPS 1: Bad fix",
        retryable=True,
        reason_code="arm_refused",
    )
    resent = [p for p in gs.sent if p.uav_id == "uav-1"]
    assert resent and resent[-1].epoch > epoch
    assert resent[-1].tasks[0].task_id == pick.task_id  # the same work, which the agent dropped


def test_a_permanent_failure_fails_its_action_at_once_with_the_agents_reason(gs):
    submit(gs, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    pick = gs.replanner.plans["uav-1"].tasks[0]
    outcome(
        gs,
        "uav-1",
        pick,
        OutcomeResult.FAILED,
        reason="grabbed nothing at tp-wrench",
        reason_code="task_failed",
    )
    record = gs.store.action("d")
    assert record.state == ActionState.FAILED
    assert "grabbed nothing" in record.reason and "task_failed" in record.reason
    failed = [e for e in gs.events if e.kind == EventKind.ACTION_FAILED]
    assert failed and "grabbed nothing" in failed[-1].detail
    assert not gs.replanner.plans["uav-1"].tasks or all(
        t.action_id != "d" for t in gs.replanner.plans["uav-1"].tasks
    )


def test_a_retryable_failure_is_replanned_and_resent_until_its_reason_passes(gs):
    submit(gs, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    for _ in range(MAX_RETRYABLE_FAILURES - 1):
        pick = gs.replanner.plans["uav-1"].tasks[0]
        epoch = gs.replanner.plans["uav-1"].epoch
        outcome(
            gs,
            "uav-1",
            pick,
            OutcomeResult.FAILED,
            reason="arming refused: PreArm: AHRS: waiting for home",
            retryable=True,
            reason_code="arm_refused",
        )
        assert gs.store.action("d").state == ActionState.PLANNED
        assert gs.replanner.plans["uav-1"].epoch > epoch  # sent again, always
    pick = gs.replanner.plans["uav-1"].tasks[0]
    outcome(gs, "uav-1", pick, OutcomeResult.FAILED, reason="no fix", retryable=True)
    assert gs.store.action("d").state == ActionState.FAILED  # the guard: it never passed


def wrench_outcome(task, epoch: int) -> TaskOutcome:
    """uav-1's report that ``task`` of delivery "d" completed, holding the wrench."""
    return TaskOutcome(
        uav_id="uav-1",
        task_id=task.task_id,
        action_id="d",
        epoch=epoch,
        tool="wrench",
        result=OutcomeResult.COMPLETED,
    )


def test_outcomes_heard_before_the_uav_is_back_wait_for_it(tmp_path):
    """A restarted ground station hears re-delivered outcomes before it has
    seen the UAV's token and telemetry: they apply once the UAV is back."""
    first = Harness(str(tmp_path / "gs.db"))
    first.bring_up(*ALL)
    submit(first, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    pick = first.replanner.plans["uav-1"].tasks[0]
    epoch = first.replanner.plans["uav-1"].epoch
    restarted = Harness(str(tmp_path / "gs.db"), now=first.now + 5)
    restarted.manager.reports.on_outcome(wrench_outcome(pick, epoch))
    restarted.settle()
    assert restarted.store.action("d").state == ActionState.PLANNED  # held, not lost nor stale
    restarted.bring_up(*ALL)
    assert restarted.store.action("d").state == ActionState.IN_PROGRESS
    assert not [e for e in restarted.events if "stale" in e.detail]


def test_a_delivery_reported_after_a_restart_replanned_without_the_uav_counts(tmp_path):
    """The ground station restarts while uav-1 carries the wrench; the other
    UAVs come back first and the replan takes uav-1's plan away (new epoch).
    uav-1's re-delivered "drop completed" of the old epoch is still true:
    the delivery completes, and is not picked again."""
    first = Harness(str(tmp_path / "gs.db"))
    first.bring_up(*ALL)
    submit(first, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    pick, drop = first.replanner.plans["uav-1"].tasks[:2]
    epoch = first.replanner.plans["uav-1"].epoch
    outcome(first, "uav-1", pick, tool="wrench")
    assert first.store.action("d").state == ActionState.IN_PROGRESS
    restarted = Harness(str(tmp_path / "gs.db"), now=first.now + 5)
    restarted.bring_up("uav-2", "uav-3")  # uav-1 not heard yet: its plan is emptied
    assert restarted.replanner.plans["uav-1"].epoch > epoch
    restarted.bring_up("uav-1")
    restarted.manager.reports.on_outcome(wrench_outcome(drop, epoch))
    restarted.settle()
    assert restarted.store.action("d").state == ActionState.COMPLETED
    assert not [e for e in restarted.events if "stale" in e.detail]


def test_a_monitor_short_of_its_duration_by_a_few_seconds_ends_and_says_so(gs):
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=120), "watch")
    uav, segment = next(
        (u, t) for u in ALL for t in gs.replanner.plans[u].tasks if isinstance(t, MonitorTask)
    )
    gs.now = segment.end_s
    outcome(gs, uav, segment, flown_s=segment.duration_s - 4.0)  # arrived 4 s late
    record = gs.store.action("watch")
    assert record.state == ActionState.COMPLETED
    assert record.monitored_s == pytest.approx(116.0, abs=0.5)
    assert record.progress == pytest.approx(116.0 / 120.0, abs=0.01)  # the shortfall shows


def test_a_monitor_short_by_more_than_the_tail_is_flown_on(gs):
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=120), "watch")
    uav, segment = next(
        (u, t) for u in ALL for t in gs.replanner.plans[u].tasks if isinstance(t, MonitorTask)
    )
    gs.now = segment.end_s
    outcome(gs, uav, segment, flown_s=segment.duration_s - 30.0)
    assert gs.store.action("watch").state == ActionState.IN_PROGRESS
    more = [t for u in ALL for t in gs.replanner.plans[u].tasks if isinstance(t, MonitorTask)]
    assert more and more[0].duration_s == pytest.approx(30.0, abs=1.0)


def test_an_action_no_uav_can_take_yet_is_retried_as_time_passes(gs):
    gs.advance(10)  # no telemetry for 10 s: every UAV is lost, nobody can take work
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=60), "later")
    assert gs.store.action("later").state == ActionState.ACCEPTED
    replans = gs.replanner.stats.count
    gs.manager.retry_unplaced()  # too soon after the last retry: nothing
    gs.settle()
    assert gs.replanner.stats.count == replans
    gs.now += 31
    gs.manager.retry_unplaced()
    gs.settle()
    assert gs.replanner.stats.count == replans + 1


def test_an_action_in_progress_whose_rest_no_uav_can_take_is_retried_too(gs):
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=600), "watch")
    uav, segment = next(
        (u, t) for u in ALL for t in gs.replanner.plans[u].tasks if isinstance(t, MonitorTask)
    )
    gs.now = segment.start_s + 20.0
    outcome(gs, uav, segment, flown_s=20.0)  # cut short: the rest is still to fly
    gs.advance(10)  # then nobody is heard: no UAV can take the rest
    assert gs.store.action("watch").state == ActionState.IN_PROGRESS
    assert gs.replanner.waiting == {"watch"}
    replans = gs.replanner.stats.count
    gs.now += 31
    gs.manager.retry_unplaced()
    gs.settle()
    assert gs.replanner.stats.count == replans + 1


def test_an_agent_idle_on_a_plan_that_still_has_work_gets_it_again(gs):
    submit(gs, DeliverAction(tool="wrench", tool_station_id="tp-wrench", worker_id="W1"), "d")
    plan = gs.replanner.plans["uav-1"]
    gs.sent.clear()
    for dt in (0.0, 2.0, 4.0, 6.0):  # its queue is empty, the plan says pick + drop
        gs.manager.reports.on_status(
            AgentStatus(
                uav_id="uav-1", stamp_s=gs.now + dt, state=AgentState.IDLE, epoch=plan.epoch
            )
        )
        gs.settle()
    resent = [p for p in gs.sent if p.uav_id == "uav-1"]
    assert len(resent) == 1 and resent[0].epoch > plan.epoch
    assert [t.task_id for t in resent[0].tasks][:2] == [t.task_id for t in plan.tasks][:2]


def watched_by_one(gs: Harness) -> tuple[str, list]:
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=120), "watch")
    uav = next(
        u for u in ALL if any(isinstance(t, MonitorTask) for t in gs.replanner.plans[u].tasks)
    )
    return uav, list(gs.replanner.plans[uav].tasks)


def test_a_late_outcome_of_an_earlier_task_with_the_same_id_is_stale(gs):
    """Agents re-deliver recent outcomes when the ground station's token comes
    back; ``uav-N.home`` of an earlier plan must not end the current one's home
    (and, with it, everything before it in the plan)."""
    uav, tasks = watched_by_one(gs)
    home = tasks[-1]
    assert isinstance(home, GoHomeTask)
    epoch = gs.replanner.plans[uav].epoch
    gs.manager.reports.on_outcome(
        TaskOutcome(
            uav_id=uav,
            task_id=home.task_id,
            action_id=None,
            epoch=epoch - 1,
            result=OutcomeResult.COMPLETED,
        )
    )
    gs.settle()
    assert [t.task_id for t in gs.replanner.plans[uav].tasks] == [t.task_id for t in tasks]
    assert [e for e in gs.events if e.detail == f"stale outcome {home.task_id} completed"]


def test_an_outcome_under_an_older_epoch_still_counts_for_a_task_carried_over(gs):
    uav, tasks = watched_by_one(gs)
    epoch = gs.replanner.plans[uav].epoch
    gs.replanner.resend(uav)
    gs.manager.replan("resend")  # same work, a new epoch the agent has not heard yet
    assert gs.replanner.plans[uav].epoch > epoch
    segment = next(t for t in tasks if isinstance(t, MonitorTask))
    gs.now = segment.end_s
    gs.manager.reports.on_outcome(
        TaskOutcome(
            uav_id=uav,
            task_id=segment.task_id,
            action_id="watch",
            epoch=epoch,
            result=OutcomeResult.COMPLETED,
            flown_s=segment.duration_s,
        )
    )
    gs.settle()
    assert gs.store.action("watch").state == ActionState.COMPLETED


def on_station(gs: Harness, uav_id: str, segment: MonitorTask, at: Point) -> None:
    """``uav_id`` hovers at ``at`` and reports flying ``segment``."""
    flying = msgspec.structs.replace(
        gs.telemetry(uav_id), position=at, flight_state=FlightState.FLYING
    )
    gs.monitor.on_telemetry(flying, gs.now)
    status = AgentStatus(
        uav_id=uav_id,
        stamp_s=gs.now,
        state=AgentState.BUSY,
        epoch=gs.replanner.plans[uav_id].epoch,
        task_id=segment.task_id,
        progress=0.5,
    )
    gs.monitor.on_status(status, gs.now)


def test_a_replan_while_a_segment_is_flown_neither_starts_the_watch_over_nor_extends_it(gs):
    """A replan in the middle of a segment (here: a task of another action
    finished) plans only what is left of the watch: the segment keeps its
    window and its UAV is not told to stay longer (it was told to watch
    from scratch, 90 s more than asked, whenever anything replanned)."""
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=90), "watch")
    uav, segment = next(
        (u, t) for u in ALL for t in gs.replanner.plans[u].tasks if isinstance(t, MonitorTask)
    )
    begin = segment.end_s - segment.duration_s
    gs.now = begin + 40.0
    slot = Point(x_m=-1.0, y_m=15.0, z_m=6.0)  # W2 at (-5, 15, 3): 4 m east, 3 m above
    on_station(gs, uav, segment, slot)
    gs.manager.replan("another action's task finished")
    [going_on] = [t for t in gs.replanner.plans[uav].tasks if isinstance(t, MonitorTask)]
    assert going_on.task_id == segment.task_id
    assert going_on.end_s == pytest.approx(segment.end_s, abs=2.0)
    assert going_on.end_s - going_on.duration_s == pytest.approx(begin, abs=2.0)
    others = [t for u in ALL if u != uav for t in gs.replanner.plans[u].tasks]
    assert not [t for t in others if isinstance(t, MonitorTask)], "nobody else is needed"
    outcome(gs, uav, going_on, flown_s=90.0)
    record = gs.store.action("watch")
    assert record.state == ActionState.COMPLETED
    assert record.monitored_s == pytest.approx(90.0)


def test_monitors_serialised_on_the_one_uav_there_was_spread_out_when_others_are_back(gs):
    """Two watches asked while uav-2 and uav-3 are held both go to uav-1, one
    after the other; once the others are given back, the second watch
    starts at once on another UAV instead of keeping its promised start a
    watch later."""
    for uav in ("uav-2", "uav-3"):
        gs.manager.control(ControlUav(uav_id=uav, command=Command.HOLD))
    gs.settle()
    for name in ("first", "second"):
        submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=90), name)

    def starts() -> dict[str, tuple[str, float]]:
        return {
            t.action_id: (u, t.end_s - t.duration_s)
            for u in ALL
            for t in gs.replanner.plans[u].tasks
            if isinstance(t, MonitorTask)
        }

    serial = starts()
    assert serial["first"][0] == serial["second"][0] == "uav-1"
    assert serial["second"][1] >= serial["first"][1] + 90.0
    for uav in ("uav-2", "uav-3"):
        gs.manager.control(ControlUav(uav_id=uav, command=Command.RESUME))
    gs.settle()
    spread = starts()
    assert spread["first"][0] != spread["second"][0]
    assert spread["second"][1] < serial["second"][1] - 60.0


def test_a_watch_being_flown_stays_with_its_uav_when_a_better_suited_one_comes_back(gs):
    """uav-1 watches W2 while the others are held; given back, uav-3 (made
    for monitoring) is better suited, but the rest of the watch starts at
    once: uav-1 keeps the slot instead of leaving it for the seconds uav-3
    needs to take off and come (a 12 s gap seen in the live fleet)."""
    for uav in ("uav-2", "uav-3"):
        gs.manager.control(ControlUav(uav_id=uav, command=Command.HOLD))
    gs.settle()
    submit(gs, MonitorAction(worker_id="W2", uavs=1, standoff_m=4, duration_s=200), "watch")
    [segment] = [t for t in gs.replanner.plans["uav-1"].tasks if isinstance(t, MonitorTask)]
    gs.now = segment.end_s - segment.duration_s + 20.0
    on_station(gs, "uav-1", segment, Point(x_m=-1.0, y_m=15.0, z_m=6.0))
    for uav in ("uav-2", "uav-3"):
        gs.manager.control(ControlUav(uav_id=uav, command=Command.RESUME))
    gs.settle()
    going_on = [t for t in gs.replanner.plans["uav-1"].tasks if isinstance(t, MonitorTask)]
    assert [t.task_id for t in going_on][:1] == [segment.task_id]
    assert going_on[0].end_s > gs.now + 30.0, "uav-1 stays on"
    later = [
        t.end_s - t.duration_s
        for u in ("uav-2", "uav-3")
        for t in gs.replanner.plans[u].tasks
        if isinstance(t, MonitorTask)
    ]
    assert all(start >= going_on[0].end_s - 1.0 for start in later), "a relief, not a gap"
