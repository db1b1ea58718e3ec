"""Hold points: where UAVs of different routes could hover at once (tool
stations for picks, workers for drops, inspection waypoints, and beside
each monitoring slot where a UAV waits after its segment).

Points nearer each other than the problem's separation (in a chain) form
one group; a group is a resource of the shared
:class:`~ground_station.planner.pads.Pads` taken by one UAV at a time,
numbered after the charging stations. Actions added later (a live session)
add their points; one that links groups merges them, and the caller moves
the merged groups' bookings (:meth:`Pads.merge`).
"""

from __future__ import annotations

from math import dist

from ground_station.planner.model import (
    WAIT_ASIDE_M,
    DeliverJob,
    InspectJob,
    Job,
    MonitorJob,
    Problem,
    Vec3,
    slot_position,
)

_NEIGHBOURS = [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)]


class HoldPoints:
    """Point -> resource index, grouped by separation. A monitoring slot
    stands for the point beside it where a UAV waits after its segment."""

    __slots__ = ("_aside", "_cell", "_grid", "_group", "_next", "_parent", "separation_m")

    def __init__(self, problem: Problem, first: int) -> None:
        self.separation_m = problem.separation_m
        self._cell = max(self.separation_m, 1e-6)
        self._grid: dict[tuple[int, int, int], list[Vec3]] = {}
        self._group: dict[Vec3, int] = {}
        self._parent: dict[int, int] = {}  # merged group -> the group it joined
        self._aside: dict[Vec3, Vec3] = {}  # monitoring slot -> where a UAV waits
        self._next = first
        for ts in problem.tool_stations:
            self._add(ts.position_m)
        for a in problem.actions:
            self.add_action(a)

    def get(self, pos: Vec3) -> int | None:
        """The resource index of ``pos``, None if it is no hold point."""
        g = self._group.get(self._aside.get(pos, pos))
        return None if g is None else self._root(g)

    def _root(self, g: int) -> int:
        while g in self._parent:
            g = self._parent[g]
        return g

    def add_action(self, action: Job) -> list[tuple[int, int]]:
        """Register the points ``action`` holds UAVs at; the groups this
        merged, as ``(merged, joined)`` pairs."""
        if isinstance(action, DeliverJob):
            return self._add(action.worker_m)
        if isinstance(action, InspectJob):
            return [m for w in action.waypoints for m in self._add(w.position_m)]
        merged = []
        if isinstance(action, MonitorJob):
            for slot in range(action.k):
                aside = slot_position(action, slot, WAIT_ASIDE_M)
                self._aside[slot_position(action, slot)] = aside
                merged += self._add(aside)
        return merged

    def _add(self, p: Vec3) -> list[tuple[int, int]]:
        if p in self._group:
            return []
        x, y, z = (int(c // self._cell) for c in p)
        near = {
            self._root(self._group[q])
            for i, j, k in _NEIGHBOURS
            for q in self._grid.get((x + i, y + j, z + k), ())
            if dist(p, q) < self.separation_m
        }
        merged = []
        if near:
            g = min(near)
            merged = [(h, g) for h in near if h != g]
            self._parent.update(merged)
        else:
            g, self._next = self._next, self._next + 1
        self._group[p] = g
        self._grid.setdefault((x, y, z), []).append(p)
        return merged
