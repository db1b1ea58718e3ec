"""The planner's entry points."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import NamedTuple

from msgspec.structs import replace

from ground_station.planner.errors import PlanningProblemError
from ground_station.planner.export import export
from ground_station.planner.heuristic import build
from ground_station.planner.improve import Score, improve
from ground_station.planner.load import check_problem
from ground_station.planner.model import CostWeights, Problem
from ground_station.planner.result import Solution
from ground_station.planner.routes import Ctx, Options


class Variant(NamedTuple):
    """A differently tuned construction: factors on the suitability and
    approach weights, and ``Options.resource_factor`` and ``max_eval``."""

    suitability_factor: float
    resource_factor: float
    max_eval: int
    approach_factor: float


VARIANTS: tuple[Variant, ...] = (
    Variant(0.5, 0.0, 3, 1.0),
    Variant(1.0, 0.3, 6, 1.6),
    Variant(0.5, 0.3, 6, 0.4),
    Variant(1.0, 0.0, 6, 1.0),
    Variant(0.5, 1.0, 3, 1.6),
    Variant(2.5, 0.3, 6, 1.0),
    Variant(1.0, 1.0, 3, 0.4),
    Variant(0.5, 0.0, 6, 1.6),
)
RUN_ROUNDS = 600
"""Time-bounded improvement: rounds per independent run. Runs restart from
a construction with new seeds and the best is kept: one run's result
varies a lot with its seed, so several short runs beat one long one (on the
corridor bench, 600-round runs cut the worst 1 s gap to the best-known from
about 20 % to 12 %)."""
START_COUNT = 3
"""Time-bounded improvement: runs start in turn from this many of the best
constructions (the best one alone is sometimes a poor basin: on one corridor
instance every run from it stayed 10 % above runs from the second best)."""
RESTART_WORK = 3000
"""Automatic restarts: ``RESTART_WORK // (actions x UAVs)`` variants (all for
small instances, none from about 20 UAVs x 150 actions up)."""


def score(p: Solution) -> Score:
    """What improvement minimises: (unplaced parts, weight-averaged completion
    time + makespan), both in seconds from ``now_s`` and of similar size, so
    neither the priority-weighted service nor the end of the mission is
    sacrificed to the other."""
    return Score(len(p.unplaced), p.metrics.mean_completion_s + p.metrics.makespan_s)


def variants(options: Options, weights: CostWeights) -> list[Options]:
    """Alternative constructions tried when there is time to improve: the
    greedy is sensitive to its knobs, so a few differently tuned runs often
    find a much better start than local search alone."""
    out = []
    for v in VARIANTS:
        w = replace(
            weights,
            suitability_s=weights.suitability_s * v.suitability_factor,
            approach=weights.approach * v.approach_factor,
        )
        out.append(
            dataclasses.replace(
                options, weights=w, resource_factor=v.resource_factor, max_eval=v.max_eval
            )
        )
    return out


def plan(
    problem: Problem,
    options: Options | None = None,
    *,
    should_stop: Callable[[], bool] | None = None,
    max_rounds: int = 0,
    seed: int = 0,
) -> Solution:
    """Plan ``problem``: the complete heuristic (or ``options.mode``), then,
    if ``should_stop`` or ``max_rounds`` is given, improvement.

    Improvement first builds the plain paper heuristic's plan and a few
    differently tuned constructions (``variants``) while ``should_stop`` stays
    false, then runs local search (``improve``) in independent runs of
    ``RUN_ROUNDS`` rounds from the ``START_COUNT`` best of them in turn while
    time remains (one run of ``max_rounds`` from the best if that is given);
    the result is never worse than the complete or the paper heuristic's plan.
    ``should_stop`` is polled between constructions and rounds: pass e.g. a
    deadline check built on the caller's clock. Pure and deterministic for a
    given sequence of ``should_stop`` answers. Raises ``PlanningProblemError``
    for invalid input; what cannot be placed is listed in ``Solution.unplaced``.
    """
    if not isinstance(problem, Problem):
        raise PlanningProblemError("$", "expected a Problem")
    check_problem(problem)
    options = options or Options()
    ctx = build(problem, options)
    if should_stop is None and max_rounds <= 0:
        return export(ctx)
    stop = should_stop or (lambda: False)
    starts, best = _starts(problem, options, ctx, stop, max_rounds)
    if max_rounds > 0:
        ctx = starts[0].ctx
        improve(ctx, stop, max_rounds, seed)
        out = export(ctx)
        return out if score(out) <= score(best) else best
    tops = [(s.ctx, s.ctx.snapshot()) for s in starts[:START_COUNT]]
    run = 0
    while not stop():  # independent runs from the best starts in turn
        ctx, snap = tops[run % len(tops)]
        ctx.restore(snap)
        improve(ctx, stop, RUN_ROUNDS, seed + run)
        run += 1
        out = export(ctx)
        if score(out) < score(best):
            best = out
    return best


class _Start(NamedTuple):
    """A construction improvement may start from, and its plan's score."""

    score: Score
    ctx: Ctx


def _starts(
    problem: Problem, options: Options, ctx: Ctx, stop: Callable[[], bool], max_rounds: int
) -> tuple[list[_Start], Solution]:
    """The constructions to improve, best first (``ctx``, the complete
    heuristic's, wins ties), and the best plan among them; unless ``options``
    is paper mode, the paper heuristic's too and, time-bounded, the
    ``variants`` (as many as ``stop`` lets build)."""
    best = export(ctx)
    starts = [_Start(score(best), ctx)]
    if options.mode != "paper":
        others = [Options(mode="paper", max_split=options.max_split)]
        if max_rounds <= 0:  # time-bounded: also try other tunings
            count = options.restarts
            if count is None:  # by size: each costs about one construction
                work = len(problem.actions) * max(1, len(problem.uavs))
                count = min(len(VARIANTS), RESTART_WORK // max(1, work))
            others += variants(options, options.weights or problem.weights)[:count]
        for i, opt in enumerate(others):
            if i > 0 and stop():
                break
            other_ctx = build(problem, opt)
            other = export(other_ctx)
            other_ctx.options = options
            starts.append(_Start(score(other), other_ctx))
            if score(other) < score(best):
                best = other
    starts.sort(key=lambda s: s.score)  # stable: the complete heuristic wins ties
    return starts, best
