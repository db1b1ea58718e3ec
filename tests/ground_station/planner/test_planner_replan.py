"""Incremental replanning: each event gives a valid plan and leaves the
routes it does not touch alone."""

from __future__ import annotations

import msgspec
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ground_station.planner import (
    DeliverJob,
    InspectJob,
    PlanningProblemError,
    Problem,
    Viewpoint,
    validate,
)
from ground_station.planner.replan import (
    ActionAdded,
    ActionCancelled,
    ActionChanged,
    BatteryLow,
    Session,
    TaskFinished,
    UavBack,
    UavLost,
    replan_once,
)
from linecrew.planner_tools.generator import generate

replace = msgspec.structs.replace
NEW = InspectJob(
    id="new",
    weight=5.0,
    waypoints=(Viewpoint(position_m=(5.0, 5.0, 3.0), service_s=5.0),),
)


def check(s: Session):
    p = s.plan()
    assert validate(s.problem, p) == []
    return p


def test_action_added_is_planned_and_other_routes_untouched() -> None:
    s = Session(generate(10, 30, 3))
    before = {u: r.steps for u, r in s.ctx.routes.items()}
    a = InspectJob(
        id="extra", waypoints=(Viewpoint(position_m=(600.0, 10.0, 30.0), service_s=20.0),)
    )
    p = s.apply(ActionAdded(action=a))
    assert validate(s.problem, p) == []
    assert any(st.action_id == "extra" for u in p.uavs for st in u.steps)
    untouched = [u for u, r in s.ctx.routes.items() if r.steps is before[u]]
    assert len(untouched) >= len(before) - 2


def test_cancel_removes_the_action(fig6: Problem) -> None:
    s = Session(fig6)
    p = s.apply(ActionCancelled(action_id="a3-monitor"))
    assert validate(s.problem, p) == []
    assert not any(st.kind == "monitor" for u in p.uavs for st in u.steps)


def test_change_replans_the_action(fig6: Problem) -> None:
    s = Session(fig6)
    mon = next(a for a in fig6.actions if a.id == "a3-monitor")
    p = s.apply(ActionChanged(action=replace(mon, duration_s=100.0)))
    assert validate(s.problem, p) == []
    ends = [st.end_s for u in p.uavs for st in u.steps if st.kind == "monitor"]
    starts = [st.arrive_s for u in p.uavs for st in u.steps if st.kind == "monitor"]
    assert max(ends) - min(starts) == pytest.approx(100.0)


def test_uav_lost_and_back(fig6: Problem) -> None:
    s = Session(fig6)
    p = s.apply(UavLost(uav_id="uav2"))
    assert validate(s.problem, p) == []
    assert p.uavs[1].steps == ()
    planned = {st.action_id for st in p.uavs[0].steps if st.action_id}
    unplaced = {x.action_id for x in p.unplaced}
    assert {a.id for a in fig6.actions} <= planned | unplaced
    p = s.apply(UavBack(uav=fig6.uavs[1]))
    assert validate(s.problem, p) == []
    assert p.unplaced == ()


def test_battery_low_sheds_work(fig6: Problem) -> None:
    s = Session(fig6)
    p = s.apply(BatteryLow(uav_id="uav2", energy_wh=25.0))
    assert validate(s.problem, p) == []
    first = p.uavs[1].steps[0]
    assert first.kind in ("recharge", "home", "wait") or first.energy_after_wh >= 20.0


def test_task_finished_marks_waypoint_done(fig6: Problem) -> None:
    s = Session(fig6)
    first = s.plan().uavs[1].steps[0]
    assert first.kind == "inspect"
    p = s.apply(TaskFinished(uav_id="uav2", position_m=first.position_m, energy_wh=95.0))
    assert validate(s.problem, p) == []
    a2 = next(a for a in s.problem.actions if a.id == "a2-inspect")
    assert first.index in a2.done


def test_unknown_references_raise(fig6: Problem) -> None:
    s = Session(fig6)
    with pytest.raises(PlanningProblemError):
        s.apply(ActionCancelled(action_id="nope"))
    with pytest.raises(PlanningProblemError):
        s.apply(UavLost(uav_id="ghost"))
    with pytest.raises(PlanningProblemError):
        s.apply(ActionAdded(action=replace(NEW, id="a2-inspect")))


def test_one_shot_replan(fig6: Problem) -> None:
    problem, p = replan_once(fig6, ActionAdded(action=NEW))
    assert validate(problem, p) == []
    assert any(st.action_id == "new" for u in p.uavs for st in u.steps)


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 1000), st.lists(st.integers(0, 6), min_size=1, max_size=6))
def test_random_event_sequences_keep_plans_valid(seed, kinds) -> None:
    problem = generate(6, 12, seed)
    extra = generate(6, 12, seed + 1).actions
    s = Session(problem)
    for n, kind in enumerate(kinds):
        uids = [u.id for u in s.problem.uavs]
        aids = [a.id for a in s.problem.actions]
        uid = uids[(seed + n) % len(uids)]
        if kind == 0:
            a = extra[n % len(extra)]
            if isinstance(a, DeliverJob):
                a = replace(a, tool_station="T0")
            s.apply(ActionAdded(action=replace(a, id=f"x{n}")))
        elif kind == 1 and aids:
            s.apply(ActionCancelled(action_id=aids[n % len(aids)]))
        elif kind == 2:
            s.apply(UavLost(uav_id=uid))
        elif kind == 3:
            u = next(u for u in s.problem.uavs if u.id == uid)
            s.apply(UavBack(uav=u))
        elif kind == 4:
            s.apply(BatteryLow(uav_id=uid, energy_wh=15.0))
        elif kind == 5 and uid in s.ctx.routes and s.ctx.routes[uid].tasks:
            t = s.ctx.routes[uid].tasks[0]
            s.apply(TaskFinished(uav_id=uid, position_m=t.pos, energy_wh=30.0))
        elif kind == 6 and aids:
            a = next(x for x in s.problem.actions if x.id == aids[-1])
            s.apply(ActionChanged(action=replace(a, weight=9.0)))
        check(s)


def _stop_after(polls: int):
    """A ``should_stop`` that says stop from its ``polls``-th call on; and the count."""
    calls = [0]

    def stop() -> bool:
        calls[0] += 1
        return calls[0] >= polls

    return stop, calls


def test_a_construction_from_scratch_stops_between_actions_when_told():
    problem = generate(4, 12, seed=3)
    stop, calls = _stop_after(5)
    assert Session.build_until(problem, None, stop) is None
    assert calls[0] == 5  # polled before each action, stopped at the fifth
    full = Session.build_until(problem, None, lambda: False)
    assert full is not None
    assert full.plan() == Session(problem).plan()
