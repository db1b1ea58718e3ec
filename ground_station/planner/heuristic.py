"""The paper's greedy made complete: queue, J1+J2+J3 allocation, splits.

Actions are taken from the weight-ordered FCFS queue; each part goes to the
UAV (and route position) with the lowest cost. Battery feasibility and
recharges come from ``simulate``; monitoring lives in ``monitor``.
"""

from __future__ import annotations

from collections.abc import Callable
from math import dist

import msgspec

from ground_station.planner import insertion, monitor
from ground_station.planner.model import (
    DeliverJob,
    InspectJob,
    Job,
    MonitorJob,
    Problem,
    Vec3,
)
from ground_station.planner.routes import Ctx, Options, Snapshot, new_ctx, queue_order
from ground_station.planner.simulate import State, Visit
from ground_station.planner.split import chunk_all, equal_chunks, fixed_split_count

SPLITS_TRIED = 1
"""How many split counts (best estimates first) are simulated per inspection."""
RANDOM_SPLIT_P = 0.3
"""Improvement only (``ctx.rng`` set): the chance of a random split count."""


def reachable(ctx: Ctx, kind: str, pos: Vec3, service_s: float) -> bool:
    """Whether some capable UAV, on a full battery from the nearest station,
    could do ``service_s`` at ``pos`` and get back above the reserve."""
    d = ctx.site.nearest(pos).distance_m
    for r in ctx.routes.values():
        k = r.kin
        if kind not in k.caps:
            continue
        if k.capacity_wh - 2 * d * k.wh_per_m - k.hover_whps * service_s >= k.reserve_wh - 1e-6:
            return True
    return False


def place_deliver(ctx: Ctx, a: DeliverJob) -> None:
    if (a.id, None) in ctx.pinned:
        return
    if not ctx.capable("deliver"):
        ctx.add_unplaced(a.id, None, "no_capable_uav")
        return
    ts = next(s for s in ctx.problem.tool_stations if s.id == a.tool_station)
    if a.tool not in ts.tools:
        ctx.add_unplaced(a.id, None, "unknown_tool")
        return
    if not (
        reachable(ctx, "deliver", ts.position_m, a.pick_s)
        and reachable(ctx, "deliver", a.worker_m, a.drop_s)
    ):
        ctx.add_unplaced(a.id, None, "unreachable_with_full_battery")
        return

    def make(st: State) -> list[Visit]:
        drop = Visit("deliver", a.id, None, a.worker_m, a.drop_s, a.release_s, tool=a.tool)
        if st.tool == a.tool:
            return [drop]
        pick = Visit("pick", a.id, None, ts.position_m, a.pick_s, a.release_s, tool=a.tool)
        return [pick, drop]

    choice, reason = insertion.best_insertion(
        ctx,
        "deliver",
        a.id,
        ts.position_m,
        a.pick_s + a.drop_s,
        a.release_s,
        make,
        end=a.worker_m,
        path_m=dist(ts.position_m, a.worker_m),
    )
    if choice is None:
        ctx.add_unplaced(a.id, None, reason)
    else:
        insertion.apply(ctx, choice)


def _place_chunk(ctx: Ctx, a: InspectJob, idx: list[int]) -> tuple[float, float]:
    """Place one contiguous chunk; returns (finish, added UAV time).

    A chunk no UAV can take whole is placed waypoint by waypoint; waypoints
    no UAV can take are reported unplaced.
    """
    wps = a.waypoints
    tasks = [
        Visit("inspect", a.id, i, wps[i].position_m, wps[i].service_s, a.release_s) for i in idx
    ]
    work = sum(t.service_s for t in tasks)
    path = sum(dist(tasks[i - 1].pos, tasks[i].pos) for i in range(1, len(tasks)))
    choice, _ = insertion.best_insertion(
        ctx,
        "inspect",
        a.id,
        tasks[0].pos,
        work,
        a.release_s,
        lambda st: tasks,
        end=tasks[-1].pos,
        path_m=path,
    )
    if choice is not None:
        before = ctx.routes[choice.uid].tail().t
        insertion.apply(ctx, choice)
        return choice.finish_s, ctx.routes[choice.uid].tail().t - before
    finish, used = ctx.problem.now_s, 0.0
    if len(idx) == 1:
        ctx.add_unplaced(a.id, idx[0], "battery_infeasible")
        return finish, used
    for i in idx:
        f, u = _place_chunk(ctx, a, [i])
        finish, used = max(finish, f), used + u
    return finish, used


def place_inspect(ctx: Ctx, a: InspectJob, only: list[int] | None = None) -> None:
    """Place an inspection's waypoints (``only`` those, if given) in
    contiguous chunks; the split count is the best estimate's (paper mode:
    the paper's fixed count)."""
    ok = _placeable(ctx, a, only)
    if not ok:
        return
    caps = ctx.capable("inspect")
    if ctx.options.mode == "paper":
        _place_split(ctx, a, ok, equal_chunks(len(ok), min(fixed_split_count(len(ok)), len(caps))))
        return
    pts = [a.waypoints[i].position_m for i in ok]
    serv = [a.waypoints[i].service_s for i in ok]
    speed = min(ctx.routes[u].kin.speed_mps for u in caps)
    max_split = min(2, ctx.options.max_split) if ctx.fast else ctx.options.max_split
    splits = chunk_all(pts, serv, speed, min(max_split, len(caps), len(ok)))
    # Simulate only the SPLITS_TRIED most promising split counts (by estimate).
    fleet = _fleet(ctx, caps)
    ranked = sorted(splits, key=lambda m: (_estimate(ctx, a, ok, splits[m], fleet), m))
    tried = sorted(ranked[:SPLITS_TRIED])
    if ctx.rng is not None and ctx.rng.random() < RANDOM_SPLIT_P:
        tried = [ctx.rng.choice(ranked)]
    if len(tried) == 1:
        _place_split(ctx, a, ok, splits[tried[0]])
    else:
        _place_best_split(ctx, a, ok, [splits[m] for m in tried])


