"""A reference optimiser for small planning problems, with OR-Tools CP-SAT.

Only ``linecrew bench planner --reference cpsat`` uses it, to measure how far
the planner is from the best plan an exact solver finds. OR-Tools is the
optional ``bench`` extra (``pip install 'linecrew[bench]'``), imported
lazily; the planner never depends on it.

The model is a restriction of the planner's problem, so every solution is a
plan the validator accepts:

- one routing circuit per UAV over service nodes (each pending waypoint,
  each monitoring slot split into up to ``SEGMENTS`` consecutive segments,
  each delivery's pick and drop) plus ``RECHARGES`` optional recharge visits
  per station, closed by the flight to the home station;
- a UAV inspects the waypoints it takes of one action in index order;
- a pick is followed directly by its drop; monitoring slots of an action
  start together at ``T0`` and segments hand over with no gap;
- times are whole seconds (flights rounded up), energy whole joules (powers
  rounded up); waiting before a task is hovered unless the UAV stands on a
  pad (after a recharge, or at the start if landed); a UAV waiting for a pad
  waits landed at the station; pads are shared (cumulative constraint);
- the objective is the planner's score times the total weight:
  sum(weight x completion) + total weight x makespan.

Problems with running tasks, held tools or unavailable UAVs are not handled.
"""

from __future__ import annotations

import dataclasses
from math import ceil, dist

import msgspec

from ground_station.planner.metrics import compute_metrics
from ground_station.planner.model import (
    DeliverAction,
    InspectAction,
    MonitorAction,
    Problem,
    Station,
    Uav,
    UavType,
    Vec3,
    slot_position,
)
from ground_station.planner.result import Plan, Step, UavPlan

SEGMENTS = 3
"""Segments a monitoring slot may be split into (two hand-overs)."""
RECHARGES = 2
"""Optional recharge visits per UAV and station."""
MAX_NODES = 80
"""Refuse problems with more service and recharge nodes than this."""
WEIGHT_SCALE = 100
"""Action weights are scaled to integers with this factor."""


class Reference(msgspec.Struct, frozen=True, kw_only=True):
    """The solver's answer: ``status`` (OPTIMAL, FEASIBLE, INFEASIBLE,
    UNKNOWN or UNSUPPORTED with ``detail``), its best plan, and the proven
    lower bound on the score (seconds, like ``api.score``)."""

    status: str
    detail: str = ""
    plan: Plan | None = None
    score_bound: float = 0.0
    wall_s: float = 0.0


@dataclasses.dataclass(frozen=True)
class _Node:
    kind: str  # inspect | monitor | pick | deliver | recharge
    pos: Vec3
    service_s: int = 0
    action_id: str | None = None
    index: int | None = None
    tool: str | None = None
    station: Station | None = None
    owner: str | None = None  # recharge visits belong to one UAV
    release_s: int = 0


def _nodes(problem: Problem) -> tuple[list[_Node], dict[tuple[str, int], list[int]]]:
    """Service and recharge nodes; per (monitor action, slot) its segment nodes."""
    nodes: list[_Node] = []
    segments: dict[tuple[str, int], list[int]] = {}
    tools = {t.id: t for t in problem.tool_stations}
    for a in problem.actions:
        rel = ceil(a.release_s - problem.now_s - 1e-9) if a.release_s > problem.now_s else 0
        if isinstance(a, InspectAction):
            for i, w in enumerate(a.waypoints):
                if i not in a.done:
                    nodes.append(
                        _Node("inspect", w.position_m, ceil(w.service_s), a.id, i, release_s=rel)
                    )
        elif isinstance(a, MonitorAction):
            for slot in range(a.k):
                segments[(a.id, slot)] = list(range(len(nodes), len(nodes) + SEGMENTS))
                pos = slot_position(a, slot)
                nodes.extend(
                    _Node("monitor", pos, 0, a.id, slot, release_s=rel) for _ in range(SEGMENTS)
                )
        elif isinstance(a, DeliverAction):
            where = tools[a.tool_station].position_m
            nodes.append(_Node("pick", where, ceil(a.pick_s), a.id, tool=a.tool, release_s=rel))
            nodes.append(_Node("deliver", a.worker_m, ceil(a.drop_s), a.id, tool=a.tool))
    for u in problem.uavs:
        for st in problem.stations:
            if st.pads >= 1:
                nodes.extend(
                    _Node("recharge", st.position_m, station=st, owner=u.id)
                    for _ in range(RECHARGES)
                )
    return nodes, segments


