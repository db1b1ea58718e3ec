"""The reference model's nodes: what a UAV may visit, in whole seconds."""

from __future__ import annotations

import dataclasses
from math import ceil, dist
from typing import Literal

from ground_station.planner.model import (
    DeliverJob,
    InspectJob,
    MonitorJob,
    Problem,
    Station,
    Vec3,
    slot_position,
)

SEGMENTS = 3
"""Segments a monitoring slot may be split into (two hand-overs)."""
RECHARGES = 2
"""Optional recharge visits per UAV and station."""
TICK_S = 0.1
"""The model's time unit (energy is in watt-ticks): flights and services are
rounded up to whole ticks."""
MAX_ARCS = 60_000
"""Refuse problems whose routing arcs (summed over UAVs) exceed this."""
NodeKind = Literal["inspect", "monitor", "pick", "deliver", "recharge"]
SERVICE_KIND = {"inspect": "inspect", "monitor": "monitor", "pick": "deliver", "deliver": "deliver"}


def ticks(seconds: float) -> int:
    """``seconds`` rounded up to whole ticks."""
    return ceil(seconds / TICK_S - 1e-6)


def units(wh: float) -> int:
    """Watt-hours in the model's energy unit (watt-ticks), rounded down."""
    return int(wh * 3600.0 / TICK_S + 1e-6)


@dataclasses.dataclass(frozen=True)
class Node:
    """One visit (times in ticks): a waypoint, a monitoring segment, a pick or drop, or a
    recharge (those belong to one UAV: ``owner``)."""

    kind: NodeKind
    pos: Vec3
    service_s: int = 0
    action_id: str | None = None
    index: int | None = None
    tool: str | None = None
    station: Station | None = None
    owner: str | None = None
    release_s: int = 0

    @property
    def recharge_station(self) -> Station:
        """The station of a recharge node."""
        if self.station is None:
            raise ValueError(f"a {self.kind} node has no station")
        return self.station


def build_nodes(problem: Problem) -> tuple[list[Node], dict[tuple[str, int], list[int]]]:
    """Service and recharge nodes; per (monitor action, slot) its segment nodes."""
    nodes: list[Node] = []
    segments: dict[tuple[str, int], list[int]] = {}
    tools = {t.id: t for t in problem.tool_stations}
    for a in problem.actions:
        rel = ticks(a.release_s - problem.now_s) if a.release_s > problem.now_s else 0
        if isinstance(a, InspectJob):
            for i, w in enumerate(a.waypoints):
                if i not in a.done:
                    nodes.append(
                        Node("inspect", w.position_m, ticks(w.service_s), a.id, i, release_s=rel)
                    )
        elif isinstance(a, MonitorJob):
            for slot in range(a.k):
                segments[(a.id, slot)] = list(range(len(nodes), len(nodes) + SEGMENTS))
                pos = slot_position(a, slot)
                nodes.extend(
                    Node("monitor", pos, 0, a.id, slot, release_s=rel) for _ in range(SEGMENTS)
                )
        elif isinstance(a, DeliverJob):
            where = tools[a.tool_station].position_m
            nodes.append(Node("pick", where, ticks(a.pick_s), a.id, tool=a.tool, release_s=rel))
            nodes.append(Node("deliver", a.worker_m, ticks(a.drop_s), a.id, tool=a.tool))
    for u in problem.uavs:
        for st in problem.stations:
            if st.pads >= 1:
                nodes.extend(
                    Node("recharge", st.position_m, station=st, owner=u.id)
                    for _ in range(RECHARGES)
                )
    return nodes, segments


def nodes_of(problem: Problem, nodes: list[Node], uav_id: str) -> list[int]:
    """The nodes ``uav_id`` may visit: its own recharges and the services
    its type can do."""
    u = next(x for x in problem.uavs if x.id == uav_id)
    caps = next(t for t in problem.uav_types if t.id == u.type).capabilities
    return [
        j
        for j, nd in enumerate(nodes)
        if (nd.owner == uav_id if nd.kind == "recharge" else SERVICE_KIND[nd.kind] in caps)
    ]


def unsupported(problem: Problem, nodes: list[Node]) -> str:
    """Why the model cannot take ``problem`` ("" if it can)."""
    if any(u.running or u.tool or not u.available for u in problem.uavs):
        return "running tasks, held tools or unavailable UAVs"
    arcs = sum(len(nodes_of(problem, nodes, u.id)) ** 2 for u in problem.uavs)
    if arcs > MAX_ARCS:
        return f"{arcs} routing arcs (at most {MAX_ARCS})"
    return ""


def clusters(nodes: list[Node], separation_m: float) -> list[list[int]]:
    """Groups (two or more) of pick, drop and waypoint nodes nearer each
    other than ``separation_m``: one UAV at a time may hover there."""
    points = [j for j, nd in enumerate(nodes) if nd.kind in ("inspect", "pick", "deliver")]
    parent = {j: j for j in points}

    def root(j: int) -> int:
        while parent[j] != j:
            j = parent[j]
        return j

    for a, i in enumerate(points):
        for j in points[a + 1 :]:
            if dist(nodes[i].pos, nodes[j].pos) < separation_m:
                parent[root(j)] = root(i)
    groups: dict[int, list[int]] = {}
    for j in points:
        groups.setdefault(root(j), []).append(j)
    return [g for g in groups.values() if len(g) > 1]
