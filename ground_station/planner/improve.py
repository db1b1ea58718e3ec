"""Bounded-time improvement: ruin and recreate over the heuristic's plan.

Each round removes one to three related actions (a seed action: random, one
of the costliest, or one of the last of the UAV that finishes last; and
actions scheduled next to it on the same UAVs) and re-inserts them with the
heuristic's cheapest insertion, now allowed between any two actions of a
route: in queue order, or, in half the rounds, randomised (shuffled order,
suitability ignored, random split counts, monitoring segments cut short and
random start times), which the CP-SAT reference showed the greedy misses:
hand-overs before the battery forces them, and splits onto a second UAV.
The objective is first fewer unplaced parts, then a smaller weight-averaged
completion time plus makespan (seconds), home legs included. The caller
bounds the time: ``should_stop`` is polled between rounds (the library reads
no clock) and ``max_rounds`` caps work.
Deterministic for a given ``seed`` and sequence of ``should_stop`` answers.
"""

from __future__ import annotations

import random
from collections.abc import Callable

from msgspec.structs import replace

from ground_station.planner import heuristic
from ground_station.planner.ending import end_steps
from ground_station.planner.model import CostWeights
from ground_station.planner.removal import remove_in_place
from ground_station.planner.routes import Ctx, queue_order
from ground_station.planner.simulate import Task

THRESHOLD = 0.002
"""Accept a round up to this fraction worse than the current state."""
RESTART_AFTER = 60
"""Rounds without a new best before going back to the best state."""
LATE_P = 0.2
"""Share of rounds that move one of the last tasks of the UAV that finishes
last (the makespan), rather than a high-cost or random action."""
RANDOM_P = 0.5
"""Share of rounds that re-insert with randomised choices (``_recreate``)."""


def objective(ctx: Ctx) -> tuple[int, float]:
    """(unplaced parts, weight-averaged completion + makespan) of the state.

    The makespan counts each UAV's way home, with a recharge first where one
    is needed (as ``export`` adds it, but without pad contention between the
    UAVs going home).
    """
    now = ctx.problem.now_s
    comp: dict[str, float] = {}
    makespan = now
    for r in ctx.routes.values():
        home, _ = end_steps(r.kin, ctx.site, ctx.pads, r.tail(), None)
        t = home[-1][3] if home else r.tail()[0]
        if t > makespan:
            makespan = t
        for s in r.steps:
            aid = s[6]
            if aid is not None and s[3] > comp.get(aid, -1e300):
                comp[aid] = s[3]
    failed = sum(len(v) for v in ctx.unplaced.values())
    weighted = 0.0
    for aid, c in comp.items():
        if aid not in ctx.unplaced:
            weighted += ctx.actions[aid].weight * (c - now)
    total = sum(a.weight for a in ctx.problem.actions) or 1.0
    return failed, weighted / total + makespan - now


def _related(ctx: Ctx, seed: str, rng: random.Random, size: int) -> list[str]:
    """The seed action plus actions adjacent to it on the UAVs it uses."""
    out = [seed]
    for uid in ctx.placed_uavs(seed):
        tasks = ctx.routes[uid].tasks
        for i, t in enumerate(tasks):
            if t.action_id != seed:
                continue
            for j in (i - 1, i + 1):
                if 0 <= j < len(tasks):
                    aid = tasks[j].action_id
                    if aid not in out and (aid, tasks[j].index) not in ctx.pinned:
                        out.append(aid)
    head, rest = out[:1], out[1:]
    rng.shuffle(rest)
    return head + rest[: size - 1]


def _late(ctx: Ctx) -> list[str]:
    """Actions among the last tasks of the UAV that finishes last."""
    r = max(ctx.routes.values(), key=lambda r: r.tail()[0])
    return [t.action_id for t in r.tasks[-3:] if (t.action_id, t.index) not in ctx.pinned]


def _remove(ctx: Ctx, aid: str) -> bool:
    for uid in ctx.placed_uavs(aid):

        def mine(t: Task) -> bool:
            return t.action_id == aid and (aid, t.index) not in ctx.pinned

        if ctx.remove_tasks(uid, mine) is None and remove_in_place(ctx, uid, mine) is None:
            return False
    ctx.unplaced.pop(aid, None)
    return True


def _contributions(ctx: Ctx) -> list[tuple[float, str]]:
    """Per placed action, weight x completion (the worst are the best to move)."""
    now = ctx.problem.now_s
    comp: dict[str, float] = {}
    for r in ctx.routes.values():
        for s in r.steps:
            aid = s[6]
            if aid is not None and s[3] > comp.get(aid, -1e300):
                comp[aid] = s[3]
    return sorted(((ctx.actions[a].weight * (c - now), a) for a, c in comp.items()), reverse=True)


def improve(
    ctx: Ctx,
    should_stop: Callable[[], bool],
    max_rounds: int = 1_000_000,
    seed: int = 0,
) -> int:
    """Improve ``ctx`` in place; returns the number of rounds that improved the
    best state. Rounds may accept a slightly worse state (threshold
    acceptance, ``THRESHOLD``) to escape local optima; the best state seen is
    restored at the end, so the result is never worse than the input."""
    rng = random.Random(seed)
    ids = [a.id for a in ctx.problem.actions]
    if not ids or not ctx.routes:
        return 0
    best = current = objective(ctx)
    best_snap = None
    accepted = 0
    stale = 0
    worst: list[tuple[float, str]] = []
    weights = ctx.weights
    ctx.anywhere = True
    try:
        for n in range(max_rounds):
            if should_stop():
                break
            if n % 25 == 0:
                worst = _contributions(ctx)[:20]
            x = rng.random()
            late = _late(ctx) if x < LATE_P else []
            if late:
                seed_id = rng.choice(late)
            elif worst and x < 0.5:
                seed_id = rng.choice(worst)[1]
            else:
                seed_id = rng.choice(ids)
            group = _related(ctx, seed_id, rng, rng.choice((1, 1, 2, 3)))
            snap = ctx.snapshot()
            ok = all(_remove(ctx, aid) for aid in group)
            if ok:
                _recreate(ctx, group, rng, weights)
                score = objective(ctx)
                if score < best:
                    best = current = score
                    best_snap = None
                    accepted += 1
                    stale = 0
                    continue
                if score[0] == current[0] and score[1] <= current[1] * (1 + THRESHOLD):
                    if best_snap is None:
                        best_snap = snap
                    current = score
                    stale += 1
                    if stale > RESTART_AFTER:
                        ctx.restore(best_snap)
                        best_snap, current, stale = None, best, 0
                    continue
            ctx.restore(snap)
            stale += 1
            if stale > RESTART_AFTER and best_snap is not None:
                ctx.restore(best_snap)
                best_snap, current, stale = None, best, 0
        if best_snap is not None:
            ctx.restore(best_snap)
    finally:
        ctx.anywhere, ctx.rng, ctx.weights = False, None, weights
    return accepted


def _recreate(ctx: Ctx, group: list[str], rng: random.Random, weights: CostWeights) -> None:
    """Re-insert ``group``: in queue order with the heuristic's own choices,
    or (``RANDOM_P``) randomised: shuffled order, suitability ignored and
    random monitoring choices (``monitor`` reads ``ctx.rng``)."""
    actions = queue_order([ctx.actions[aid] for aid in group])
    ctx.rng, ctx.weights = None, weights
    if rng.random() < RANDOM_P:
        ctx.rng = rng
        rng.shuffle(actions)
        if rng.random() < 0.5:
            ctx.weights = replace(weights, suitability_s=0.0)
    for a in actions:
        heuristic.place_action(ctx, a)
