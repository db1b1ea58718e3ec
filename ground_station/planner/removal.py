"""Time-preserving removal: take tasks out of a route without moving the rest.

Re-simulating a route after a removal can fail: the UAV arrives at a later
anchored (monitoring) segment with a different battery or a different pad
slot. This fallback keeps every remaining step at its time: the UAV flies
straight to the next kept step (never longer than the detour it replaces)
and idles in place until that step's original arrival. With hover power not
above flight power the battery is then never lower than before, so the
route stays feasible; the energies are recomputed and checked anyway.
"""

from __future__ import annotations

from collections.abc import Callable
from math import dist

from ground_station.planner.energy import EPS_S, EPS_WH, energy_after_recharge
from ground_station.planner.routes import Ctx
from ground_station.planner.simulate import HOLDS, State, Task, hold_wait


def remove_in_place(ctx: Ctx, uid: str, pred: Callable[[Task], bool]) -> list[Task] | None:
    """Remove matching tasks keeping all other steps' times; None if the
    battery would break (the route is then unchanged)."""
    r = ctx.routes[uid]
    k = r.kin
    n = len(r.tasks)
    if not any(pred(t) for t in r.tasks):
        return []
    charging = {s.id: i for i, s in enumerate(ctx.site.charging)}
    stations = {s.position_m for s in ctx.problem.stations}
    t, pos, e, landed, tool = r.init
    steps: list = []
    marks: list[int] = []
    states: list[State] = []
    tasks: list[Task] = []
    res: list[tuple[int, float, float]] = []
    removed: list[Task] = []
    mine = (uid, -1e18)  # this route's own bookings are being redone
    last_kept = max((i for i, x in enumerate(r.tasks) if not pred(x)), default=-1)
    open_mark: int | None = None
    for i in range(n):
        task = r.tasks[i]
        lo = r.marks[i]
        hi = r.marks[i + 1] if i + 1 < n else len(r.steps)
        gone = pred(task)
        if gone:
            removed.append(task)
            if i > last_kept:
                continue  # nothing after it needs its recharges
        if not gone:
            marks.append(open_mark if open_mark is not None else len(steps))
            open_mark = None
            tasks.append(task)
        elif open_mark is None:
            open_mark = len(steps)
        for raw in r.steps[lo:hi]:
            kind, _start, arrive, end, _e, p, aid, idx, station, tl, _d = raw
            if gone and aid is not None:
                continue  # keep the removed task's recharges and waits only
            d = dist(pos, p)
            if kind == "wait" and d > 1e-9 and p not in stations:
                p, d = pos, 0.0  # an in-place wait stays where the UAV now is
            if kind == "wait" and d == 0.0:
                new_start = arrive = t
            else:
                new_start = arrive - d / k.speed_mps
            if new_start < t - EPS_S:
                return None
            if new_start > t + EPS_S:  # idle where we are until it is time to go
                if not landed:
                    e -= k.hover_whps * (new_start - t)
                    if not hold_wait(ctx.site, ctx.pads, pos, t, new_start, mine, res):
                        return None
                steps.append(("wait", t, t, new_start, e, pos, None, None, None, None, 0.0))
            e -= d * k.wh_per_m
            if d > 0:
                landed = False
            if e < k.reserve_wh - EPS_WH:
                return None
            if (kind == "pick" and tool is not None) or (kind == "deliver" and tool != tl):
                return None
            if kind == "recharge":
                e = energy_after_recharge(ctx.site.by_id[station], k.capacity_wh, e, end - arrive)
                landed = True
                res.append((charging[station], arrive, end))
            elif kind == "wait":
                landed = landed or p in stations
                if not landed:
                    e -= k.hover_whps * (end - arrive)
                    if not hold_wait(ctx.site, ctx.pads, p, arrive, end, mine, res):
                        return None
            else:
                e -= k.hover_whps * (end - arrive)
                point = ctx.site.points.get(p) if kind in HOLDS else None
                if point is not None:
                    res.append((point, arrive, end))
                if kind == "pick":
                    tool = tl
                elif kind == "deliver":
                    tool = None
            if e < k.reserve_wh - EPS_WH:
                return None
            steps.append((kind, new_start, arrive, end, e, p, aid, idx, station, tl, d))
            t, pos = end, p
        if not gone:
            states.append(State(t, pos, e, landed, tool))
    # The final state must still reach a station above the reserve.
    if e - ctx.site.nearest(pos)[0] * k.wh_per_m < k.reserve_wh - EPS_WH:
        return None
    r.tasks, r.states, r.steps, r.marks = tasks, states, steps, marks
    ctx.pads.remove_uav(uid, -1e18)
    for si, s, e2 in res:
        ctx.pads.add(si, s, e2, uid)
    return removed
