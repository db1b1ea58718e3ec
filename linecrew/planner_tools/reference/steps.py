"""A CP-SAT solution as a plan document, and a plan as fixed routes."""

from __future__ import annotations

from math import dist
from typing import TYPE_CHECKING, TypedDict, Unpack

import msgspec

from ground_station.planner.metrics import compute_metrics
from ground_station.planner.model import Airframe, Station, Uav, Vec3
from ground_station.planner.result import Solution, Step, StepKind, UavPlan
from linecrew.planner_tools.reference.cpsat import Model
from linecrew.planner_tools.reference.nodes import TICK_S, Node, ticks

if TYPE_CHECKING:
    from ortools.sat.python.cp_model import CpSolver, LiteralT


class _Refs(TypedDict, total=False):
    """What a step refers to: its station, or its action, index and tool."""

    station: str
    action_id: str | None
    index: int | None
    tool: str | None


def export(m: Model, solver: CpSolver) -> Solution:
    """The solution as a plan document (times and energy in floats)."""
    uavs = tuple(UavPlan(uav_id=u.id, steps=tuple(_steps(m, solver, u))) for u in m.problem.uavs)
    plan = Solution(uavs=uavs)
    return msgspec.structs.replace(plan, metrics=compute_metrics(m.problem, plan))


def _steps(m: Model, solver: CpSolver, u: Uav) -> list[Step]:
    succ = {i: j for (i, j), lit in m.arcs[u.id].items() if solver.boolean_value(lit)}
    run = _Run(u, m.types[u.type], m.problem.now_s)
    i = -1
    now = m.problem.now_s
    while succ.get(i, -1) != -1:
        j = succ[i]
        start, end = solver.value(m.start[j]) * TICK_S, solver.value(m.end[j]) * TICK_S
        run.visit(m.nodes[j], start + now, end + now)
        i = j
    if run.steps:
        run.fly_home(next(s for s in m.problem.stations if s.id == u.home_station))
    return run.steps


class _Run:
    """Builds one UAV's steps from its visits, tracking time and energy."""

    def __init__(self, u: Uav, t: Airframe, now: float) -> None:
        self.t = t
        self.pos, self.time, self.e = u.position_m, now, u.energy_wh
        self.landed = not u.airborne
        self.steps: list[Step] = []

    def _flight(self, to: Vec3) -> tuple[float, float]:
        d = dist(self.pos, to)
        return d, ticks(d / self.t.cruise_speed_mps) * TICK_S

    def _step(
        self, kind: StepKind, arrive: float, end: float, pos: Vec3, d: float, **kw: Unpack[_Refs]
    ) -> None:
        self.steps.append(
            Step(
                kind=kind,
                start_s=self.time,
                arrive_s=arrive,
                end_s=end,
                position_m=pos,
                energy_after_wh=self.e,
                distance_m=d,
                **kw,
            )
        )
        self.pos, self.time = pos, end

    def visit(self, nd: Node, start: float, end: float) -> None:
        """Fly to ``nd`` (waiting first if early) and serve it from ``start`` to ``end``."""
        t = self.t
        d, tt = self._flight(nd.pos)
        if nd.kind == "recharge":
            self.e -= t.flight_power_w * tt / 3600.0
            st = nd.recharge_station
            if start > self.time + tt:  # wait landed at the station for a pad
                self._step("wait", self.time + tt, start, nd.pos, d, station=st.id)
                d = 0.0
            if st.recharge == "swap":
                self.e = t.battery_wh
            else:
                self.e = min(t.battery_wh, self.e + t.battery_wh * (end - start) / st.full_charge_s)
            self._step("recharge", start, end, nd.pos, d, station=st.id)
            self.landed = True
            return
        leave = start - tt
        if leave > self.time:
            if not self.landed:
                self.e -= t.hover_power_w * (leave - self.time) / 3600.0
            self._step("wait", self.time, leave, self.pos, 0.0)
        self.e -= t.flight_power_w * tt / 3600.0 + t.hover_power_w * (end - start) / 3600.0
        self.landed = False
        self._step(
            nd.kind, start, end, nd.pos, d, action_id=nd.action_id, index=nd.index, tool=nd.tool
        )

    def fly_home(self, home: Station) -> None:
        """The last leg, to the home station."""
        d, tt = self._flight(home.position_m)
        self.e -= self.t.flight_power_w * tt / 3600.0
        self._step("home", self.time + tt, self.time + tt, home.position_m, d, station=home.id)


def route_literals(m: Model, plan: Solution) -> list[LiteralT] | None:
    """Literals fixing the routes of ``plan`` (every arc on or off), or None
    if the model cannot express them."""
    seqs = _sequences(m, plan)
    if seqs is None:
        return None
    out: list[LiteralT] = []
    for uid, seq in seqs.items():
        on = set(zip([-1, *seq], [*seq, -1], strict=True))
        out += [lit if key in on else ~lit for key, lit in m.arcs[uid].items()]
    return out


def _sequences(m: Model, plan: Solution) -> dict[str, list[int]] | None:
    """Per UAV, the model nodes its steps visit in order (None if
    inexpressible). Monitoring steps of a slot map to its segments
    in time order across UAVs."""
    segment: dict[tuple[str, int], int] = {}
    watches = sorted(
        (s.arrive_s, up.uav_id, n, (s.action_id, s.index))
        for up in plan.uavs
        for n, s in enumerate(up.steps)
        if s.kind == "monitor"
    )
    rank: dict[tuple, int] = {}
    for _, uid, n, slot in watches:
        rank[slot] = rank.get(slot, -1) + 1
        segment[(uid, n)] = rank[slot]
    out: dict[str, list[int]] = {}
    for up in plan.uavs:
        free: dict[tuple[str, str | None, int | None], list[int]] = {}
        for j in m.visit.get(up.uav_id, {}):
            nd = m.nodes[j]
            at = nd.station.id if nd.station else nd.action_id
            free.setdefault((nd.kind, at, nd.index), []).append(j)
        seq: list[int] = []
        for n, s in enumerate(up.steps):
            if s.kind in ("wait", "home"):
                continue
            if s.kind == "monitor":
                if s.action_id is None or s.index is None:
                    return None  # a monitoring step names its action and slot
                js = m.segments.get((s.action_id, s.index), [])
                h = segment[(up.uav_id, n)]
                if h >= len(js) or js[h] not in m.visit[up.uav_id]:
                    return None
                seq.append(js[h])
                continue
            key = (s.kind, s.station if s.kind == "recharge" else s.action_id, s.index)
            if not free.get(key):
                return None
            seq.append(free[key].pop(0))
        out[up.uav_id] = seq
    return out
