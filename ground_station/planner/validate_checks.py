"""The validator's fleet-wide checks (see ``validate``): where each UAV
ends, shared pads, separation between hovering UAVs, and that every action
is done exactly once. Like ``validate``, independent of the planner's
scheduling code."""

from __future__ import annotations

from collections import defaultdict
from math import cos, dist, pi, radians, sin
from typing import NamedTuple

from ground_station.planner.model import (
    DeliverJob,
    InspectJob,
    MonitorJob,
    Problem,
    Station,
    Uav,
    Vec3,
)
from ground_station.planner.result import Solution, Step, Violation

TOL_S = 1e-3
TOL_WH = 1e-3
TOL_M = 0.01


class Hold(NamedTuple):
    """A hover: from, until, where, which UAV (ordered by start)."""

    start_s: float
    end_s: float
    position_m: Vec3
    uav_id: str


class Segment(NamedTuple):
    """A monitoring step: its slot, from, until."""

    slot: int
    start_s: float
    end_s: float


PadUse = dict[str, list[tuple[float, float]]]
"""Station id -> the (from, until) intervals a pad there is taken."""


class Report:
    """The violations found so far."""

    def __init__(self) -> None:
        self.items: list[Violation] = []

    def add(
        self, code: str, detail: str, uav: str | None = None, action: str | None = None
    ) -> None:
        """Record a violation."""
        self.items.append(Violation(code=code, detail=detail, uav_id=uav, action_id=action))


def slot_of(act: MonitorJob, slot: int, aside_m: float = 0.0) -> tuple[float, float, float]:
    """Where slot ``slot`` is, from the action's definition (not the
    planner's code); ``aside_m`` along the ring (counter-clockwise)."""
    x, y, z = act.worker_m
    bearing = radians(act.bearing_deg) + 2 * pi * slot / act.k
    r = act.standoff_m
    return (
        x + r * cos(bearing) - aside_m * sin(bearing),
        y + r * sin(bearing) + aside_m * cos(bearing),
        z + act.height_m,
    )


def check_end(
    rep: Report,
    problem: Problem,
    u: Uav,
    steps: tuple[Step, ...],
    stations: dict[str, Station],
    pad_use: PadUse,
) -> None:
    """``problem.end``: the UAV ends landed at home, or (``any_station``) at
    a station, where away from home it holds a pad from its landing on."""
    last = steps[-1] if steps else None
    pos = last.position_m if last else u.position_m
    at = [s for s in stations.values() if dist(s.position_m, pos) <= TOL_M]
    landed = (last.kind in ("recharge", "home", "wait") and bool(at)) if last else not u.airborne
    if landed and any(s.id == u.home_station for s in at):
        return
    if problem.end == "home":
        rep.add("not_home", f"ends at {pos}, not on {u.home_station}", u.id)
    elif not landed or not at:
        rep.add("end_station", f"ends at {pos}, not on a station", u.id)
    else:
        pad_use[at[0].id].append((last.end_s if last else problem.now_s, float("inf")))


def check_pads(rep: Report, stations: dict[str, Station], pad_use: PadUse) -> None:
    """Never more UAVs on a station's pads than it has."""
    for sid, ivs in pad_use.items():
        events = sorted([(a + TOL_S, 1) for a, _ in ivs] + [(b, -1) for _, b in ivs])
        level = 0
        for at, delta in events:
            level += delta
            if level > stations[sid].pads:
                rep.add("pad_capacity", f"station {sid}: {level} UAVs on pads at {at:.1f} s")
                break


def check_separation(rep: Report, separation_m: float, holds: list[Hold]) -> None:
    """No two UAVs hover nearer than ``separation_m`` at once."""
    active: list[Hold] = []
    for hold in sorted(holds):
        start, end, where, uid = hold
        active = [a for a in active if a.end_s > start + TOL_S]
        for _, other_end, there, other in active:
            if other != uid and dist(where, there) < separation_m - TOL_M:
                rep.add(
                    "separation",
                    f"{dist(where, there):.2f} m from {other} "
                    f"{start:.1f}-{min(end, other_end):.1f} s",
                    uid,
                )
        active.append(hold)


def check_actions(
    rep: Report,
    problem: Problem,
    plan: Solution,
    monitor_iv: dict[str, list[Segment]],
    waypoints: dict[str, list[int]],
    delivered: dict[str, int],
) -> None:
    """Every action (part) planned exactly once, or listed unplaced; every
    monitoring covered from one start for its whole duration."""
    unplaced: dict[str, set[int | None]] = defaultdict(set)
    for x in plan.unplaced:
        unplaced[x.action_id].add(x.part)
    for a in problem.actions:
        whole_unplaced = None in unplaced[a.id]
        if isinstance(a, InspectJob):
            _check_waypoints(rep, a, waypoints.get(a.id, []), unplaced[a.id])
        elif isinstance(a, DeliverJob):
            expect = 0 if whole_unplaced else 1
            if delivered.get(a.id, 0) != expect:
                rep.add("deliver_count", f"delivered {delivered.get(a.id, 0)} times", action=a.id)
        elif isinstance(a, MonitorJob):
            _check_monitoring(rep, a, monitor_iv.get(a.id, []), whole_unplaced)


def _check_waypoints(
    rep: Report, a: InspectJob, inspected: list[int], unplaced: set[int | None]
) -> None:
    """Each waypoint inspected once, unless done or unplaced."""
    counts: dict[int, int] = defaultdict(int)
    for i in inspected:
        counts[i] += 1
    for i in range(len(a.waypoints)):
        expect = 0 if (i in a.done or i in unplaced or None in unplaced) else 1
        if counts[i] != expect:
            code = "waypoint_duplicate" if counts[i] > expect else "waypoint_missing"
            rep.add(code, f"waypoint {i} inspected {counts[i]} times", action=a.id)


def _check_monitoring(rep: Report, a: MonitorJob, ivs: list[Segment], whole_unplaced: bool) -> None:
    """All slots start together (T0) and stay covered for ``duration_s``."""
    if whole_unplaced:
        if ivs:
            rep.add("unplaced_but_planned", "monitoring planned and unplaced", action=a.id)
        return
    if not ivs:
        rep.add("monitor_missing", "monitoring not planned", action=a.id)
        return
    t0 = min(seg.start_s for seg in ivs)
    if t0 < a.release_s - TOL_S:
        rep.add("before_release", "monitoring starts before release", action=a.id)
    for slot in range(a.k):
        _check_slot(rep, a, slot, t0, sorted(seg for seg in ivs if seg.slot == slot))


def _check_slot(rep: Report, a: MonitorJob, slot: int, t0: float, mine: list[Segment]) -> None:
    """Slot ``slot``'s segments (``mine``, by start) cover it from ``t0`` on."""
    if not mine or mine[0].start_s > t0 + TOL_S:
        rep.add("monitor_not_synchronised", f"slot {slot} not started at T0", action=a.id)
        return
    covered = t0
    for seg in mine:
        if seg.start_s > covered + TOL_S:
            detail = f"slot {slot} uncovered {covered:.1f}-{seg.start_s:.1f}"
            rep.add("monitor_gap", detail, action=a.id)
        covered = max(covered, seg.end_s)
    if covered < t0 + a.duration_s - TOL_S:
        rep.add("monitor_gap", f"slot {slot} ends early at {covered:.1f}", action=a.id)
