"""A UAV silent within the link timeout: told once with the time its silence
began, its tasks unknown (never failed, never replanned) until it is heard
again, when they are what its reports say."""

from __future__ import annotations

from ground_station.fleet_monitor import SILENT_AFTER_S
from linecrew_runtime.clock import time_of_day
from proto import ActionState, AgentState, AgentStatus, EventKind, InspectTask
from tests.ground_station.harness import ALL


def fleet(gs) -> dict:
    return {u.uav_id: u for u in gs.manager.fleet().uavs}


def test_a_silent_uav_s_tasks_are_unknown_until_it_is_heard_again(gs):
    gs.submit("inspect-loop")
    [plan] = [p for p in gs.sent if any(isinstance(t, InspectTask) for t in p.tasks)]
    victim, others = plan.uav_id, [u for u in ALL if u != plan.uav_id]
    task = next(t for t in plan.tasks if isinstance(t, InspectTask))
    running = AgentStatus(
        uav_id=victim, stamp_s=gs.now, state=AgentState.BUSY, epoch=plan.epoch, task_id=task.task_id
    )
    gs.monitor.on_status(running, gs.now)
    last_heard = gs.now
    sent, seen, replans = len(gs.sent), len(gs.events), gs.replanner.stats.count

    for _ in range(4):  # 4 s of silence in steps, the others heard meanwhile
        gs.advance(1.0)
        gs.heartbeat(*others)
    silent = [e for e in gs.events[seen:] if e.kind == EventKind.UAV_SILENT]
    assert [e.uav_id for e in silent] == [victim]  # once per spell
    assert f"silent since {time_of_day(last_heard)}" in silent[0].detail
    shown = fleet(gs)[victim]
    assert shown.silent_s is not None and shown.silent_s >= SILENT_AFTER_S
    assert shown.silent_since_s == last_heard
    ids = [t.task_id for t in gs.replanner.plans[victim].tasks]
    assert shown.unknown_tasks == ids[ids.index(task.task_id) :] and shown.unknown_tasks
    assert all(not u.unknown_tasks for uav, u in fleet(gs).items() if uav != victim)
    assert gs.manager.book.record("inspect-loop").state == ActionState.PLANNED  # not failed
    assert (len(gs.sent), gs.replanner.stats.count) == (sent, replans)  # nothing replanned

    gs.monitor.on_status(running, gs.now)
    gs.heartbeat(victim)
    gs.advance(0.1)
    told = [(e.kind, e.uav_id) for e in gs.events[seen:] if e.uav_id == victim]
    assert told == [(EventKind.UAV_SILENT, victim), (EventKind.UAV_HEARD, victim)]
    back = fleet(gs)[victim]
    assert back.silent_s is None and back.silent_since_s is None and back.unknown_tasks == []
    assert not [e for e in gs.events if e.kind in (EventKind.ACTION_FAILED, EventKind.UAV_LOST)]
    assert (len(gs.sent), gs.replanner.stats.count) == (sent, replans)
    assert gs.replanner.plans[victim] == plan  # its work stayed with it
