"""The CP-SAT model of one problem (see the package docstring)."""

from __future__ import annotations

from math import ceil, dist
from typing import TYPE_CHECKING

from ground_station.planner.model import MonitorJob, Problem, Uav
from linecrew.planner_tools.reference.nodes import Node, clusters, nodes_of, ticks, units

if TYPE_CHECKING:
    from types import ModuleType

    from ortools.sat.python.cp_model import IntVar, LinearExpr, LiteralT

WEIGHT_SCALE = 100
"""Action weights are scaled to integers with this factor."""


class Model:
    """Variables and constraints, built in the constructor: per node its
    start, end, departure and energy; per UAV a circuit of arc literals."""

    def __init__(
        self,
        cp: ModuleType,
        problem: Problem,
        nodes: list[Node],
        segments: dict[tuple[str, int], list[int]],
        horizon_s: float | None = None,
    ) -> None:
        """``cp`` is ``ortools.sat.python.cp_model`` (imported lazily by the caller)."""
        self.problem = problem
        self.nodes = nodes
        self.segments = segments
        self.types = {t.id: t for t in problem.uav_types}
        self.model = md = cp.CpModel()
        self.monitors = {a.id: a for a in problem.actions if isinstance(a, MonitorJob)}
        self.horizon = horizon = ticks(horizon_s) if horizon_s else self._horizon()
        n = len(nodes)
        self.start = [md.new_int_var(0, horizon, f"s{j}") for j in range(n)]
        self.end = [md.new_int_var(0, horizon, f"f{j}") for j in range(n)]
        self.dep = [md.new_int_var(0, horizon, f"l{j}") for j in range(n)]
        cap = max(units(t.battery_wh) for t in problem.uav_types)
        self.energy = [md.new_int_var(0, cap, f"e{j}") for j in range(n)]
        self.duration = [self._duration(j, horizon) for j in range(n)]
        self.home = {u.id: md.new_int_var(0, horizon, f"home_{u.id}") for u in problem.uavs}
        self.arcs: dict[str, dict[tuple[int, int], IntVar]] = {}
        self.visit: dict[str, dict[int, IntVar]] = {}
        for u in problem.uavs:
            self._route(u)
        self._cover_once()
        self._monitors()
        self._deliveries()
        self._pads()
        self._holds()
        self._objective(horizon)

    def _horizon(self) -> int:
        p = self.problem
        span = sum(n.service_s for n in self.nodes) + sum(
            a.duration_s for a in p.actions if isinstance(a, MonitorJob)
        )
        far = max((dist(a.pos, b.pos) for a in self.nodes for b in self.nodes), default=0.0) + max(
            (dist(u.position_m, n.pos) for u in p.uavs for n in self.nodes), default=0.0
        )
        slow = min(t.cruise_speed_mps for t in p.uav_types)
        charge = max((s.full_charge_s + s.swap_s for s in p.stations), default=0.0)
        hops = len(self.nodes) + 2
        return ticks(span + hops * (far / slow + charge) + 3600)

    def _duration(self, j: int, horizon: int) -> IntVar | int:
        node = self.nodes[j]
        md = self.model
        d: IntVar | int
        if node.kind == "monitor" or (
            node.kind == "recharge" and node.recharge_station.recharge == "charge"
        ):
            d = md.new_int_var(0, horizon, f"d{j}")
        elif node.kind == "recharge":
            d = ticks(node.recharge_station.swap_s)
        else:
            d = node.service_s
        md.add(self.end[j] == self.start[j] + d)
        md.add(self.dep[j] >= self.end[j])
        md.add(self.start[j] >= node.release_s)
        return d

    def _route(self, u: Uav) -> None:
        """One circuit per UAV (circuit node 0 is its start and its home),
        with time and energy along every arc."""
        md = self.model
        t = self.types[u.type]
        mine = nodes_of(self.problem, self.nodes, u.id)
        cap = units(t.battery_wh)
        reserve = units(self.problem.reserve_fraction * t.battery_wh) + 1
        home = next(s for s in self.problem.stations if s.id == u.home_station).position_m
        arcs: list[tuple[int, int, LiteralT]] = []
        lits: dict[tuple[int, int], IntVar] = {}
        visit: dict[int, IntVar] = {}
        used = md.new_bool_var(f"used_{u.id}")
        arcs.append((0, 0, ~used))
        flights: list[tuple[int, IntVar]] = []
        for j in mine:
            lit = md.new_bool_var(f"v_{u.id}_{j}")
            visit[j] = lit
            arcs.append((j + 1, j + 1, ~lit))
            md.add(self.energy[j] >= reserve).only_enforce_if(lit)
            md.add(self.energy[j] <= cap).only_enforce_if(lit)
            md.add_implication(lit, used)
        points = [(-1, u.position_m), *((j, self.nodes[j].pos) for j in mine)]
        for i, pi in points:
            for j, pj in [*((j, self.nodes[j].pos) for j in mine), (-1, home)]:
                if i == j:
                    continue
                lit = md.new_bool_var(f"x_{u.id}_{i}_{j}")
                arcs.append((i + 1, j + 1, lit))
                lits[(i, j)] = lit
                tt = ticks(dist(pi, pj) / t.cruise_speed_mps)
                self._arc(lit, u, i, j, tt, reserve)
                flights.append((tt, lit))
        md.add_circuit(arcs)
        self.arcs[u.id] = lits
        self.visit[u.id] = visit
        busy = self._busy(u, visit)
        md.add(self.home[u.id] >= sum(tt * lit for tt, lit in flights) + sum(busy.values()))
        self._energy_budget(u, flights, busy, reserve)

    def _busy(self, u: Uav, visit: dict[int, IntVar]) -> dict[int, LinearExpr | int]:
        """Per visit, the time ``u`` spends there (for the redundant workload
        bound: a UAV is home no earlier than its flights and visits add up to)."""
        out: dict[int, LinearExpr | int] = {}
        for j, lit in visit.items():
            d = self.duration[j]
            if isinstance(d, int):
                out[j] = d * lit
                continue
            mine = self.model.new_int_var(0, self.horizon, f"b_{u.id}_{j}")
            self.model.add(mine == d).only_enforce_if(lit)
            self.model.add(mine == 0).only_enforce_if(~lit)
            out[j] = mine
        return out

    def _energy_budget(
        self,
        u: Uav,
        flights: list[tuple[int, IntVar]],
        busy: dict[int, LinearExpr | int],
        reserve: int,
    ) -> None:
        """Redundant: what ``u`` flies and hovers is at most its charge above
        the reserve plus what its recharges add (each at most to full, at a
        charge station at most the charging rate times its duration)."""
        md = self.model
        t = self.types[u.type]
        cap = units(t.battery_wh)
        flight, hover = ceil(t.flight_power_w), ceil(t.hover_power_w)
        used: list[LinearExpr | int] = [flight * tt * lit for tt, lit in flights]
        gains = []
        for j, spent in busy.items():
            nd = self.nodes[j]
            if nd.kind != "recharge":
                used.append(hover * spent)
                continue
            g = md.new_int_var(0, cap - reserve, f"g_{u.id}_{j}")
            md.add(g <= (cap - reserve) * self.visit[u.id][j])
            if nd.recharge_station.recharge == "charge":
                md.add(g * ticks(nd.recharge_station.full_charge_s) <= cap * spent)
            gains.append(g)
        md.add(sum(used) <= units(u.energy_wh) - reserve + sum(gains))

    def _arc(self, lit: IntVar, u: Uav, i: int, j: int, tt: int, reserve: int) -> None:
        """Arc ``i -> j`` (-1: the UAV's start, or the flight home). After a
        service the UAV hovers where it is until it leaves (``dep``), then
        flies straight to ``j``; before a recharge or home it leaves at once
        and waits landed at the station for a pad."""
        md = self.model
        t = self.types[u.type]
        flight, hover = ceil(t.flight_power_w), ceil(t.hover_power_w)
        fly = flight * tt
        start = i == -1
        t_i = 0 if start else self.end[i]
        e_i = units(u.energy_wh) if start else self.energy[i]
        on_pad = (start and not u.airborne) or (not start and self.nodes[i].kind == "recharge")
        to_station = j == -1 or self.nodes[j].kind == "recharge"
        if not start and not on_pad and to_station:
            md.add(self.dep[i] == self.end[i]).only_enforce_if(lit)
        if j == -1:  # the flight home
            md.add(self.home[u.id] == t_i + tt).only_enforce_if(lit)
            md.add(e_i - fly >= reserve).only_enforce_if(lit)
            return
        if to_station:
            md.add(self.start[j] >= t_i + tt).only_enforce_if(lit)
            md.add(e_i - fly >= reserve).only_enforce_if(lit)
            st = self.nodes[j].recharge_station
            if st.recharge == "charge":
                md.add(self.duration[j] >= 1).only_enforce_if(lit)
                full = ticks(st.full_charge_s)
                cap = units(t.battery_wh)
                md.add(
                    self.energy[j] * full <= (e_i - fly) * full + cap * self.duration[j]
                ).only_enforce_if(lit)
            return
        if on_pad or start:
            md.add(self.start[j] >= t_i + tt).only_enforce_if(lit)
        else:
            md.add(self.start[j] == self.dep[i] + tt).only_enforce_if(lit)
        wait = 0 if on_pad else self.start[j] - t_i - tt
        md.add(
            self.energy[j] <= e_i - fly - hover * wait - hover * self.duration[j]
        ).only_enforce_if(lit)

    def _cover_once(self) -> None:
        """Every service node but optional monitoring segments is visited
        once; a UAV's recharge visits of a station are used in order."""
        for j, nd in enumerate(self.nodes):
            if nd.kind not in ("recharge", "monitor"):
                self.model.add_exactly_one(v[j] for v in self.visit.values() if j in v)
        for v in self.visit.values():
            prev = None
            for j in sorted(v):
                nd = self.nodes[j]
                if nd.kind != "recharge":
                    continue
                if prev is not None and self.nodes[prev].station is nd.station:
                    self.model.add_implication(v[j], v[prev])
                    self.model.add(self.start[j] >= self.end[prev]).only_enforce_if(v[j])
                prev = j

    def _monitors(self) -> None:
        """Slots of an action start together at ``t0``; a slot's segments
        follow each other with no gap (the relief arrives as the other leaves)."""
        md = self.model
        self.t0: dict[str, IntVar] = {}
        for (aid, _slot), js in self.segments.items():
            a = self.monitors[aid]
            if aid not in self.t0:
                self.t0[aid] = md.new_int_var(0, self.horizon, f"t0_{aid}")
            md.add(self.start[js[0]] == self.t0[aid])
            md.add(self.end[js[-1]] == self.t0[aid] + ticks(a.duration_s))
            present = []
            for h, j in enumerate(js):
                on = md.new_bool_var(f"p{j}")
                md.add(sum(v[j] for v in self.visit.values() if j in v) == on)
                present.append(on)
                if h == 0:
                    md.add(on == 1)
                else:
                    md.add(self.start[j] == self.end[js[h - 1]])
                    md.add_implication(on, present[h - 1])
                md.add(self.duration[j] >= 1).only_enforce_if(on)
                md.add(self.duration[j] == 0).only_enforce_if(~on)

    def _deliveries(self) -> None:
        """Pick and drop on the same UAV, the drop later; other work (and
        recharges) may come between, but a UAV carries one tool at a time."""
        md = self.model
        carry: dict[str, list] = {}
        for j, nd in enumerate(self.nodes):
            if nd.kind != "pick":
                continue
            md.add(self.start[j + 1] >= self.end[j])
            for uid, v in self.visit.items():
                if j in v:
                    md.add(v[j] == v[j + 1])
                    iv = md.new_optional_interval_var(
                        self.start[j],
                        md.new_int_var(0, self.horizon, f"cs_{uid}_{j}"),
                        self.end[j + 1],
                        v[j],
                        f"carry_{uid}_{j}",
                    )
                    carry.setdefault(uid, []).append(iv)
        for ivs in carry.values():
            if len(ivs) > 1:
                md.add_no_overlap(ivs)

    def _pads(self) -> None:
        by_station: dict[str, list] = {}
        for v in self.visit.values():
            for j, lit in v.items():
                nd = self.nodes[j]
                if nd.kind == "recharge":
                    iv = self.model.new_optional_interval_var(
                        self.start[j], self.duration[j], self.end[j], lit, f"pad{j}"
                    )
                    by_station.setdefault(nd.recharge_station.id, []).append(iv)
        stations = {s.id: s for s in self.problem.stations}
        for sid, ivs in by_station.items():
            if len(ivs) > stations[sid].pads:
                self.model.add_cumulative(ivs, [1] * len(ivs), stations[sid].pads)

    def _holds(self) -> None:
        """Separation: at a shared point one UAV hovers at a time, from its
        arrival until it leaves."""
        md = self.model
        for group in clusters(self.nodes, self.problem.separation_m):
            ivs = [
                md.new_interval_var(
                    self.start[j], md.new_int_var(0, self.horizon, f"hs{j}"), self.dep[j], f"h{j}"
                )
                for j in group
            ]
            md.add_no_overlap(ivs)

    def _way_home(self, j: int) -> int:
        """The shortest flight (ticks) from node ``j`` to a home, over the
        UAVs that may visit it."""
        homes = {s.id: s.position_m for s in self.problem.stations}
        return min(
            (
                ticks(dist(self.nodes[j].pos, homes[u.home_station]) / t.cruise_speed_mps)
                for u in self.problem.uavs
                if j in self.visit[u.id]
                for t in (self.types[u.type],)
            ),
            default=0,
        )

    def _objective(self, horizon: int) -> None:
        """``api.score`` times the total weight: sum(weight x completion) +
        total weight x makespan."""
        md = self.model
        terms = []
        self.total_weight = 0.0
        for a in self.problem.actions:
            w = round(a.weight * WEIGHT_SCALE)
            self.total_weight += w
            if isinstance(a, MonitorJob):
                terms.append(w * (self.t0[a.id] + ticks(a.duration_s)))
                continue
            done = [
                j for j, nd in enumerate(self.nodes) if nd.action_id == a.id and nd.kind != "pick"
            ]
            if not done:
                continue
            c = md.new_int_var(0, horizon, f"c_{a.id}")
            md.add_max_equality(c, [self.end[j] for j in done])
            terms.append(w * c)
        makespan = md.new_int_var(0, horizon, "makespan")
        md.add_max_equality(makespan, list(self.home.values()))
        for j, nd in enumerate(self.nodes):  # redundant: someone flies home from j
            if nd.kind != "recharge":
                md.add(makespan >= self.end[j] + self._way_home(j))
        md.minimize(sum(terms) + round(self.total_weight) * makespan)