def _unsupported(problem: Problem, nodes: list[_Node]) -> str:
    if any(u.running or u.tool or not u.available for u in problem.uavs):
        return "running tasks, held tools or unavailable UAVs"
    if len(nodes) > MAX_NODES:
        return f"{len(nodes)} nodes (at most {MAX_NODES})"
    return ""


SERVICE_KIND = {"inspect": "inspect", "monitor": "monitor", "pick": "deliver", "deliver": "deliver"}


def solve(
    problem: Problem, time_limit_s: float = 30.0, workers: int = 2, hint: Plan | None = None
) -> Reference:
    """Solve ``problem`` with CP-SAT within ``time_limit_s`` seconds.

    ``hint`` (e.g. the planner's plan) seeds the search with its routes:
    CP-SAT then starts from a plan at least that good where the model can
    express it (at most ``SEGMENTS`` segments per slot and ``RECHARGES``
    recharges per station); the proven bound does not depend on it."""
    from ortools.sat.python import cp_model

    nodes, segments = _nodes(problem)
    why = _unsupported(problem, nodes)
    if why:
        return Reference(status="UNSUPPORTED", detail=why)
    m = _Model(cp_model, problem, nodes, segments)
    if hint is not None:
        m.hint(hint)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = time_limit_s
    solver.parameters.num_workers = workers
    code = solver.solve(m.model)
    status = solver.status_name(code)
    total_w = m.total_weight
    out = Reference(
        status=status,
        score_bound=solver.best_objective_bound / total_w if total_w else 0.0,
        wall_s=solver.wall_time,
    )
    if code in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        plan = m.export(solver)
        out = msgspec.structs.replace(out, plan=plan)
    return out