def _placeable(ctx: Ctx, a: InspectJob, only: list[int] | None) -> list[int]:
    """The waypoints to place (not done, not running); the others that no
    UAV can take are reported unplaced."""
    skip = set(a.done) | {i for aid, i in ctx.pinned if aid == a.id}
    idx = [i for i in (only if only is not None else range(len(a.waypoints))) if i not in skip]
    if idx and not ctx.capable("inspect"):
        for i in idx:
            ctx.add_unplaced(a.id, i, "no_capable_uav")
        return []
    ok = []
    for i in idx:
        wp = a.waypoints[i]
        if reachable(ctx, "inspect", wp.position_m, wp.service_s):
            ok.append(i)
        else:
            ctx.add_unplaced(a.id, i, "unreachable_with_full_battery")
    return ok


def _place_split(
    ctx: Ctx, a: InspectJob, ok: list[int], chunks: list[list[int]]
) -> tuple[float, float]:
    """Place each chunk (indices into ``ok``); (finish, added UAV time)."""
    finish, used = ctx.problem.now_s, 0.0
    for c in chunks:
        f, u = _place_chunk(ctx, a, [ok[j] for j in c])
        finish, used = max(finish, f), used + u
    return finish, used


def _place_best_split(
    ctx: Ctx, a: InspectJob, ok: list[int], splits: list[list[list[int]]]
) -> None:
    """Place the best of ``splits``: fewest unplaced waypoints, then finish
    plus ``resource_factor`` x the UAV time used."""
    snap = ctx.snapshot()
    best: Snapshot | None = None
    best_score = 0.0
    for chunks in splits:
        finish, used = _place_split(ctx, a, ok, chunks)
        score = finish + ctx.options.resource_factor * used + 1e6 * len(ctx.unplaced.get(a.id, ()))
        if best is None or score < best_score:
            best, best_score = ctx.snapshot(), score
        ctx.restore(snap)
    assert best is not None
    ctx.restore(best)


class _Tail(msgspec.Struct, frozen=True, gc=False):
    """Where a UAV's route ends, for ``_estimate``: time, position, speed and
    suitability cost for inspections."""

    uid: str
    t: float
    pos: Vec3
    speed_mps: float
    suit_cost: float


def _estimate(
    ctx: Ctx, a: InspectJob, ok: list[int], chunks: list[list[int]], fleet: list[_Tail]
) -> float:
    """Cheap score of a split: each chunk on the UAV that could finish it
    first (tails only, no battery), as ``place_inspect`` scores real splits."""
    wps = a.waypoints
    release = a.release_s
    taken: set[str] = set()
    finish, used = ctx.problem.now_s, 0.0
    for c in chunks:
        pts = [wps[ok[j]].position_m for j in c]
        work = sum(wps[ok[j]].service_s for j in c)
        path = sum(dist(pts[i - 1], pts[i]) for i in range(1, len(pts)))
        first = pts[0]
        best_uid: str | None = None  # the UAV that finishes the chunk first
        best_cost = best_fin = best_used = 0.0
        for tail in fleet:
            if tail.uid in taken:
                continue
            speed = tail.speed_mps
            fin = tail.t + dist(tail.pos, first) / speed
            if fin < release:
                fin = release
            fin += work + path / speed
            cost = fin + tail.suit_cost
            if best_uid is None or cost < best_cost:
                best_uid, best_cost, best_fin, best_used = tail.uid, cost, fin, fin - tail.t
        if best_uid is None:
            return float("inf")
        taken.add(best_uid)
        finish, used = max(finish, best_fin), used + best_used
    return finish + ctx.options.resource_factor * used


def _fleet(ctx: Ctx, uids: list[str]) -> list[_Tail]:
    """The route tails ``_estimate`` scores chunks against."""
    out = []
    for uid in uids:
        r = ctx.routes[uid]
        st = r.tail()
        k = r.kin
        suit_cost = ctx.weights.suitability_s * k.caps["inspect"]
        out.append(_Tail(uid, st.t, st.pos, k.speed_mps, suit_cost))
    return out


def place_action(ctx: Ctx, a: Job, only: list[int] | None = None) -> None:
    """Place one action (or only some waypoints of an inspection)."""
    if isinstance(a, InspectJob):
        place_inspect(ctx, a, only)
    elif isinstance(a, MonitorJob):
        monitor.place_monitor(ctx, a)
    else:
        place_deliver(ctx, a)


def build(problem: Problem, options: Options | None = None) -> Ctx:
    """Run the heuristic over the whole queue; returns the planning state."""
    ctx = build_until(problem, options, lambda: False)
    assert ctx is not None  # never told to stop
    return ctx


def build_until(
    problem: Problem, options: Options | None, should_stop: Callable[[], bool]
) -> Ctx | None:
    """:func:`build`, polling ``should_stop`` between actions: None if stopped
    (a construction from scratch of a large problem takes a few hundred ms)."""
    ctx = new_ctx(problem, options or Options())
    for a in queue_order(problem.actions):
        if should_stop():
            return None
        place_action(ctx, a)
    return ctx
