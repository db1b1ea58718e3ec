"""The demo's plain-language narration: events (and plans) to lines."""

from __future__ import annotations

from linecrew.launch.narrate import Narrator, intro, outcome_text
from linecrew_runtime.scenarios import load
from proto.events import EventKind, GsEvent

ORIGIN_S = 1000.0


def event(kind: EventKind, stamp_s: float = ORIGIN_S + 42, **fields) -> GsEvent:
    return GsEvent(seq=1, stamp_s=stamp_s, kind=kind, **fields)


def state(action_id: str, detail: str) -> GsEvent:
    return event(EventKind.ACTION_STATE, action_id=action_id, detail=detail)


def plan(uav_id: str, *tasks: dict) -> dict:
    return {"uav_id": uav_id, "epoch": 3, "tasks": list(tasks)}


PICK = {
    "type": "pick",
    "task_id": "deliver-wrench.pick",
    "action_id": "deliver-wrench",
    "tool": "wrench",
    "tool_station_id": "tp-wrench",
    "start_s": ORIGIN_S,
    "end_s": ORIGIN_S + 30,
}
DROP = {
    "type": "deliver",
    "task_id": "deliver-wrench.drop",
    "action_id": "deliver-wrench",
    "tool": "wrench",
    "worker_id": "W1",
}
RECHARGE = {"type": "recharge", "task_id": "uav-2.recharge1", "station_id": "C2"}


def test_a_plan_change_tells_the_new_first_task_with_its_mission_time():
    narrator = Narrator(ORIGIN_S)
    changed = event(EventKind.PLAN_CHANGED, uav_id="uav-1", epoch=3, detail="2 tasks")
    assert narrator.lines([changed], [plan("uav-1", PICK, DROP)]) == [
        "t=   42 s  uav-1 heads to tp-wrench to pick the wrench, then brings it to W1"
        " (deliver-wrench)"
    ]


def test_a_plan_change_that_keeps_the_first_task_tells_nothing():
    narrator = Narrator(ORIGIN_S)
    changed = event(EventKind.PLAN_CHANGED, uav_id="uav-2", epoch=3)
    assert narrator.lines([changed], [plan("uav-2", RECHARGE)]) == [
        "t=   42 s  uav-2 recharges at C2"
    ]
    retimed = {**RECHARGE, "end_s": ORIGIN_S + 500}
    again = event(EventKind.PLAN_CHANGED, uav_id="uav-2", epoch=4)
    assert narrator.lines([again], [plan("uav-2", retimed, PICK)]) == []
    emptied = event(EventKind.PLAN_CHANGED, uav_id="uav-2", epoch=5)
    assert narrator.lines([emptied], [plan("uav-2")]) == ["t=   42 s  uav-2 has nothing left to do"]


def test_a_first_empty_plan_tells_nothing_and_other_uavs_plans_are_ignored():
    narrator = Narrator(ORIGIN_S)
    changed = event(EventKind.PLAN_CHANGED, uav_id="uav-3", epoch=1)
    assert narrator.lines([changed], [plan("uav-1", PICK)]) == []


def test_a_handover_names_who_relieves_whom_and_is_counted():
    narrator = Narrator(ORIGIN_S)
    handover = event(
        EventKind.HANDOVER,
        action_id="monitor-w2",
        uav_id="uav-3",
        detail="slot 0 of W2: uav-2 -> uav-3",
    )
    assert (
        narrator.lines([handover, handover], [])
        == ["t=   42 s  hand-over: uav-3 relieves uav-2 watching W2"] * 2
    )
    assert narrator.handovers == 2


def test_a_failed_action_is_told_with_its_reason_once():
    narrator = Narrator(ORIGIN_S)
    events = [
        event(
            EventKind.ACTION_STATE,
            action_id="inspect-towers",
            detail="in_progress->failed: no UAV can reach waypoint 2",
        ),
        event(
            EventKind.ACTION_FAILED,
            action_id="inspect-towers",
            detail="no UAV can reach waypoint 2",
        ),
    ]
    assert narrator.lines(events, []) == [
        "t=   42 s  inspect-towers FAILED: no UAV can reach waypoint 2"
    ]