class _Model:
    """The CP-SAT model of one problem (built in the constructor)."""

    def __init__(self, cp, problem: Problem, nodes: list[_Node], segments) -> None:  # type: ignore[no-untyped-def]
        self.problem = problem
        self.nodes = nodes
        self.segments = segments
        self.types = {t.id: t for t in problem.uav_types}
        self.model = md = cp.CpModel()
        self.actions = {a.id: a for a in problem.actions}
        self.horizon = horizon = self._horizon()
        n = len(nodes)
        self.start = [md.new_int_var(0, horizon, f"s{j}") for j in range(n)]
        self.end = [md.new_int_var(0, horizon, f"f{j}") for j in range(n)]
        cap = max(round(t.battery_wh * 3600) for t in problem.uav_types)
        self.energy = [md.new_int_var(0, cap, f"e{j}") for j in range(n)]
        self.duration = [self._duration(cp, j, horizon) for j in range(n)]
        self.home = {u.id: md.new_int_var(0, horizon, f"home_{u.id}") for u in problem.uavs}
        self.arcs: dict[str, dict[tuple[int, int], object]] = {}
        self.visit: dict[str, dict[int, object]] = {}
        for u in problem.uavs:
            self._route(u, horizon)
        self._cover_once()
        self._monitors(segments)
        self._deliveries()
        self._pads(cp)
        self._objective(horizon)

    def _horizon(self) -> int:
        p = self.problem
        span = sum(n.service_s for n in self.nodes) + sum(
            a.duration_s for a in p.actions if isinstance(a, MonitorAction)
        )
        far = max((dist(a.pos, b.pos) for a in self.nodes for b in self.nodes), default=0.0) + max(
            (dist(u.position_m, n.pos) for u in p.uavs for n in self.nodes), default=0.0
        )
        slow = min(t.cruise_speed_mps for t in p.uav_types)
        charge = max((s.full_charge_s + s.swap_s for s in p.stations), default=0.0)
        hops = len(self.nodes) + 2
        return int(span + hops * (far / slow + charge)) + 3600

    def _duration(self, cp, j: int, horizon: int):  # type: ignore[no-untyped-def]
        node = self.nodes[j]
        md = self.model
        if node.kind == "monitor" or (
            node.kind == "recharge" and node.station.recharge == "charge"
        ):
            d = md.new_int_var(0, horizon, f"d{j}")
        elif node.kind == "recharge":
            d = ceil(node.station.swap_s)
        else:
            d = node.service_s
        md.add(self.end[j] == self.start[j] + d)
        md.add(self.start[j] >= node.release_s)
        return d

    def _route(self, u: Uav, horizon: int) -> None:
        """One circuit per UAV (node 0 is its start and its home), with
        time and energy along every arc."""
        md = self.model
        t = self.types[u.type]
        mine = [
            j
            for j, nd in enumerate(self.nodes)
            if (
                nd.owner == u.id
                if nd.kind == "recharge"
                else SERVICE_KIND[nd.kind] in t.capabilities
            )
        ]
        flight, hover = ceil(t.flight_power_w), ceil(t.hover_power_w)
        cap = round(t.battery_wh * 3600)
        reserve = ceil(self.problem.reserve_fraction * t.battery_wh * 3600)
        home = next(s for s in self.problem.stations if s.id == u.home_station).position_m
        e0 = int(u.energy_wh * 3600)
        arcs: list[tuple[int, int, object]] = []
        lits: dict[tuple[int, int], object] = {}
        visit: dict[int, object] = {}
        used = md.new_bool_var(f"used_{u.id}")
        arcs.append((0, 0, ~used))
        for j in mine:
            lit = md.new_bool_var(f"v_{u.id}_{j}")
            visit[j] = lit
            arcs.append((j + 1, j + 1, ~lit))
            md.add(self.energy[j] >= reserve).only_enforce_if(lit)
            md.add(self.energy[j] <= cap).only_enforce_if(lit)
            md.add_implication(lit, used)
        points = [(None, u.position_m), *((j, self.nodes[j].pos) for j in mine)]
        for i, pi in points:
            for j, pj in [*((j, self.nodes[j].pos) for j in mine), (None, home)]:
                if i == j:
                    continue
                if i is None and j is None:
                    continue
                lit = md.new_bool_var(f"x_{u.id}_{i}_{j}")
                arcs.append((0 if i is None else i + 1, 0 if j is None else j + 1, lit))
                lits[(-1 if i is None else i, -1 if j is None else j)] = lit
                tt = ceil(dist(pi, pj) / t.cruise_speed_mps - 1e-9)
                self._arc(lit, u, i, j, tt, flight * tt, hover, cap, reserve, e0)
        md.add_circuit(arcs)
        self.arcs[u.id] = lits
        self.visit[u.id] = visit

    def _arc(self, lit, u, i, j, tt, fly, hover, cap, reserve, e0) -> None:  # type: ignore[no-untyped-def]
        md = self.model
        t_i = 0 if i is None else self.end[i]
        e_i = e0 if i is None else self.energy[i]
        if j is None:  # the flight home
            md.add(self.home[u.id] >= t_i + tt).only_enforce_if(lit)
            md.add(e_i - fly >= reserve).only_enforce_if(lit)
            return
        md.add(self.start[j] >= t_i + tt).only_enforce_if(lit)
        nd = self.nodes[j]
        if nd.kind == "recharge":
            md.add(e_i - fly >= reserve).only_enforce_if(lit)
            st = nd.station
            if st.recharge == "charge":
                md.add(self.duration[j] >= 1).only_enforce_if(lit)
                full = ceil(st.full_charge_s)
                md.add(
                    self.energy[j] * full <= (e_i - fly) * full + cap * self.duration[j]
                ).only_enforce_if(lit)
            return
        on_pad = (i is None and not u.airborne) or (
            i is not None and self.nodes[i].kind == "recharge"
        )
        wait = 0 if on_pad else self.start[j] - t_i - tt
        md.add(
            self.energy[j] <= e_i - fly - hover * wait - hover * self.duration[j]
        ).only_enforce_if(lit)

    def _cover_once(self) -> None:
        """Every service node but optional monitoring segments is visited once."""
        for j, nd in enumerate(self.nodes):
            if nd.kind == "recharge":
                continue
            lits = [v[j] for v in self.visit.values() if j in v]
            if nd.kind != "monitor":
                self.model.add_exactly_one(lits)
        for v in self.visit.values():  # recharge visits of a station in order
            prev = None
            for j in sorted(v):
                nd = self.nodes[j]
                if nd.kind != "recharge":
                    continue
                if prev is not None and self.nodes[prev].station is nd.station:
                    self.model.add_implication(v[j], v[prev])
                    self.model.add(self.start[j] >= self.end[prev]).only_enforce_if(v[j])
                prev = j
        self._waypoint_order()

    def _waypoint_order(self) -> None:
        """A UAV inspects the waypoints of an action it takes in index order
        (the action's waypoints are ordered; parts may go to several UAVs)."""
        for v in self.visit.values():
            mine = [j for j in sorted(v) if self.nodes[j].kind == "inspect"]
            for a, i in enumerate(mine):
                for j in mine[a + 1 :]:
                    if self.nodes[i].action_id == self.nodes[j].action_id:
                        both = [v[i], v[j]]
                        self.model.add(self.start[j] >= self.end[i]).only_enforce_if(both)

    def _monitors(self, segments) -> None:  # type: ignore[no-untyped-def]
        md = self.model
        self.t0 = {}
        for (aid, _slot), js in segments.items():
            a = self.actions[aid]
            if aid not in self.t0:
                self.t0[aid] = md.new_int_var(0, self.horizon, f"t0_{aid}")
            md.add(self.start[js[0]] == self.t0[aid])
            md.add(self.end[js[-1]] == self.t0[aid] + ceil(a.duration_s))
            present = []
            for h, j in enumerate(js):
                lits = [v[j] for v in self.visit.values() if j in v]
                on = md.new_bool_var(f"p{j}")
                md.add(sum(lits) == on)
                present.append(on)
                if h == 0:
                    md.add(on == 1)
                else:
                    md.add(self.start[j] == self.end[js[h - 1]])
                    md.add_implication(on, present[h - 1])
                md.add(self.duration[j] >= 1).only_enforce_if(on)
                md.add(self.duration[j] == 0).only_enforce_if(~on)

    def _deliveries(self) -> None:
        """A pick is followed directly by its drop, on the same UAV."""
        for j, nd in enumerate(self.nodes):
            if nd.kind != "pick":
                continue
            for uid, v in self.visit.items():
                if j in v:
                    self.model.add(self.arcs[uid][(j, j + 1)] == v[j])

    def _pads(self, cp) -> None:  # type: ignore[no-untyped-def]
        by_station: dict[str, list] = {}
        for v in self.visit.values():
            for j, lit in v.items():
                nd = self.nodes[j]
                if nd.kind == "recharge":
                    iv = self.model.new_optional_interval_var(
                        self.start[j], self.duration[j], self.end[j], lit, f"pad{j}"
                    )
                    by_station.setdefault(nd.station.id, []).append(iv)
        stations = {s.id: s for s in self.problem.stations}
        for sid, ivs in by_station.items():
            if len(ivs) > stations[sid].pads:
                self.model.add_cumulative(ivs, [1] * len(ivs), stations[sid].pads)

    def _objective(self, horizon: int) -> None:
        md = self.model
        terms = []
        self.total_weight = 0.0
        for a in self.problem.actions:
            w = round(a.weight * WEIGHT_SCALE)
            self.total_weight += w
            if isinstance(a, MonitorAction):
                terms.append(w * (self.t0[a.id] + ceil(a.duration_s)))
                continue
            done = [j for j, nd in enumerate(self.nodes) if nd.action_id == a.id]
            if not done:
                continue
            c = md.new_int_var(0, horizon, f"c_{a.id}")
            md.add_max_equality(c, [self.end[j] for j in done])
            terms.append(w * c)
        makespan = md.new_int_var(0, horizon, "makespan")
        md.add_max_equality(makespan, list(self.home.values()))
        md.minimize(sum(terms) + round(self.total_weight) * makespan)

    def hint(self, plan: Plan) -> None:
        """Hint the routes of ``plan`` (visits and arcs; times follow), if
        the model can express them."""
        seqs = self._sequences(plan)
        if seqs is None:
            return
        for uid, seq in seqs.items():
            on = set(zip([-1, *seq], [*seq, -1], strict=True)) if seq else set()
            for key, lit in self.arcs[uid].items():
                self.model.add_hint(lit, key in on)
            for j, lit in self.visit[uid].items():
                self.model.add_hint(lit, j in seq)

    def _sequences(self, plan: Plan) -> dict[str, list[int]] | None:
        """Per UAV, the model nodes its steps visit in order (None if
        inexpressible). Monitoring steps of a slot map to its segments in
        time order across UAVs."""
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
            free: dict[tuple, list[int]] = {}
            for j in self.visit.get(up.uav_id, {}):
                nd = self.nodes[j]
                key = (nd.kind, nd.station.id if nd.station else nd.action_id, nd.index)
                free.setdefault(key, []).append(j)
            seq: list[int] = []
            for n, s in enumerate(up.steps):
                if s.kind in ("wait", "home"):
                    continue
                if s.kind == "monitor":
                    js = self.segments.get((s.action_id, s.index), [])
                    h = segment[(up.uav_id, n)]
                    if h >= len(js) or js[h] not in self.visit[up.uav_id]:
                        return None
                    seq.append(js[h])
                    continue
                key = (s.kind, s.station if s.kind == "recharge" else s.action_id, s.index)
                if not free.get(key):
                    return None
                seq.append(free[key].pop(0))
            out[up.uav_id] = seq
        return out

    def export(self, solver) -> Plan:  # type: ignore[no-untyped-def]
        """The solution as a plan document (times and energy in floats)."""
        uavs = []
        for u in self.problem.uavs:
            uavs.append(UavPlan(uav_id=u.id, steps=tuple(self._steps(solver, u))))
        plan = Plan(uavs=tuple(uavs))
        return msgspec.structs.replace(plan, metrics=compute_metrics(self.problem, plan))

    def _steps(self, solver, u: Uav) -> list[Step]:  # type: ignore[no-untyped-def]
        lits = self.arcs[u.id]
        succ = {i: j for (i, j), lit in lits.items() if solver.boolean_value(lit)}
        t = self.types[u.type]
        run = _Run(u, t, self.problem.now_s)
        i = -1
        while succ.get(i, -1) != -1:
            j = succ[i]
            nd = self.nodes[j]
            start, end = solver.value(self.start[j]), solver.value(self.end[j])
            run.visit(nd, start + self.problem.now_s, end + self.problem.now_s)
            i = j
        if run.steps:
            home = next(s for s in self.problem.stations if s.id == u.home_station)
            run.fly_home(home)
        return run.steps


class _Run:
    """Builds one UAV's steps from its visits, tracking time and energy."""

    def __init__(self, u: Uav, t: UavType, now: float) -> None:
        self.t = t
        self.pos, self.time, self.e = u.position_m, now, u.energy_wh
        self.landed = not u.airborne
        self.steps: list[Step] = []

    def _flight(self, to: Vec3) -> tuple[float, float]:
        d = dist(self.pos, to)
        return d, float(ceil(d / self.t.cruise_speed_mps - 1e-9))

    def _step(self, kind: str, arrive: float, end: float, pos: Vec3, d: float, **kw) -> None:  # type: ignore[no-untyped-def]
        self.steps.append(
            Step(
                kind=kind,  # type: ignore[arg-type]
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

    def visit(self, nd: _Node, start: float, end: float) -> None:
        """Fly to ``nd`` (waiting first if early) and serve it from ``start`` to ``end``."""
        t = self.t
        d, tt = self._flight(nd.pos)
        if nd.kind == "recharge":
            self.e -= t.flight_power_w * tt / 3600.0
            st = nd.station
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
