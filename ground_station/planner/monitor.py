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
A UAV flying a segment (``Uav.running``) goes on at its slot first.
An action some of whose segments stay planned (an improvement ruins the
rest but never moves a frozen one) gets only its slots without one.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable
from math import dist
from typing import NamedTuple

import msgspec

from ground_station.planner import costs
from ground_station.planner.energy import EPS_S
from ground_station.planner.model import MonitorJob, Vec3, slot_position
from ground_station.planner.monitor_start import ReadyTimes, start_times
from ground_station.planner.reach import monitor_reach
from ground_station.planner.routes import Ctx, Snapshot
from ground_station.planner.simulate import Visit

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
"""A promised start (``MonitorJob.start_s``) stands unless the action
can start at least this much earlier now (a UAV came back or was freed):
small gains never move a start the UAVs are already flying to."""


class Need(msgspec.Struct, frozen=True, order=True, gc=False):
    """Slot ``slot`` to cover from ``start_s`` until ``end_s`` (ordered by start)."""

    start_s: float
    slot: int
    end_s: float


def segment_needs(tasks: Iterable[Visit]) -> list[Need]:
    """What the monitoring segments among ``tasks`` cover."""
    return [
        Need(t.anchor_s, t.index, t.anchor_s + t.service_s)
        for t in tasks
        if t.kind == "monitor" and t.anchor_s is not None and t.index is not None
    ]


class _Member(msgspec.Struct, frozen=True, gc=False):
    """A capable UAV: its fixed cost (suitability and interruption) and suitability."""

    uid: str
    fixed_cost: float
    suit: float


_Ranked = tuple[float, str, float, int]
"""A UAV that can start a segment: (rank cost, uid, suitability, route
position). A plain tuple, unpacked where used: ``list.sort`` compares exact
tuples several times faster than Structs or NamedTuples, and these are
sorted by the fleet for every segment tried."""


class _Offer(msgspec.Struct, frozen=True, order=True, gc=False):
    """A segment a UAV can fly until ``end_s``: rank cost (less the time it
    covers), suitability, route position."""

    cost: float
    uid: str
    end_s: float
    suit: float
    position: int


class _Coverage(NamedTuple):
    """A full coverage tried: its cost, its start and the state with it."""

    cost: float
    start_s: float
    snapshot: Snapshot


def _cover(
    ctx: Ctx, a: MonitorJob, t0: float, uids: list[str], ready: dict[str, float] | None = None
) -> float | None:
    """Tentatively commit a full coverage from ``t0``; its cost, or None."""
    end = t0 + a.duration_s
    return _cover_needs(ctx, a, [Need(t0, s, end) for s in range(a.k)], uids, ready=ready)


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


def _rank_uavs(ctx: Ctx, fleet: list[_Member], pos: Vec3, t: float, push: bool) -> list[_Ranked]:
    """The UAVs of ``fleet`` that can start a segment at ``pos`` at ``t``,
    best first: at the end of its route if it is free by then; with
    ``push``, also before its later tasks (at a penalty)."""
    out: list[_Ranked] = []
    for m in fleet:
        uid = m.uid
        r = ctx.routes[uid]
        speed = r.kin.speed_mps
        st = r.tail()
        travel_s = dist(st.pos, pos) / speed
        if st.t + travel_s <= t + EPS_S:
            out.append((m.fixed_cost + MON_TRAVEL * travel_s, uid, m.suit, len(r.tasks)))
            continue
        p = _push_position(ctx, uid, pos, t) if push else None
        if p is not None:
            travel_s = dist(r.state_before(p).pos, pos) / speed
            cost = m.fixed_cost + MON_TRAVEL * travel_s + PUSH_PENALTY_S
            out.append((cost, uid, m.suit, p))
    out.sort()
    return out


def _members(ctx: Ctx, a: MonitorJob, uids: list[str]) -> list[_Member]:
    """The UAVs ``uids`` with their fixed costs for ``a``."""
    w = ctx.weights
    out = []
    for uid in uids:
        suit = costs.j1(ctx.routes[uid].kin.caps, "monitor")
        jv = costs.j3(ctx.running.get(uid), a.id)
        out.append(_Member(uid, w.suitability_s * suit + w.interruption_s * jv, suit))
    return out


