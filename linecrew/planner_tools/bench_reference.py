"""Best-known plans for ``linecrew bench planner --reference-ms``.

Independent of the plan being measured as far as possible: long multi-seed
improvement runs of the complete planner (``search``), a long improvement
run of the plain paper heuristic (``paper-search``: another basin), and
with ``--reference cpsat`` OR-Tools CP-SAT (``reference``) seeded once with
the planner's plan (``cpsat-planner``) and once with the paper heuristic's
(``cpsat-paper``). The best of all is the reference; a CP-SAT OPTIMAL
proves the optimum of its model, a restriction of the problem (see
``reference``), so a heuristic may still beat a "proven" plan.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from ground_station.planner.api import plan, score
from ground_station.planner.model import Problem
from ground_station.planner.result import Solution
from ground_station.planner.routes import Options

SEARCH_SEEDS = 3
"""Long improvement runs of the complete planner (the budget is shared)."""


def deadline(ms: float) -> Callable[[], bool]:
    """A ``should_stop`` that turns true ``ms`` milliseconds from now."""
    end = time.perf_counter() + ms / 1000.0
    return lambda: time.perf_counter() >= end


def references(
    problem: Problem, improved: Solution, paper: Solution, budget_ms: float, cpsat: bool
) -> tuple[dict[str, Solution], dict[str, Any]]:
    """Each reference's plan by kind, and the CP-SAT statuses and bounds."""
    plans: dict[str, Solution] = {
        "search": min(
            (
                plan(problem, should_stop=deadline(budget_ms / SEARCH_SEEDS), seed=k)
                for k in range(SEARCH_SEEDS)
            ),
            key=score,
        ),
        "paper-search": plan(problem, Options(mode="paper"), should_stop=deadline(budget_ms)),
    }
    info: dict[str, Any] = {}
    if cpsat:
        from linecrew.planner_tools.reference import solve

        for kind, hint in (("cpsat-planner", improved), ("cpsat-paper", paper)):
            r = solve(problem, budget_ms / 1000.0, hint=hint)
            info[kind] = {
                "status": r.status,
                "detail": r.detail,
                "bound": r.score_bound,
                "hinted": r.hinted,
                "wall_s": r.wall_s,
                "score": score(r.plan)[1] if r.plan is not None else None,
            }
            if r.plan is not None:
                plans[kind] = r.plan
            if r.status == "UNSUPPORTED":
                break  # the same answer for the other seed
    return plans, info


def best_known(plans: dict[str, Solution], info: dict[str, Any]) -> dict[str, Any]:
    """The best reference: its kind and plan, the score CP-SAT proved optimal
    for its model (``optimum``, None if unproven) and the best lower bound."""
    kind = min(plans, key=lambda k: score(plans[k]))
    proven = [v["score"] for v in info.values() if v["status"] == "OPTIMAL"]
    bound = max((v["bound"] for v in info.values()), default=0.0)
    return {"kind": kind, "plan": plans[kind], "optimum": min(proven, default=None), "bound": bound}
