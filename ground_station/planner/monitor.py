"""Synchronised k-UAV monitoring with hand-over.

A monitoring action needs ``k`` slots (stand-off positions around the
worker) covered together from a common start ``T0`` for ``duration_s``.
UAVs that arrive early wait (landed if they can) so all slots start at T0.
Each slot is covered by a chain of segments: when a UAV's battery forces it
to leave, another UAV arrives at or before that moment and takes the slot
(the paper's Fig. 6), so coverage has no gap. Segments are tasks anchored
at their start time; the UAV that left recharges in its own route.
A start promised by an earlier plan stands unless one ``EARLIER_S``
sooner is possible now.
An action some of whose segments stay planned (an improvement ruins the
rest but never moves a frozen one) gets only its slots without one.
"""

from __future__ import annotations

import heapq
from math import dist

from ground_station.planner import costs
from ground_station.planner.energy import EPS_S
from ground_station.planner.model import MonitorAction, Vec3, slot_position
from ground_station.planner.monitor_start import ReadyTimes, start_times
from ground_station.planner.routes import Ctx
from ground_station.planner.simulate import Task, monitor_reach

MAX_REACH = 3
"""UAVs (best first by suitability and distance) examined for each segment."""
MON_TRAVEL = 1.0
"""Rank cost per second of flight to a slot (3 and 6 were worse on the bench)."""
PUSH_PENALTY_S = 600.0
"""Extra rank cost of a repair segment that delays a UAV's later tasks."""
SHORTEN_P = 0.25
SHORTEN = (0.2, 1.0)
"""Improvement only: the chance that a candidate segment is cut short (to a
uniform random fraction in this range of its reach), so a UAV can leave
early for other work."""
SHUFFLE_P = 0.2
"""Improvement only: the chance that segment candidates are tried in random order."""
EARLIER_S = 30.0
"""A promised start (``MonitorAction.start_s``) stands unless the action
can start at least this much earlier now (a UAV came back or was freed):
small gains never move a start the UAVs are already flying to."""


def _cover(
    ctx: Ctx, a: MonitorAction, t0: float, uids: list[str], ready: dict[str, float] | None = None
) -> float | None:
    """Tentatively commit a full coverage from ``t0``; its cost, or None."""
    end = t0 + a.duration_s
    return _cover_needs(ctx, a, [(t0, s, end) for s in range(a.k)], uids, ready=ready)


def _push_position(ctx: Ctx, uid: str, pos: Vec3, t: float) -> int | None:
    """The last position in ``uid``'s route from which a segment at ``pos``
    from ``t`` can still be reached (delaying what follows); None if none."""
    r = ctx.routes[uid]
    speed = r.kin.speed_mps
    n = len(r.tasks)
    lo = 1 if n and (r.tasks[0].action_id, r.tasks[0].index) in ctx.pinned else 0
    for p in range(n - 1, lo - 1, -1):
        st = r.state_before(p)
        if st.t + dist(st.pos, pos) / speed <= t + EPS_S:
            return p
    return None


def _rank_uavs(
    ctx: Ctx, fleet: list[tuple[str, float, float]], pos: Vec3, t: float, push: bool
) -> list[tuple[float, str, float, int]]:
    """``(rank cost, uid, suitability, route position)`` of each UAV in
    ``fleet`` (``(uid, fixed cost, suitability)``) that can start a segment at
    ``pos`` at ``t``: at the end of its route if it is free by then; with
    ``push``, also before its later tasks (at a penalty)."""
    out = []
    for uid, fixed, suit in fleet:
        r = ctx.routes[uid]
        speed = r.kin.speed_mps
        st = r.tail()
        travel_s = dist(st.pos, pos) / speed
        if st.t + travel_s <= t + EPS_S:
            out.append((fixed + MON_TRAVEL * travel_s, uid, suit, len(r.tasks)))
            continue
        p = _push_position(ctx, uid, pos, t) if push else None
        if p is not None:
            travel_s = dist(r.state_before(p).pos, pos) / speed
            out.append((fixed + MON_TRAVEL * travel_s + PUSH_PENALTY_S, uid, suit, p))
    out.sort()
    return out


