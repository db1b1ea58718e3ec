"""Candidate start times (T0) of a synchronised monitoring.

A UAV's earliest time at the ring counts the recharge it needs first
("recharge first, then come": ``monitor_ready``), so the k-th earliest of
those is the first start worth trying; later ones come from the same list
(the k+1-th, k+2-th, k+4-th, ... earliest), and only if none of them can be
covered, from the time the whole fleet is ready.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterator

from ground_station.planner.model import MonitorJob, slot_position
from ground_station.planner.reach import direct_arrival, hold_floor_wh, monitor_ready
from ground_station.planner.routes import Ctx

MAX_T0_CANDIDATES = 2
"""Start times tried first (the k-th earliest ready time, then later ones)."""
HOLD_SHARE = 0.8
"""A ready UAV can watch the whole duration, or this share of what a full
battery holds at the ring (less and it would come only to hand over soon).
Of 0 (any stint) / 0.5 / 0.8, 0.8 built the best plans on the corridor
bench (20x200, 5 seeds: +7 / -2 / -8 % score against starting from direct
arrivals and the fleet's last finish; 50x500: -63 / -67 / -67 %)."""
RANDOM_T0 = 2
"""Improvement only: random start times added to the candidates."""


class ReadyTimes:
    """Per UAV, the earliest time it can be at slot 0 from the end of its
    route with the battery for a useful watch (``monitor_ready``): the whole
    ``duration_s``, or ``HOLD_SHARE`` of what a full battery holds there.

    Evaluated lazily in order of ``bound``, a lower bound of when the UAV can
    start a segment there (direct flight; a direct flight with the battery
    for ``min_seg_s`` is exact), so only UAVs that may be among the earliest
    are simulated. A UAV that leaves a pad first (landed, or after a
    recharge) is ready ``Problem.takeoff_s`` later.
    """

    def __init__(
        self, ctx: Ctx, a: MonitorJob, uids: list[str], base: float, min_seg_s: float
    ) -> None:
        self._ctx, self.base, self._duration_s = ctx, base, a.duration_s
        self._min_seg_s = min_seg_s
        self._takeoff_s = ctx.problem.takeoff_s
        self._pos = pos = slot_position(a, 0)
        self.bound: dict[str, float] = {}
        self._flight: dict[str, float] = {}  # direct arrival, take-off not counted
        self._direct: set[str] = set()  # can come now for at least ``min_seg_s``
        self._heap: list[tuple[float, bool, str]] = []
        for uid in uids:
            r = ctx.routes[uid]
            st = r.tail()
            arr, e_at = direct_arrival(r.kin, st, pos, base)
            self._flight[uid] = arr
            if st.landed:
                arr += self._takeoff_s
            self.bound[uid] = arr
            self._heap.append((arr, False, uid))
            if e_at >= hold_floor_wh(r.kin, ctx.site, pos, min_seg_s):
                self._direct.add(uid)
        heapq.heapify(self._heap)
        self._sorted: list[float] = []

    def _exact(self, uid: str) -> float | None:
        """``monitor_ready`` for a useful watch; for any stint if none fits."""
        ctx = self._ctx
        r = ctx.routes[uid]
        k, st = r.kin, r.tail()
        # A full battery, flown from the nearest station to the ring and back.
        leg_wh = hold_floor_wh(k, ctx.site, self._pos, 0.0) - k.reserve_wh
        usable_wh = k.capacity_wh - 2 * leg_wh - k.reserve_wh
        hold_s = min(self._duration_s, HOLD_SHARE * usable_wh / max(k.hover_whps, 1e-12))
        for need_s in (hold_s, self._min_seg_s):
            t = monitor_ready(k, ctx.site, ctx.pads, st, self._pos, self.base, (uid, st.t), need_s)
            if t is not None and (st.landed or t > self._flight[uid] + 1e-9):  # leaves a pad
                t += self._takeoff_s
            if t is not None or need_s <= self._min_seg_s:
                return t
        return None

    def nth(self, j: int) -> float | None:
        """The ``j``-th (from 0) earliest ready time; None if fewer UAVs can get there."""
        heap, out = self._heap, self._sorted
        while len(out) <= j and heap:
            t, exact, uid = heapq.heappop(heap)
            if exact:
                out.append(t)
                continue
            x = self._exact(uid)
            if x is not None:
                heapq.heappush(heap, (x, True, uid))
            if x is not None and uid not in self._direct:
                self.bound[uid] = x
        return out[j] if j < len(out) else None

    def last(self) -> float | None:
        """The latest ready time (the whole fleet that can get there is ready)."""
        self.nth(len(self.bound))
        return self._sorted[-1] if self._sorted else None


def start_times(
    ctx: Ctx, a: MonitorJob, ready: ReadyTimes, t0: float
) -> tuple[list[float], Iterator[float]]:
    """(first candidates, later fallbacks) for a coverage whose k-th earliest
    ready time is ``t0``; the fallbacks are generated only as far as needed."""
    primary = [t0]
    limit = 1 if ctx.options.mode == "paper" else MAX_T0_CANDIDATES
    j = a.k
    while len(primary) < limit and (x := ready.nth(j)) is not None:
        if x > t0 + ctx.weights.suitability_s:
            break
        if x > t0:
            primary.append(x)
        j += 1
    if ctx.rng is not None:
        far = max(t for t in ready.bound.values() if t < float("inf"))
        span = far + a.duration_s - ready.base
        primary += [ready.base + ctx.rng.random() * span for _ in range(RANDOM_T0)]
    return primary, _fallbacks(ctx, a, ready)


def _fallbacks(ctx: Ctx, a: MonitorJob, ready: ReadyTimes) -> Iterator[float]:
    j = a.k
    while (x := ready.nth(j)) is not None:
        yield x
        if ctx.fast:
            break
        j = 2 * j - a.k + 1  # k, k+1, k+3, k+7, ...
    last = ready.last()
    if last is None:
        return
    charge_s = max((s.full_charge_s for s in ctx.site.charging), default=0.0)
    if not ctx.fast:
        yield last
    yield last + a.duration_s
    if not ctx.fast:
        yield last + charge_s
    yield last + 2 * (a.duration_s + charge_s)
