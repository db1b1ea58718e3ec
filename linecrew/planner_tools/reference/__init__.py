"""A reference optimiser for small planning problems, with OR-Tools CP-SAT.

Only ``linecrew bench planner`` uses it, to measure how far the planner is
from the best plan an exact solver finds. OR-Tools is the optional ``bench``
extra (``pip install 'linecrew[bench]'``), imported lazily; the planner
never depends on it.

What it models (``cpsat.Model``), so that every solution is a plan the
validator accepts:

- one routing circuit per UAV over service nodes (each pending waypoint,
  each monitoring slot split into up to ``SEGMENTS`` consecutive segments,
  each delivery's pick and drop) plus ``RECHARGES`` optional recharge visits
  per UAV and station, closed by the flight to the home station (so a UAV
  may cross several charges to get home);
- waypoints in any order and any split between UAVs, interleaved with other
  work; a pick and its drop on one UAV with anything between (other work,
  recharges), one tool carried at a time;
- monitoring slots of an action start together at ``T0`` and segments hand
  over with no gap; pads are shared (cumulative); at a shared hover point
  (a tool station, a worker, coincident waypoints) one UAV at a time;
- times are whole seconds (flights rounded up), energy whole joules (powers
  rounded up), charging linear in time; a UAV waits hovering where it is
  before flying to its next task, landed on a pad after a recharge, landed
  at a station for a pad;
- the objective is ``api.score`` times the total weight:
  sum(weight x completion) + total weight x makespan.

What it does not model, so OPTIMAL proves the optimum of this restriction
only: fractional seconds (each flight may cost up to 1 s more than in the
planner), more than ``SEGMENTS`` segments per slot or ``RECHARGES`` visits
per station, waiting at the next task's point rather than the last one,
ending away from home (``end: any_station``), and running tasks, held tools
or unavailable UAVs (refused as UNSUPPORTED).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import msgspec

from ground_station.planner.api import score
from ground_station.planner.model import Problem
from ground_station.planner.result import Solution
from linecrew.planner_tools.reference.cpsat import Model
from linecrew.planner_tools.reference.nodes import TICK_S, build_nodes, unsupported
from linecrew.planner_tools.reference.steps import export, route_literals

if TYPE_CHECKING:
    from ortools.sat.python.cp_model import CpSolver

__all__ = ["Reference", "solve"]


class Reference(msgspec.Struct, frozen=True, kw_only=True):
    """The solver's answer: ``status`` (OPTIMAL, FEASIBLE, INFEASIBLE,
    UNKNOWN or UNSUPPORTED with ``detail``), its best plan, the proven
    lower bound on the score (seconds, like ``api.score``) and whether the
    hint's routes seeded the search."""

    status: str
    detail: str = ""
    plan: Solution | None = None
    score_bound: float = 0.0
    wall_s: float = 0.0
    hinted: bool = False


HORIZON_SLACK = 1.1
"""With a hint, makespans are cut at this factor of the hint's score (plus
``HORIZON_PAD_S``): a plan of a better score cannot have a longer makespan."""
HORIZON_PAD_S = 600.0
SEED_SHARE = 0.25
"""Share of the time limit (at most ``SEED_MAX_S``) spent timing the hint's
fixed routes in the model, the complete solution that seeds the search."""
SEED_MAX_S = 20.0


def solve(
    problem: Problem, time_limit_s: float = 30.0, workers: int = 2, hint: Solution | None = None
) -> Reference:
    """Solve ``problem`` with CP-SAT within ``time_limit_s`` seconds.

    ``hint`` (e.g. the planner's or the paper heuristic's plan) seeds the
    search: its routes are fixed and timed in the model first, and that
    solution is the search's starting point. It also bounds the makespan
    (``HORIZON_SLACK``); OPTIMAL is reported only when that cut cannot have
    removed a better plan."""
    from ortools.sat.python import cp_model

    nodes, segments = build_nodes(problem)
    why = unsupported(problem, nodes)
    if why:
        return Reference(status="UNSUPPORTED", detail=why)
    horizon_s = None
    if hint is not None and not hint.unplaced:
        horizon_s = score(hint)[1] * HORIZON_SLACK + HORIZON_PAD_S
    m = Model(cp_model, problem, nodes, segments, horizon_s)
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = workers
    t0 = time.perf_counter()
    hinted = hint is not None and _seed(m, solver, hint, min(SEED_MAX_S, time_limit_s * SEED_SHARE))
    solver.parameters.max_time_in_seconds = max(0.1, time_limit_s - (time.perf_counter() - t0))
    code = solver.solve(m.model)
    status = solver.status_name(code)
    if code == cp_model.OPTIMAL and solver.objective_value > m.total_weight * m.horizon:
        status = "FEASIBLE"  # the horizon cut may hide a better plan
    total_w = m.total_weight
    out = Reference(
        status=status,
        score_bound=solver.best_objective_bound * TICK_S / total_w if total_w else 0.0,
        wall_s=time.perf_counter() - t0,
        hinted=hinted,
    )
    if code in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        out = msgspec.structs.replace(out, plan=export(m, solver))
    return out


def _seed(m: Model, solver: CpSolver, hint: Solution, limit_s: float) -> bool:
    """Time ``hint``'s routes in the model and hint that whole solution."""
    lits = route_literals(m, hint)
    if lits is None:
        return False
    m.model.add_assumptions(lits)
    solver.parameters.max_time_in_seconds = limit_s
    code = solver.solve(m.model)
    m.model.clear_assumptions()
    if solver.status_name(code) not in ("OPTIMAL", "FEASIBLE"):
        return False
    values = list(solver.response_proto.solution)
    m.model.clear_hints()
    m.model.proto.solution_hint.vars.extend(range(len(values)))
    m.model.proto.solution_hint.values.extend(values)
    return True
