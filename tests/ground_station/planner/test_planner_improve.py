"""Improvement only ever returns a valid plan at least as good as its input
(and as the plain paper heuristic)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ground_station.planner import Options, plan, score, validate
from ground_station.planner.export import export
from ground_station.planner.heuristic import build
from ground_station.planner.improve import improve, objective
from linecrew.planner_tools.generator import generate


@settings(max_examples=8, deadline=None)
@given(st.integers(2, 8), st.integers(2, 16), st.integers(0, 10_000))
def test_improved_plan_is_valid_and_never_worse(n_uavs, n_actions, seed) -> None:
    problem = generate(n_uavs, n_actions, seed)
    base = plan(problem)
    paper = plan(problem, Options(mode="paper"))
    better = plan(problem, max_rounds=30)
    assert validate(problem, better) == []
    assert score(better) <= score(base)
    assert score(better) <= score(paper)


def test_improvement_rounds_only_accept_strict_gains() -> None:
    problem = generate(6, 20, 4)
    ctx = build(problem)
    before = objective(ctx)
    accepted = improve(ctx, lambda: False, max_rounds=40)
    after = objective(ctx)
    assert after <= before
    assert (accepted > 0) == (after < before)
    assert validate(problem, export(ctx)) == []


def test_should_stop_is_honoured() -> None:
    problem = generate(6, 20, 5)
    calls = []

    def stop() -> bool:
        calls.append(1)
        return len(calls) > 3

    ctx = build(problem)
    improve(ctx, stop)
    assert len(calls) == 4


def test_improvement_is_deterministic() -> None:
    problem = generate(5, 15, 9)
    assert plan(problem, max_rounds=25) == plan(problem, max_rounds=25)


def test_time_bounded_improvement_with_restarts_is_valid_and_never_worse() -> None:
    for seed in (1, 2):
        problem = generate(5, 20, seed)
        calls = iter(range(60))

        def stop(calls=calls) -> bool:
            return next(calls, None) is None  # a deterministic "deadline"

        better = plan(problem, should_stop=stop)
        assert validate(problem, better) == []
        assert score(better) <= score(plan(problem))
        assert score(better) <= score(plan(problem, Options(mode="paper")))


def test_randomised_rounds_find_early_hand_overs() -> None:
    # Three watches of 900-1200 s, three UAVs on 55-70 Wh: the greedy keeps
    # each UAV on a watch until its battery forces it off (score 4135); CP-SAT
    # found 3039 by handing over earlier. Randomised rounds get within 8 %.
    problem = generate(3, 4, 1)
    greedy = plan(problem)
    better = plan(problem, max_rounds=1000)
    assert score(greedy)[1] > 4000
    assert score(better)[1] < 3039 * 1.08
    assert validate(problem, better) == []


def test_time_bounded_improvement_runs_independent_restarts() -> None:
    problem = generate(3, 4, 1)
    polls = iter(range(3000))
    out = plan(problem, should_stop=lambda: next(polls) >= 2500)
    assert validate(problem, out) == []
    assert score(out) <= score(plan(problem, max_rounds=600))


def test_objective_is_the_exported_score_home_legs_included() -> None:
    # Here UAVs recharge before flying home at the end; an objective without
    # the home legs was 400 s below the plan's score and misled the search.
    problem = generate(5, 20, 1)
    ctx = build(problem)
    improve(ctx, lambda: False, max_rounds=50)
    exported = export(ctx)
    assert any(u.steps[-2].kind == "recharge" for u in exported.uavs if len(u.steps) > 1)
    assert objective(ctx) == (score(exported)[0], pytest.approx(score(exported)[1]))
