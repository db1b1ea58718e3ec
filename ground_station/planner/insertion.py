"""Cheapest insertion of a part (a few tasks) into some UAV's route.

complete mode tries each capable UAV at the end of its route and in the idle
gaps before its anchored (monitoring) tasks, ordered by a lower bound of the
cost so most candidates are never simulated. paper mode only appends and
ranks UAVs by the paper's distance cost.
"""

from __future__ import annotations

from collections.abc import Callable
from math import dist
from typing import NamedTuple

import msgspec

from ground_station.planner import costs
from ground_station.planner.model import Vec3
from ground_station.planner.routes import Ctx, GapCache
from ground_station.planner.simulate import Sim, State, Visit

MIN_GAP_S = 5.0
MAX_GAP_EVAL = 2
"""Idle gaps (before anchored tasks) simulated per part, best bounds first."""
MAX_ANYWHERE_EVAL = 4
"""Mid-route positions simulated per part while improving."""


class Choice(NamedTuple):
    """A simulated insertion: its cost, where (``pos`` in ``uid``'s route, or
    before its running task if ``preempt``), the tasks and their simulation,
    the part's finish and the delay pushed onto the UAV's later tasks."""

    cost: float
    uid: str
    pos: int
    tasks: list[Visit]
    sim: Sim
    finish_s: float
    delay_s: float
    preempt: bool = False


def preemption(ctx: Ctx, uid: str, action_id: str) -> float | None:
    """J3 of interrupting ``uid``'s running task for ``action_id``; None if
    it has none or the new action does not have a strictly higher weight."""
    r = ctx.routes[uid]
    if not r.tasks or (r.tasks[0].action_id, r.tasks[0].index) not in ctx.pinned:
        return None
    running = ctx.actions[r.tasks[0].action_id].weight
    new = ctx.actions[action_id].weight
    return costs.j3_interrupt(running, new) if new > running else None


def gap_positions(ctx: Ctx, uid: str) -> list[int]:
    """Indices of anchored tasks preceded by an idle gap worth filling (and,
    while improving, every boundary between two actions)."""
    r = ctx.routes[uid]
    anywhere = ctx.anywhere
    cache = r.gap_cache
    if cache is not None and cache.tasks is r.tasks and cache.anywhere == anywhere:
        return cache.positions
    out: list[int] = []
    speed = r.kin.speed_mps
    prev = None
    for i, t in enumerate(r.tasks):
        boundary = anywhere and prev is not None and t.action_id != prev and i > 0
        prev = t.action_id
        if t.anchor_s is None:
            if boundary and (t.action_id, t.index) not in ctx.pinned:
                out.append(i)
            continue
        st = r.state_before(i)
        if t.anchor_s - st.t - dist(st.pos, t.pos) / speed > MIN_GAP_S:
            out.append(i)
    r.gap_cache = GapCache(r.tasks, anywhere, out)
    return out


_Bound = tuple[float, str, int]
"""A lower bound of the cost of inserting at a position of a UAV's route:
(cost, uid, position; -1 before the running task). A plain tuple, unpacked
where used: ``list.sort`` compares exact tuples several times faster than
Structs or NamedTuples."""


class _Terms(msgspec.Struct, frozen=True, gc=False):
    """A UAV's J1 (suitability) and J3 (continuation) for the part."""

    suit: float
    j3: float


def _bounds(
    ctx: Ctx,
    uid: str,
    action_id: str,
    start: Vec3,
    end: Vec3,
    release_s: float,
    part_s: float,
    terms: _Terms,
) -> list[_Bound]:
    """Lower bounds of inserting a part (``start`` .. ``end``, ``part_s``
    long) at each position of ``uid``'s route (its end, its gaps, and before
    a running task it may interrupt), leaving out positions where it cannot
    fit before the next anchored task."""
    r = ctx.routes[uid]
    w = ctx.weights
    now = ctx.problem.now_s
    tasks, states = r.tasks, r.states
    n = len(tasks)
    speed = r.kin.speed_mps
    travel, approach = w.travel, w.approach
    suit, jv = terms.suit, terms.j3
    # costs.complete_cost(w, suit, finish, now, 0.0, jv), unrolled
    suit_cost, j3_cost = w.suitability_s * suit, w.interruption_s * jv
    out = []
    for pos in (n, *gap_positions(ctx, uid)):
        st = states[pos - 1] if pos > 0 else r.init
        d0 = dist(st.pos, start)
        fin = st.t + d0 / speed
        if fin < release_s:
            fin = release_s
        fin += part_s
        if pos < n:
            nxt = tasks[pos]
            anchor = nxt.anchor_s
            if anchor is not None and fin + dist(end, nxt.pos) / speed > anchor:
                continue
        lb = suit_cost + travel * (fin - now) + j3_cost
        out.append((lb + approach * d0 / speed, uid, pos))
    interrupt = preemption(ctx, uid, action_id) if ctx.pinned else None
    if interrupt is not None:
        fin = max(r.init.t + dist(r.init.pos, start) / speed, release_s) + part_s
        out.append((costs.complete_cost(w, suit, fin, now, 0.0, jv + interrupt), uid, -1))
    return out