def test_action_progress_uav_trouble_and_faults_are_told():
    narrator = Narrator(ORIGIN_S)
    events = [
        state("monitor-w2", "planned->in_progress: monitor-w2.slot0.uav-3.1 started"),
        state("deliver-wrench", "in_progress->completed: deliver-wrench.drop completed"),
        state("inspect-towers", "planned->accepted: no UAV free"),
        event(EventKind.UAV_LOST, uav_id="uav-1", detail="silent past the link timeout"),
        event(EventKind.UAV_CRASHED, uav_id="uav-3", detail="telemetry says crashed"),
        event(EventKind.FAULT, uav_id="uav-2", detail="battery 4.1 Wh below plan"),
    ]
    assert [line.split(" s  ", 1)[1] for line in narrator.lines(events, [])] == [
        "monitor-w2 in progress",
        "deliver-wrench completed",
        "inspect-towers waits for a UAV: no UAV free",
        "uav-1 LOST: silent past the link timeout",
        "uav-3 CRASHED: telemetry says crashed",
        "uav-2 fault: battery 4.1 Wh below plan",
    ]


def test_a_repeated_fault_is_told_again_only_after_the_first_task_changed():
    narrator = Narrator(ORIGIN_S)

    def battery(wh: float) -> GsEvent:
        return event(EventKind.FAULT, uav_id="uav-2", detail=f"battery {wh} Wh below plan")

    other = event(EventKind.FAULT, uav_id="uav-1", detail="battery 9.0 Wh below plan")
    changed = event(EventKind.PLAN_CHANGED, uav_id="uav-2", epoch=4)
    told = narrator.lines([battery(16.6), battery(16.4), other, battery(16.2)], [])
    assert [line.split(" s  ", 1)[1] for line in told] == [
        "uav-2 fault: battery 16.6 Wh below plan",
        "uav-1 fault: battery 9.0 Wh below plan",
    ]
    told = narrator.lines([changed, battery(16.0)], [plan("uav-2", RECHARGE)])
    assert [line.split(" s  ", 1)[1] for line in told] == [
        "uav-2 recharges at C2",
        "uav-2 fault: battery 16.0 Wh below plan",
    ]


def test_a_uav_back_after_being_lost_is_back_otherwise_it_just_connected():
    narrator = Narrator(ORIGIN_S)
    back = event(EventKind.UAV_BACK, uav_id="uav-1", detail="heard again")
    lost = event(EventKind.UAV_LOST, uav_id="uav-1", detail="silent")
    told = narrator.lines([back, lost, back], [])
    assert [line.split(" s  ", 1)[1] for line in told] == [
        "uav-1 connected (its agent is up)",
        "uav-1 LOST: silent",
        "uav-1 back: heard again",
    ]


def test_replans_are_not_told():
    narrator = Narrator(ORIGIN_S)
    replan = event(EventKind.REPLAN, epoch=7, detail="uav-1 lost; 2 plan(s) changed in 3.0 ms")
    assert narrator.lines([replan], [plan("uav-1", PICK)]) == []


def test_the_inbox_is_drained_in_order():
    narrator = Narrator(ORIGIN_S)
    first, second = event(EventKind.ACTION_ACCEPTED), event(EventKind.REPLAN)
    narrator.inbox.put(first)
    narrator.inbox.put(second)
    assert narrator.drain() == [first, second]
    assert narrator.drain() == []


def test_the_intro_lists_each_scripted_action_with_its_time_and_the_speedup():
    paper = load("paper")
    text = intro(paper, 10)
    for scripted in paper.actions:
        assert f"at {scripted.at_s:>4.0f} s  {scripted.id}: " in text
    assert "at    0 s  deliver-wrench: deliver the wrench from tp-wrench to worker W1" in text
    assert "x10: 10 mission seconds pass per real second" in text


def test_an_outcome_gives_the_reason_only_when_not_completed():
    done = {"state": "completed", "progress": 1.0, "reason": "deliver-wrench.drop completed"}
    failed = {"state": "failed", "progress": 0.4, "reason": "no UAV can reach waypoint 2"}
    assert outcome_text(done) == "completed (100 %)"
    assert outcome_text(failed) == "failed (40 %): no UAV can reach waypoint 2"


def test_a_silent_spell_is_told_when_it_begins_and_when_it_ends():
    narrator = Narrator(ORIGIN_S)
    events = [
        event(EventKind.UAV_SILENT, uav_id="uav-2", detail="silent since 10:00:05 (mission clock)"),
        event(EventKind.UAV_HEARD, uav_id="uav-2", detail="heard again within the link timeout"),
    ]
    assert [line.split(" s  ", 1)[1] for line in narrator.lines(events, [])] == [
        "uav-2 silent since 10:00:05 (mission clock)",
        "uav-2 heard again within the link timeout",
    ]
