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
from typing import NamedTuple

from msgspec.structs import replace

from ground_station.planner import heuristic
from ground_station.planner.ending import end_steps
from ground_station.planner.model import CostWeights
from ground_station.planner.removal import remove
from ground_station.planner.routes import Ctx, Snapshot, queue_order
from ground_station.planner.simulate import Visit

THRESHOLD = 0.002
"""Accept a round up to this fraction worse than the current state."""
RESTART_AFTER = 60
"""Rounds without a new best before going back to the best state."""
LATE_P = 0.2
"""Share of rounds that move one of the last tasks of the UAV that finishes
last (the makespan), rather than a high-cost or random action."""
RANDOM_P = 0.5
"""Share of rounds that re-insert with randomised choices (``_recreate``)."""


class Score(NamedTuple):
    """What improvement minimises, in this order: unplaced parts, then
    weight-averaged completion + makespan (s)."""

    unplaced: int
    cost_s: float


def objective(ctx: Ctx) -> Score:
    """(unplaced parts, weight-averaged completion + makespan) of the state.

    The makespan counts each UAV's way home, with a recharge first where one
    is needed (as ``export`` adds it, but without pad contention between the
    UAVs going home).
    """
    now = ctx.problem.now_s
    makespan = now
    for r in ctx.routes.values():
        home, _ = end_steps(r.kin, ctx.site, ctx.pads, r.tail(), None)
        t = home[-1].end_s if home else r.tail().t
        if t > makespan:
            makespan = t
    failed = sum(len(v) for v in ctx.unplaced.values())
    weighted = 0.0
    for aid, c in _completions(ctx).items():
        if aid not in ctx.unplaced:
            weighted += ctx.actions[aid].weight * (c - now)
    total = sum(a.weight for a in ctx.problem.actions) or 1.0
    return Score(failed, weighted / total + makespan - now)


def _completions(ctx: Ctx) -> dict[str, float]:
    """Per placed action, the end of its last step."""
    comp: dict[str, float] = {}
    for r in ctx.routes.values():
        for s in r.steps:
            aid = s.action_id
            if aid is not None and s.end_s > comp.get(aid, -1e300):
                comp[aid] = s.end_s
    return comp


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
    r = max(ctx.routes.values(), key=lambda r: r.tail().t)
    return [t.action_id for t in r.tasks[-3:] if (t.action_id, t.index) not in ctx.pinned]


def _remove(ctx: Ctx, aid: str) -> bool:
    for uid in ctx.placed_uavs(aid):

        def mine(t: Visit) -> bool:
            return t.action_id == aid and (aid, t.index) not in ctx.pinned

        if not remove(ctx, uid, mine):
            return False
    ctx.unplaced.pop(aid, None)
    return True


class _Contribution(NamedTuple):
    """A placed action's weight x completion (from ``now_s``)."""

    cost: float
    action_id: str


def _contributions(ctx: Ctx) -> list[_Contribution]:
    """Per placed action, weight x completion, worst (the best to move) first."""
    now = ctx.problem.now_s
    return sorted(
        (_Contribution(ctx.actions[a].weight * (c - now), a) for a, c in _completions(ctx).items()),
        reverse=True,
    )


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
    search = _Threshold(ctx, objective(ctx))
    worst: list[_Contribution] = []
    weights = ctx.weights
    ctx.anywhere = True
    try:
        for n in range(max_rounds):
            if should_stop():
                break
            if n % 25 == 0:
                worst = _contributions(ctx)[:20]
            seed_id = _pick_seed(ctx, rng, ids, worst)
            group = _related(ctx, seed_id, rng, rng.choice((1, 1, 2, 3)))
            snap = ctx.snapshot()
            score = None
            if all(_remove(ctx, aid) for aid in group):
                _recreate(ctx, group, rng, weights)
                score = objective(ctx)
            search.judge(snap, score)
        search.finish()
    finally:
        ctx.anywhere, ctx.rng, ctx.weights = False, None, weights
    return search.accepted


def _pick_seed(ctx: Ctx, rng: random.Random, ids: list[str], worst: list[_Contribution]) -> str:
    """A round's seed action: one of the last tasks of the UAV that finishes
    last (``LATE_P``), one of the ``worst`` contributions, or any action."""
    x = rng.random()
    late = _late(ctx) if x < LATE_P else []
    if late:
        return rng.choice(late)
    if worst and x < 0.5:
        return rng.choice(worst).action_id
    return rng.choice(ids)


class _Threshold:
    """Threshold acceptance over rounds: the best and current objectives, and
    the best state to go back to (None while the current state is the best)."""

    def __init__(self, ctx: Ctx, score: Score) -> None:
        self.ctx = ctx
        self.best = self.current = score
        self.best_snap: Snapshot | None = None
        self.stale = 0  # rounds without a new best
        self.accepted = 0  # rounds that found a new best

    def judge(self, snap: Snapshot, score: Score | None) -> None:
        """Keep a round's state (objective ``score``; None if the round
        failed) or go back to ``snap``, the state before it; after
        ``RESTART_AFTER`` rounds without a new best, go back to the best."""
        if score is not None:
            if score < self.best:
                self.best = self.current = score
                self.best_snap = None
                self.accepted += 1
                self.stale = 0
                return
            current = self.current
            if score.unplaced == current.unplaced and score.cost_s <= current.cost_s * (
                1 + THRESHOLD
            ):
                if self.best_snap is None:
                    self.best_snap = snap
                self.current = score
                self.stale += 1
                if self.stale > RESTART_AFTER:
                    self._back_to_best()
                return
        self.ctx.restore(snap)
        self.stale += 1
        if self.stale > RESTART_AFTER and self.best_snap is not None:
            self._back_to_best()

    def _back_to_best(self) -> None:
        """Restart from the best state seen."""
        assert self.best_snap is not None
        self.ctx.restore(self.best_snap)
        self.best_snap, self.current, self.stale = None, self.best, 0

    def finish(self) -> None:
        """Leave the best state seen."""
        if self.best_snap is not None:
            self.ctx.restore(self.best_snap)


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
