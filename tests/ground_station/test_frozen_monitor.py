"""An improvement never covers a monitoring slot twice when a segment of it
is frozen (chaos seed 3: a slot held by two UAVs for 161 s). The live plan
pins the frozen segments' (action, slot); a round that ruins the action
keeps them, and re-placing the action gives only its other slots, over
the kept window, instead of a second coverage beside them."""

from __future__ import annotations

import collections
import itertools

import msgspec
import pytest

from ground_station.live_plan import LivePlan
from ground_station.planner import Problem, Solution, validate
from ground_station.planner.export import export
from ground_station.planner.heuristic import build
from ground_station.planner.improve import improve
from ground_station.planner.model import MonitorJob
from linecrew.planner_tools.generator import generate


def doubled(plan: Solution) -> list[tuple]:
    """Pairs of segments of one slot that overlap (on station) by over 1 s."""
    segments = collections.defaultdict(list)
    for uav in plan.uavs:
        for step in uav.steps:
            if step.kind == "monitor":
                key = (step.action_id, step.index)
                segments[key].append((step.arrive_s, step.end_s, uav.uav_id))
    return [
        (key, a, b)
        for key, segs in segments.items()
        for a, b in itertools.combinations(sorted(segs), 2)
        if min(a[1], b[1]) - max(a[0], b[0]) > 1.0
    ]


def slot_zero_of_each_monitor(problem: Problem) -> set[tuple[str, int | None]]:
    return {(a.id, 0) for a in problem.actions if isinstance(a, MonitorJob)}


@pytest.mark.parametrize(("problem_seed", "seed"), [(7, 2), (14, 0), (14, 1), (14, 2)])
def test_the_live_plan_improves_around_a_frozen_segment_without_a_second_coverage(
    problem_seed, seed
):
    problem = generate(4, 8, problem_seed)
    live = LivePlan()
    live.replan(lambda _base: problem, 0.0, {u.id: 1.0 for u in problem.uavs})
    assert doubled(live.session.plan()) == []
    candidate = live.improve(60, seed, slot_zero_of_each_monitor(problem))
    assert candidate is not None
    assert doubled(candidate.plan) == []
    assert validate(problem, candidate.plan) == []


@pytest.mark.parametrize(("problem_seed", "seed"), [(6, 0), (12, 1)])
def test_a_two_uav_monitor_with_one_slot_frozen_gets_its_other_slot_in_step(problem_seed, seed):
    problem = generate(5, 12, problem_seed)
    actions = tuple(
        msgspec.structs.replace(a, k=2) if isinstance(a, MonitorJob) else a for a in problem.actions
    )
    problem = msgspec.structs.replace(problem, actions=actions)
    ctx = build(problem)
    ctx.pinned |= slot_zero_of_each_monitor(problem)
    improve(ctx, lambda: False, max_rounds=60, seed=seed)
    plan = export(ctx)
    assert doubled(plan) == []
    assert validate(problem, plan) == []  # every slot covered, all from one start