def _cover_needs(
    ctx: Ctx,
    a: MonitorJob,
    needs: list[Need],
    uids: list[str],
    push: bool = False,
    ready: dict[str, float] | None = None,
) -> float | None:
    """Commit segments covering each need with hand-overs; their cost, or None.
    With ``push`` a segment may also go before a UAV's later tasks.
    ``ready`` (lower bounds of the UAVs' ready times, ``ReadyTimes.bound``)
    skips UAVs that cannot be at a slot by then, until they take a segment."""
    slots = [slot_position(a, s) for s in range(a.k)]
    need = list(needs)
    heapq.heapify(need)
    end = max(n.end_s for n in needs)
    fleet = _members(ctx, a, uids)
    held = _held_slots(ctx, a)
    suit_sum = 0.0
    handovers = 0
    moved: set[str] = set()
    while need:
        cur = heapq.heappop(need)
        t, end = cur.start_s, cur.end_s
        holders = {uid: slot for uid, slot in held.items() if uid not in moved}
        pre = [
            r
            for r in _rank_uavs(ctx, fleet, slots[cur.slot], t, push)
            if holders.get(r[1], cur.slot) == cur.slot
        ]
        offers = _offers(ctx, a, pre, cur, slots[cur.slot], ready, moved)
        offers.sort(key=lambda o: o.uid not in holders)  # the UAV on the slot goes on first
        taken = _commit_first(ctx, a, offers, cur, slots[cur.slot])
        if taken is None:
            return None
        moved.add(taken.uid)
        suit_sum += taken.suit * (taken.end_s - t) / a.duration_s
        if taken.end_s < end - EPS_S:
            heapq.heappush(need, Need(taken.end_s, cur.slot, end))
            handovers += 1
    w = ctx.weights
    return (
        w.suitability_s * suit_sum + w.travel * (end - ctx.problem.now_s) * a.k + 10.0 * handovers
    )


def _held_slots(ctx: Ctx, a: MonitorJob) -> dict[str, int]:
    """The slot of ``a`` each UAV flying one of its segments holds now: it
    goes on watching there first, and takes no other slot before that (never
    flown across the ring while a newcomer takes its place)."""
    return {uid: run.index for uid, run in ctx.running.items() if run.action_id == a.id}


def _offers(
    ctx: Ctx,
    a: MonitorJob,
    pre: list[_Ranked],
    need: Need,
    pos: Vec3,
    ready: dict[str, float] | None,
    moved: set[str],
) -> list[_Offer]:
    """The segments the first ``MAX_REACH`` UAVs of ``pre`` that can get to
    ``pos`` by ``need.start_s`` would fly, best first (improvement may cut
    them short or shuffle them)."""
    t, end = need.start_s, need.end_s
    min_seg = ctx.problem.min_monitor_segment_s
    out: list[_Offer] = []
    for rank_cost, uid, suit, p in pre:
        if len(out) >= MAX_REACH:
            break
        r = ctx.routes[uid]
        slack = 2 * a.standoff_m / r.kin.speed_mps + EPS_S  # slot 0 to slot s
        if ready is not None and uid not in moved and ready.get(uid, float("inf")) > t + slack:
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
        out.append(_Offer(rank_cost - (seg_end - t), uid, seg_end, suit, p))
    out.sort()
    if ctx.rng is not None and len(out) > 1 and ctx.rng.random() < SHUFFLE_P:
        ctx.rng.shuffle(out)
    return out


def _commit_first(
    ctx: Ctx, a: MonitorJob, offers: list[_Offer], need: Need, pos: Vec3
) -> _Offer | None:
    """Commit the first of ``offers`` that simulates; None if none does."""
    t = need.start_s
    for offer in offers:
        task = Visit("monitor", a.id, need.slot, pos, offer.end_s - t, a.release_s, anchor_s=t)
        sim = ctx.try_insert(offer.uid, offer.position, [task])
        if not isinstance(sim, str):
            ctx.commit(offer.uid, offer.position, [task], sim)
            return offer
    return None


