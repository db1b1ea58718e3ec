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

from msgspec.structs import replace

from ground_station.planner.energy import EPS_S, EPS_WH, energy_after_recharge
from ground_station.planner.model import Vec3
from ground_station.planner.result import Step
from ground_station.planner.routes import Ctx
from ground_station.planner.simulate import HOLDS, State, Visit, hold_wait
from ground_station.planner.state import Booking, wait_step


def remove(ctx: Ctx, uid: str, pred: Callable[[Visit], bool]) -> bool:
    """Remove matching tasks from ``uid``'s route, re-simulating it or else
    keeping the other steps' times; False (unchanged) if neither works."""
    return ctx.remove_tasks(uid, pred) is not None or remove_in_place(ctx, uid, pred) is not None


def remove_in_place(ctx: Ctx, uid: str, pred: Callable[[Visit], bool]) -> list[Visit] | None:
    """Remove matching tasks keeping all other steps' times; None if the
    battery would break (the route is then unchanged)."""
    r = ctx.routes[uid]
    if not any(pred(t) for t in r.tasks):
        return []
    n = len(r.tasks)
    replay = _Replay(ctx, uid)
    marks: list[int] = []
    states: list[State] = []
    tasks: list[Visit] = []
    removed: list[Visit] = []
    last_kept = max((i for i, x in enumerate(r.tasks) if not pred(x)), default=-1)
    open_mark: int | None = None  # where the kept steps of removed tasks begin
    for i, task in enumerate(r.tasks):
        gone = pred(task)
        if gone:
            removed.append(task)
            if i > last_kept:
                continue  # nothing after it needs its recharges
            if open_mark is None:
                open_mark = len(replay.steps)
        else:
            marks.append(open_mark if open_mark is not None else len(replay.steps))
            open_mark = None
            tasks.append(task)
        hi = r.marks[i + 1] if i + 1 < n else len(r.steps)
        if not replay.fly_task(r.steps[r.marks[i] : hi], gone):
            return None
        if not gone:
            states.append(replay.state())
    if replay.stranded():
        return None
    r.tasks, r.states, r.steps, r.marks = tasks, states, replay.steps, marks
    ctx.pads.remove_uav(uid, -1e18)
    ctx.pads.book(replay.res, uid)
    return removed


class _Replay:
    """A route flown again step by step, each step at its old times."""

    __slots__ = (
        "charging",
        "ctx",
        "e",
        "floor_wh",
        "k",
        "landed",
        "mine",
        "pos",
        "res",
        "stations",
        "steps",
        "t",
        "tool",
    )

    def __init__(self, ctx: Ctx, uid: str) -> None:
        r = ctx.routes[uid]
        self.ctx, self.k = ctx, r.kin
        self.floor_wh = r.kin.reserve_wh - EPS_WH
        self.charging = {s.id: i for i, s in enumerate(ctx.site.charging)}
        self.stations = {s.position_m for s in ctx.problem.stations}
        self.t, self.pos, self.e, self.landed, self.tool = r.init
        self.steps: list[Step] = []
        self.res: list[Booking] = []
        self.mine = (uid, -1e18)  # this route's own bookings are being redone

    def state(self) -> State:
        """Where the UAV is now."""
        return State(self.t, self.pos, self.e, self.landed, self.tool)

    def stranded(self) -> bool:
        """Whether the UAV can no longer reach a station above the reserve."""
        return self.e - self.ctx.site.nearest(self.pos).distance_m * self.k.wh_per_m < self.floor_wh

    def fly_task(self, raws: list[Step], gone: bool) -> bool:
        """Fly a task's steps (of a removed task only its recharges and
        waits); False if the battery, a tool or a hold point breaks."""
        for raw in raws:
            if gone and raw.action_id is not None:
                continue
            if not self._fly(raw):
                return False
        return True

    def _fly(self, raw: Step) -> bool:
        """Fly straight from where the UAV is to ``raw``'s position, leaving
        just in time to arrive when it did, and serve it as before."""
        p, arrive, end = raw.position_m, raw.arrive_s, raw.end_s
        d = dist(self.pos, p)
        if raw.kind == "wait" and d > 1e-9 and p not in self.stations:
            p, d = self.pos, 0.0  # an in-place wait stays where the UAV now is
        if raw.kind == "wait" and d == 0.0:
            start = arrive = self.t
        else:
            start = arrive - d / self.k.speed_mps
        if start < self.t - EPS_S or not self._idle_until(start):
            return False
        self.e -= d * self.k.wh_per_m
        if d > 0:
            self.landed = False
        if self.e < self.floor_wh or not self._serve(raw, p, arrive):
            return False
        if self.e < self.floor_wh:
            return False
        self.steps.append(
            replace(
                raw,
                start_s=start,
                arrive_s=arrive,
                energy_after_wh=self.e,
                position_m=p,
                distance_m=d,
            )
        )
        self.t, self.pos = end, p
        return True

    def _idle_until(self, start: float) -> bool:
        """Wait where the UAV is until ``start``, if later (hovering, it holds
        the point there); False if another UAV holds it."""
        t = self.t
        if start > t + EPS_S:
            if not self.landed:
                self.e -= self.k.hover_whps * (start - t)
                site, pads = self.ctx.site, self.ctx.pads
                if not hold_wait(site, pads, self.pos, t, start, self.mine, self.res):
                    return False
            self.steps.append(wait_step(t, start, self.e, self.pos))
        return True

    def _serve(self, raw: Step, p: Vec3, arrive: float) -> bool:
        """Spend ``raw``'s time at ``p`` (recharge, wait or work); False if
        the tool or an airborne wait's hold point breaks."""
        kind, end, site = raw.kind, raw.end_s, self.ctx.site
        if kind == "pick" and self.tool is not None:
            return False
        if kind == "deliver" and self.tool != raw.tool:
            return False
        if kind == "recharge":
            assert raw.station is not None
            station = site.by_id[raw.station]
            self.e = energy_after_recharge(station, self.k.capacity_wh, self.e, end - arrive)
            self.landed = True
            self.res.append(Booking(self.charging[raw.station], arrive, end))
        elif kind == "wait":
            self.landed = self.landed or p in self.stations
            if not self.landed:
                self.e -= self.k.hover_whps * (end - arrive)
                return hold_wait(site, self.ctx.pads, p, arrive, end, self.mine, self.res)
        else:
            self.e -= self.k.hover_whps * (end - arrive)
            point = site.points.get(p) if kind in HOLDS else None
            if point is not None:
                self.res.append(Booking(point, arrive, end))
            if kind == "pick":
                self.tool = raw.tool
            elif kind == "deliver":
                self.tool = None
        return True
