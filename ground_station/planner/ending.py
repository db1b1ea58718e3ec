"""The final leg: from a route's last state to where the UAV ends the
mission (``Problem.end``), with as many recharges on the way as needed.

The way is a shortest path in time over the charging stations (A* towards
home, Dijkstra for ``any_station``). A hop leaves a station after a swap, or
after charging just what it needs (``charge`` stations), and arrives above
the reserve; waits for a pad come from the shared ``Pads``. ``home`` ends on
the home station (its own spot: no pad); ``any_station`` on home or the
first station reached with a pad free from the landing on for good, and
another one too: a parked UAV holds its pad for good, and never takes a
station's last one, so that the others' ways home stay open.
"""

from __future__ import annotations

from heapq import heappop, heappush
from math import dist

import msgspec

from ground_station.planner.energy import EPS_S, EPS_WH, Kin, SiteMap
from ground_station.planner.model import Vec3
from ground_station.planner.pads import Ignore, Pads
from ground_station.planner.recharge import RcOption, emit_recharge
from ground_station.planner.result import Step
from ground_station.planner.state import Booking, State

PARK_S = float("inf")
"""End of a parked UAV's pad reservation."""
MARGIN_WH = 1e-4
"""Charged above what a hop needs, against rounding."""


class Label(msgspec.Struct, frozen=True, gc=False):
    """The best way found to a node: arrival there and the energy left, the
    previous node (-1 for the start) and the recharge there (None at the start)."""

    arrive_s: float
    energy_wh: float
    prev: int
    recharge: RcOption | None


class _Open(msgspec.Struct, frozen=True, order=True, gc=False):
    """A search queue entry: the node and its estimated arrival at the goal."""

    estimate_s: float
    node: int


def landing_step(k: Kin, st: State, pos: Vec3, station_id: str, d: float) -> Step:
    """The final flight from ``st`` to station ``station_id`` at ``pos``, ``d`` m away."""
    end = st.t + d / k.speed_mps
    return Step(
        kind="home",
        start_s=st.t,
        arrive_s=end,
        end_s=end,
        energy_after_wh=st.e - d * k.wh_per_m,
        position_m=pos,
        distance_m=d,
        station=station_id,
    )


def end_steps(
    k: Kin, site: SiteMap, pads: Pads, st: State, ign: Ignore
) -> tuple[list[Step], list[Booking]]:
    """Steps that end the mission from ``st`` and their reservations."""
    steps: list[Step] = []
    res: list[Booking] = []
    home = site.index.get(k.home, len(site.positions))
    way = _Way(k, site, pads, ign, home)
    goal = way.search(st)
    if goal is None:
        return _nearest_landing(k, site, st), res
    labels = way.labels
    path = [goal]
    while labels[path[-1]].prev >= 0:
        path.append(labels[path[-1]].prev)
    for node in reversed(path[:-1]):
        rc = labels[node].recharge
        assert rc is not None  # every hop but the first leaves a station
        st = emit_recharge(k, site, st, rc, steps, res)
    pos = k.home_pos if goal == home else site.positions[goal]
    d = dist(st.pos, pos)
    if st.landed and d < 1e-9:
        end = st.t
    else:
        sid = k.home if goal == home else site.charging[goal].id
        steps.append(landing_step(k, st, pos, sid, d))
        end = steps[-1].end_s
    if goal != home:
        res.append(Booking(goal, end, PARK_S))
    return steps, res


class _Way:
    """A* (Dijkstra for ``any_station``) over the charging stations and, as
    node ``n``, the home station if it is a landing spot only."""

    def __init__(self, k: Kin, site: SiteMap, pads: Pads, ign: Ignore, home: int) -> None:
        self.k, self.site, self.pads, self.ign, self.home = k, site, pads, ign, home
        self.n = n = len(site.positions)
        self.anywhere = site.end == "any_station"
        to_home = [*site.dists(k.home_pos), 0.0]
        self.h = [0.0 if self.anywhere else d / k.speed_mps for d in to_home]
        usable_wh = k.capacity_wh - k.reserve_wh
        self.reach_m = usable_wh / k.wh_per_m if k.wh_per_m > 0 else float("inf")  # one hop
        self.labels: dict[int, Label] = {}
        self.done = [False] * (n + 1)
        self.heap: list[_Open] = []

    def _dists(self, pos: Vec3) -> list[float]:
        return [*self.site.dists(pos), dist(pos, self.k.home_pos)]

    def _push(self, j: int, label: Label) -> None:
        old = self.labels.get(j)
        if old is None or label.arrive_s < old.arrive_s - EPS_S:
            self.labels[j] = label
            heappush(self.heap, _Open(label.arrive_s + self.h[j], j))

    def search(self, st: State) -> int | None:
        """The goal node reached first from ``st`` (None if none is)."""
        k = self.k
        for j, d in enumerate(self._dists(st.pos)):
            e = st.e - d * k.wh_per_m
            if (j < self.n or self.home == self.n) and (d == 0.0 or e >= k.reserve_wh - EPS_WH):
                self._push(j, Label(st.t + d / k.speed_mps, e, -1, None))
        while self.heap:
            i = heappop(self.heap).node
            if self.done[i]:
                continue
            self.done[i] = True
            t, e = self.labels[i].arrive_s, self.labels[i].energy_wh
            if i == self.home or (self.anywhere and self.pads.free_for_good(i, t, 1, self.ign)):
                return i
            if i < self.n:
                self._relax(i, t, e)
        return None

    def _relax(self, i: int, t: float, e: float) -> None:
        """Hops from station ``i``, reached at ``t`` with ``e`` Wh."""
        k, station, done, labels = self.k, self.site.charging[i], self.done, self.labels
        hops = self.site.within(i, self.reach_m)
        if self.home == self.n:
            hops = [*hops, (self.n, dist(self.site.positions[i], k.home_pos))]
        for j, d in hops:
            need = k.reserve_wh + d * k.wh_per_m + MARGIN_WH
            if done[j] or need > k.capacity_wh or need <= e:
                continue  # out of range, or flown to directly from before ``i``
            if station.recharge == "swap":
                dur, charged = station.swap_s, k.capacity_wh
            else:
                dur, charged = station.full_charge_s * (need - e) / k.capacity_wh, need
            old = labels.get(j)
            if old is not None and t + dur + d / k.speed_mps >= old.arrive_s - EPS_S:
                continue  # no earlier even without a wait for a pad
            start = self.pads.earliest(i, t, dur, self.ign)
            arrive = start + dur + d / k.speed_mps
            rc = RcOption(i, start - t, dur, e, charged, arrive, charged - d * k.wh_per_m)
            self._push(j, Label(arrive, rc.e_at_task, i, rc))


def _nearest_landing(k: Kin, site: SiteMap, st: State) -> list[Step]:
    """No way to an end: land at the nearest station (landing spots are not pads)."""
    near = site.nearest(st.pos)
    si = near.station
    if si < 0:
        return []
    return [landing_step(k, st, site.positions[si], site.charging[si].id, near.distance_m)]