def best_insertion(
    ctx: Ctx,
    kind: str,
    action_id: str,
    start: Vec3,
    work_s: float,
    release_s: float,
    make: Callable[[State], list[Visit]],
    uids: list[str] | None = None,
    end: Vec3 | None = None,
    path_m: float = 0.0,
) -> tuple[Choice | None, str]:
    """Best (uid, position) for the tasks ``make(state)`` builds; or a reason.

    ``work_s`` (service time) and ``path_m`` (flight inside the part) feed the
    lower bounds that decide which candidates are simulated at all."""
    uids = ctx.capable(kind) if uids is None else uids
    if not uids:
        return None, "no_capable_uav"
    terms: dict[str, _Terms] = {}
    cands: list[_Bound] = []
    for uid in uids:
        r = ctx.routes[uid]
        terms[uid] = t = _Terms(r.kin.caps[kind], costs.j3(ctx.running.get(uid), action_id))
        if ctx.options.mode == "paper":
            cost = costs.paper_cost(ctx.weights, t.suit, r.tail(), start, t.j3)
            cands.append((cost, uid, len(r.tasks)))
        else:
            part_s = work_s + path_m / r.kin.speed_mps
            cands += _bounds(ctx, uid, action_id, start, end or start, release_s, part_s, t)
    cands.sort()
    return _cheapest(ctx, cands, terms, action_id, start, make), "battery_infeasible"


def _cheapest(
    ctx: Ctx,
    cands: list[_Bound],
    terms: dict[str, _Terms],
    action_id: str,
    start: Vec3,
    make: Callable[[State], list[Visit]],
) -> Choice | None:
    """Simulate candidates in order of their bounds until no later one can
    win or the evaluation budget (``Options.max_eval`` route ends, a few
    gaps) is spent; the cheapest that fits (paper mode: the first)."""
    paper = ctx.options.mode == "paper"
    max_eval = ctx.options.max_eval
    max_gaps = MAX_ANYWHERE_EVAL if ctx.anywhere else MAX_GAP_EVAL
    best: Choice | None = None
    evaluated = gaps = 0
    for lb, uid, pos in cands:
        if evaluated >= (max_eval if best is not None else 3 * max_eval):
            break
        if best is not None and lb >= best.cost:
            break
        if pos < len(ctx.routes[uid].tasks):
            if gaps >= max_gaps:
                continue
            gaps += 1
        else:
            evaluated += 1
        choice = _simulated(ctx, uid, pos, lb, terms[uid], action_id, start, make)
        if choice is None:
            continue
        if best is None or choice.cost < best.cost:
            best = choice
        if paper:
            break
    return best


def _simulated(
    ctx: Ctx,
    uid: str,
    pos: int,
    lb: float,
    terms: _Terms,
    action_id: str,
    start: Vec3,
    make: Callable[[State], list[Visit]],
) -> Choice | None:
    """The insertion at ``pos`` (-1: before the running task) simulated and
    costed (paper mode: its bound ``lb``); None if it does not fit."""
    r = ctx.routes[uid]
    preempt = pos < 0
    pos = max(pos, 0)
    tasks = make(r.state_before(pos))
    sim = ctx.try_preempt(uid, tasks) if preempt else ctx.try_insert(uid, pos, tasks)
    if isinstance(sim, str):
        return None
    finish = sim.states[len(tasks) - 1].t
    if pos >= len(r.tasks) or sim.old_next >= 0:
        delay = 0.0
    else:
        delay = max(0.0, sim.states[-1].t - r.tail().t)
    if ctx.options.mode == "paper":
        cost = lb
    else:
        suit, jv = terms.suit, terms.j3
        if preempt:
            jv += preemption(ctx, uid, action_id) or 0.0
        w = ctx.weights
        cost = costs.complete_cost(w, suit, finish, ctx.problem.now_s, delay, jv)
        st = r.state_before(pos)
        cost += w.approach * dist(st.pos, start) / r.kin.speed_mps
    return Choice(cost, uid, pos, tasks, sim, finish, delay, preempt)


def apply(ctx: Ctx, choice: Choice) -> None:
    """Commit ``choice``."""
    if choice.preempt:
        ctx.commit_preempt(choice.uid, choice.tasks, choice.sim)
    else:
        ctx.commit(choice.uid, choice.pos, choice.tasks, choice.sim)