def _cover_needs(
    ctx: Ctx,
    a: MonitorAction,
    needs: list[tuple[float, int, float]],
    uids: list[str],
    push: bool = False,
    ready: dict[str, float] | None = None,
) -> float | None:
    """Commit segments covering each (from, slot, until) with hand-overs.
    With ``push`` a segment may also go before a UAV's later tasks.
    ``ready`` (lower bounds of the UAVs' ready times, ``ReadyTimes.bound``)
    skips UAVs that cannot be at a slot by then, until they take a segment."""
    min_seg = ctx.problem.min_monitor_segment_s
    slots = [slot_position(a, s) for s in range(a.k)]
    need = list(needs)
    heapq.heapify(need)
    end = max(e for _, _, e in needs)
    w = ctx.weights
    fleet = []
    for uid in uids:
        suit = costs.j1(ctx.routes[uid].kin.caps, "monitor")
        jv = costs.j3(ctx.running.get(uid), a.id)
        fleet.append((uid, w.suitability_s * suit + w.interruption_s * jv, suit))
    suit_sum = 0.0
    handovers = 0
    moved: set[str] = set()
    inf = float("inf")
    while need:
        t, s, end = heapq.heappop(need)
        pos = slots[s]
        pre = _rank_uavs(ctx, fleet, pos, t, push)
        ranked: list[tuple[float, str, float, float, int]] = []
        for base, uid, suit, p in pre:
            if len(ranked) >= MAX_REACH:
                break
            r = ctx.routes[uid]
            slack = 2 * a.standoff_m / r.kin.speed_mps + EPS_S  # slot 0 to slot s
            if ready is not None and uid not in moved and ready.get(uid, inf) > t + slack:
                continue
            st = r.state_before(p)
            reach = monitor_reach(r.kin, ctx.site, ctx.pads, st, pos, t, (uid, st.t), end)
            if reach is None:
                continue
            seg_end = min(end, reach)
            if ctx.rng is not None and ctx.rng.random() < SHORTEN_P:
                seg_end = t + (seg_end - t) * ctx.rng.uniform(*SHORTEN)
            if seg_end < end - EPS_S and seg_end - t < min_seg:
                continue
            ranked.append((base - (seg_end - t), uid, seg_end, suit, p))
        ranked.sort()
        if ctx.rng is not None and len(ranked) > 1 and ctx.rng.random() < SHUFFLE_P:
            ctx.rng.shuffle(ranked)
        for _, uid, seg_end, suit, p in ranked:
            task = Task("monitor", a.id, s, pos, seg_end - t, a.release_s, anchor_s=t)
            sim = ctx.try_insert(uid, p, [task])
            if isinstance(sim, str):
                continue
            ctx.commit(uid, p, [task], sim)
            moved.add(uid)
            suit_sum += suit * (seg_end - t) / a.duration_s
            if seg_end < end - EPS_S:
                heapq.heappush(need, (seg_end, s, end))
                handovers += 1
            break
        else:
            return None
    return (
        w.suitability_s * suit_sum + w.travel * (end - ctx.problem.now_s) * a.k + 10.0 * handovers
    )


def repair(ctx: Ctx, a: MonitorAction, gaps: list[tuple[float, int, float]]) -> bool:
    """Cover the (from, slot, until) intervals a lost UAV leaves, without
    touching the rest of the monitoring; False (unchanged) if impossible."""
    snap = ctx.snapshot()
    if _cover_needs(ctx, a, gaps, ctx.capable("monitor"), push=True) is not None:
        return True
    ctx.restore(snap)
    return False


def _keep_start(ctx: Ctx, a: MonitorAction, start_s: float, uids: list[str]) -> bool:
    """Commit a coverage from the promised ``start_s``; False (unchanged) if infeasible."""
    snap = ctx.snapshot()
    if _cover(ctx, a, start_s, uids) is not None:
        return True
    ctx.restore(snap)
    return False


def _complete_kept(ctx: Ctx, a: MonitorAction, uids: list[str]) -> bool:
    """If segments of ``a`` are still planned (pinned ones an improvement
    round kept), cover only the slots without one over the kept segments'
    window, never a second coverage beside them; True if so (unplaced if
    that is impossible)."""
    kept = [
        (t.anchor_s, t.anchor_s + t.service_s, t.index)
        for uid in ctx.placed_uavs(a.id)
        for t in ctx.routes[uid].tasks
        if t.action_id == a.id and t.anchor_s is not None
    ]
    if not kept:
        return False
    start, end = min(k[0] for k in kept), max(k[1] for k in kept)
    needs = [(start, s, end) for s in range(a.k) if s not in {k[2] for k in kept}]
    if needs:
        snap = ctx.snapshot()
        if _cover_needs(ctx, a, needs, uids) is None:
            ctx.restore(snap)
            ctx.add_unplaced(a.id, None, "monitor_coverage_infeasible")
    return True


def place_monitor(ctx: Ctx, a: MonitorAction) -> None:
    uids = ctx.capable("monitor")
    if not uids:
        ctx.add_unplaced(a.id, None, "no_capable_uav")
        return
    if a.k > len(uids):
        ctx.add_unplaced(a.id, None, "k_exceeds_fleet")
        return
    if _complete_kept(ctx, a, uids):
        return
    pos0 = slot_position(a, 0)
    d = ctx.site.nearest(pos0)[0]
    min_seg = min(ctx.problem.min_monitor_segment_s, a.duration_s)
    if not any(
        (k := ctx.routes[u].kin).capacity_wh - 2 * d * k.wh_per_m - k.hover_whps * min_seg
        >= k.reserve_wh
        for u in uids
    ):
        ctx.add_unplaced(a.id, None, "unreachable_with_full_battery")
        return
    base = max(a.release_s, ctx.problem.now_s)
    ready = ReadyTimes(ctx, a, uids, base, min_seg)
    t0 = ready.nth(a.k - 1)
    promised = a.start_s if a.start_s is not None and a.start_s >= base else None
    keep = promised is not None and (t0 is None or t0 > promised - EARLIER_S)
    if keep and promised is not None and _keep_start(ctx, a, promised, uids):
        return
    if t0 is None:
        ctx.add_unplaced(a.id, None, "monitor_coverage_infeasible")
        return
    primary, fallback = start_times(ctx, a, ready, t0)
    snap = ctx.snapshot()
    best: tuple[float, float, tuple] | None = None
    tried: set[float] = set()
    for group in (primary, fallback):
        for t in group:
            if t in tried:
                continue
            tried.add(t)
            cost = _cover(ctx, a, t, uids, ready.bound)
            if cost is not None and (best is None or cost < best[0]):
                best = (cost, t, ctx.snapshot())
            ctx.restore(snap)
            if best is not None and group is fallback:
                break
        if best is not None:
            break
    retry = promised is not None and not keep and (best is None or best[1] > promised)
    if retry and promised is not None and _keep_start(ctx, a, promised, uids):
        return  # the earlier start did not work out: the promise stands (not tried yet)
    if best is None:
        ctx.add_unplaced(a.id, None, "monitor_coverage_infeasible")
        return
    ctx.restore(best[2])
