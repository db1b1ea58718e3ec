"""The planner's entry points."""

from __future__ import annotations

from collections.abc import Callable

from ground_station.planner.errors import PlanningProblemError
from ground_station.planner.export import export
from ground_station.planner.heuristic import build
from ground_station.planner.improve import improve
from ground_station.planner.load import check_problem
from ground_station.planner.model import Problem
from ground_station.planner.result import Plan
from ground_station.planner.routes import Options


def score(p: Plan) -> tuple[int, float]:
    """What improvement minimises: (unplaced parts, weighted completion + makespan)."""
    return len(p.unplaced), p.metrics.weighted_completion_s + p.metrics.makespan_s


def plan(
    problem: Problem,
    options: Options | None = None,
    *,
    should_stop: Callable[[], bool] | None = None,
    max_rounds: int = 0,
    seed: int = 0,
) -> Plan:
    """Plan ``problem``: the complete heuristic (or ``options.mode``), then,
    if ``should_stop`` or ``max_rounds`` is given, bounded improvement.

    With improvement, the plain paper heuristic is also run and the better of
    the two starts the search, and the result is never worse than either.
    ``should_stop`` is polled between improvement rounds: pass e.g. a
    deadline check built on the caller's clock. Pure and deterministic for a
    given sequence of ``should_stop`` answers. Raises ``PlanningProblemError``
    for invalid input; what cannot be placed is listed in ``Plan.unplaced``.
    """
    if not isinstance(problem, Problem):
        raise PlanningProblemError("$", "expected a Problem")
    check_problem(problem)
    options = options or Options()
    ctx = build(problem, options)
    if should_stop is None and max_rounds <= 0:
        return export(ctx)
    best = export(ctx)
    if options.mode != "paper":
        paper_ctx = build(problem, Options(mode="paper", max_split=options.max_split))
        paper = export(paper_ctx)
        if score(paper) < score(best):
            best, ctx = paper, paper_ctx
            ctx.options = options
    improve(ctx, should_stop or (lambda: False), max_rounds or 1_000_000_000, seed)
    out = export(ctx)
    return out if score(out) <= score(best) else best