def repair(ctx: Ctx, a: MonitorJob, gaps: list[Need]) -> bool:
    """Cover the needs a lost UAV leaves, without touching the rest of the
    monitoring; False (unchanged) if impossible."""
    snap = ctx.snapshot()
    if _cover_needs(ctx, a, gaps, ctx.capable("monitor"), push=True) is not None:
        return True
    ctx.restore(snap)
    return False


def _keep_start(ctx: Ctx, a: MonitorJob, start_s: float, uids: list[str]) -> bool:
    """Commit a coverage from the promised ``start_s``; False (unchanged) if infeasible."""
    snap = ctx.snapshot()
    if _cover(ctx, a, start_s, uids) is not None:
        return True
    ctx.restore(snap)
    return False


def _complete_kept(ctx: Ctx, a: MonitorJob, uids: list[str]) -> bool:
    """If segments of ``a`` are still planned (pinned ones an improvement
    round kept), cover only the slots without one over the kept segments'
    window, never a second coverage beside them; True if so (unplaced if
    that is impossible)."""
    kept = segment_needs(
        t for uid in ctx.placed_uavs(a.id) for t in ctx.routes[uid].tasks if t.action_id == a.id
    )
    if not kept:
        return False
    start, end = min(k.start_s for k in kept), max(k.end_s for k in kept)
    needs = [Need(start, s, end) for s in range(a.k) if s not in {k.slot for k in kept}]
    if needs:
        snap = ctx.snapshot()
        if _cover_needs(ctx, a, needs, uids) is None:
            ctx.restore(snap)
            ctx.add_unplaced(a.id, None, "monitor_coverage_infeasible")
    return True


def place_monitor(ctx: Ctx, a: MonitorJob) -> None:
    """Cover ``a`` from the best start tried (a promised start stands unless
    a clearly earlier one works), or report it unplaced."""
    uids = ctx.capable("monitor")
    if not uids:
        ctx.add_unplaced(a.id, None, "no_capable_uav")
        return
    if a.k > len(uids):
        ctx.add_unplaced(a.id, None, "k_exceeds_fleet")
        return
    if _complete_kept(ctx, a, uids):
        return
    min_seg = min(ctx.problem.min_monitor_segment_s, a.duration_s)
    if not _reachable(ctx, a, uids, min_seg):
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
    best = _best_coverage(ctx, a, uids, ready, t0)
    retry = promised is not None and not keep and (best is None or best.start_s > promised)
    if retry and promised is not None and _keep_start(ctx, a, promised, uids):
        return  # the earlier start did not work out: the promise stands (not tried yet)
    if best is None:
        ctx.add_unplaced(a.id, None, "monitor_coverage_infeasible")
        return
    ctx.restore(best.snapshot)


def _reachable(ctx: Ctx, a: MonitorJob, uids: list[str], min_seg: float) -> bool:
    """Whether some UAV, on a full battery from the nearest station, could
    watch slot 0 for ``min_seg`` and get back above the reserve."""
    d = ctx.site.nearest(slot_position(a, 0)).distance_m
    return any(
        (k := ctx.routes[u].kin).capacity_wh - 2 * d * k.wh_per_m - k.hover_whps * min_seg
        >= k.reserve_wh
        for u in uids
    )


def _best_coverage(
    ctx: Ctx, a: MonitorJob, uids: list[str], ready: ReadyTimes, t0: float
) -> _Coverage | None:
    """The cheapest coverage from the first candidate starts, or else from
    the first fallback start that works (``start_times``); the state is
    left as it was."""
    primary, fallback = start_times(ctx, a, ready, t0)
    snap = ctx.snapshot()
    best: _Coverage | None = None
    tried: set[float] = set()
    for group in (primary, fallback):
        for t in group:
            if t in tried:
                continue
            tried.add(t)
            cost = _cover(ctx, a, t, uids, ready.bound)
            if cost is not None and (best is None or cost < best.cost):
                best = _Coverage(cost, t, ctx.snapshot())
            ctx.restore(snap)
            if best is not None and group is fallback:
                break
        if best is not None:
            break
    return best
