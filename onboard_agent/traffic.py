"""Where the other UAVs are, as the ground station last heard them
(``gs/traffic``), so that the agent never flies to a point another UAV
hovers at: the last line of separation after the plan's own (hold points
taken in turn, distinct slots, spots) when a plan is stale or a UAV hangs.

A route passes as it passes people (:mod:`onboard_agent.route`) the
points other UAVs hover at or are about to: the target each flies to (a
slot, a hold, a waypoint, the next leg), where each that hovers there is,
and where each unheard for a while (its agent hung or cut off) was last
heard. Where a UAV heard on its way is now is not in the way: it moves on.

Ages are in real seconds (the link clock), whatever the mission's speed-up.
Without a report (the ground station is away) nothing is known: the agent
flies its plan as before.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from onboard_agent.route import ground_distance
from onboard_agent.surroundings import horizontal_distance
from proto.geo import Point
from proto.telemetry import Traffic as TrafficReport

STALE_S = 60.0
"""A report entry older than this (as heard by the ground station, plus the
time since the report came) is forgotten."""
UNHEARD_S = 1.0
"""An entry older than this (five telemetry periods) may have flown on to
the target it was flying to: it holds that point too (a hung agent's
autopilot flies on to its last target)."""
HOVER_M = 1.0
"""A UAV heard this close to its target hovers there (or is about to)."""


class Sighting(NamedTuple):
    """A point another airborne UAV may be at."""

    uav_id: str
    where: Point
    unheard: bool  # unheard for ``UNHEARD_S``
    target: bool  # the target it was flying to, not where it was heard
    hovering: bool = False  # heard within ``HOVER_M`` of its target


class Traffic:
    """The latest traffic report, with when it came."""

    def __init__(self, uav_id: str) -> None:
        self.uav_id = uav_id
        self._report: TrafficReport | None = None
        self._received_s = 0.0

    def update(self, report: TrafficReport, now_s: float) -> None:
        """Keep ``report`` (received at ``now_s`` of the link clock)."""
        self._report, self._received_s = report, now_s

    def position(self, uav_id: str, now_s: float) -> Point | None:
        """Where ``uav_id`` was last heard airborne, if the report says so."""
        return next(
            (s.where for s in self._others(now_s) if s.uav_id == uav_id and not s.target), None
        )

    def holder(
        self, point: Point, radius_m: float, now_s: float, here: Point | None = None
    ) -> Sighting | None:
        """Another airborne UAV within ``radius_m`` of ``point``, if any (the
        nearest): where it was heard, or, unheard for ``UNHEARD_S``, the
        target it was flying to. From ``here``:

        - level with ``point``, one heard leaving it (flying to a target
          farther off) no longer holds it: a relief closes in as the UAV it
          relieves climbs away;
        - above or below it, one heard in the column between (within
          ``radius_m`` horizontally) holds it: chaos seed 13, a relief
          moved over its slot as the UAV it relieved climbed out of it;
        - one heard nearer ``point`` (ties: the lower id) on its way to it
          (:func:`_coming`) holds it: of two UAVs sent to one point, the
          nearer goes first (chaos seed 18);
        - one heard coming straight down through it (:func:`_descending`,
          a landing UAV cannot stop) holds it, however far above (chaos
          seed 15: a UAV flew in under one landing and came up against it)."""
        others = self._others(now_s)
        targets = {s.uav_id: s.where for s in others if s.target and not s.unheard}
        level = here is None or abs(here.z_m - point.z_m) <= HOVER_M

        def gap(s: Sighting) -> float:
            if s.unheard or here is None:
                return s.where.distance_to(point)
            if level and _leaving(s.where, targets.get(s.uav_id), point, radius_m):
                return math.inf
            if not level and _in_column(s.where, point, here, radius_m):
                return horizontal_distance(s.where, point)
            return s.where.distance_to(point)

        near = [(gap(s), s) for s in others if s.unheard or not s.target]
        nearest_gap, nearest = min(near, key=lambda n: n[0], default=(math.inf, None))
        if nearest_gap < radius_m:
            return nearest
        if here is None:
            return None
        heard = {s.uav_id: s.where for s in others if not s.target and not s.unheard}
        mine = (here.distance_to(point), self.uav_id)
        coming = [
            (heard[s.uav_id].distance_to(point), s.uav_id, s)
            for s in others
            if s.target and s.uav_id in heard and _coming(heard[s.uav_id], s.where, point, radius_m)
        ]
        first = [c for c in coming if c[:2] < mine]
        if first:
            return min(first, key=lambda c: c[:2])[2]
        return next(
            (
                s
                for s in others
                if s.target
                and s.uav_id in heard
                and _descending(heard[s.uav_id], s.where, point, radius_m)
            ),
            None,
        )

    def obstacles(self, now_s: float, track: tuple[Point, Point] | None = None) -> list[Point]:
        """Where other airborne UAVs hover or are about to: heard at their
        target, the targets they fly to, and where those unheard for
        ``UNHEARD_S`` were heard. Chaos seeds 14 and 17: a UAV crossing
        beside a worker at the height that clears people passed 0.92 m
        from one arriving at (or watching from) its slot beside that worker.

        The point a heard UAV climbs to counts only for UAVs after it in id
        order: two UAVs climbing side by side, each over the other's climb
        target, went on raising their crossings to 695 m (chaos seed 12).
        So does where a heard UAV on its way is now and, given this UAV's
        own ``track`` (from, to), the point of the other's track nearest it:
        of two UAVs whose tracks cross, the later in id order crosses over
        the other, which flies on (chaos seed 20: two swapping slots met
        head on at 6 m; seed 17: two re-routed mid-climb to targets at one
        height crossed there, each already past where the other was heard)."""
        others = self._others(now_s)
        heard = {s.uav_id: s.where for s in others if not s.target}
        out = [
            s.where
            for s in others
            if _stays(s, heard) or s.uav_id < self.uav_id  # a climb target, or where one is now
        ]
        return out + self._tracks(others, heard, track)

    def ahead(self, now_s: float, track: tuple[Point, Point] | None = None) -> list[Point]:
        """The obstacles another UAV stays at (:func:`_stays`) or has yet to
        reach on its track, not where one on its way is now (it moves on:
        a UAV leaving the slot its relief flies to)."""
        others = self._others(now_s)
        heard = {s.uav_id: s.where for s in others if not s.target}
        stays = [s.where for s in others if _stays(s, heard)]
        return stays + [
            p
            for p in self._tracks(others, heard, track)
            if all(p.distance_to(where) >= HOVER_M for where in heard.values())
        ]

    def verticals(self, now_s: float) -> list[Point]:
        """Where the UAVs after this one in id order that climb or descend
        straight are: this UAV waits for them to pass clear of its level legs
        (:func:`onboard_agent.route.next_leg`; their climb targets are no
        obstacles for it, and where one descending is now is none either:
        chaos seed 13, an earlier UAV turned level across the column of a
        later one that had just begun to descend in it and passed 1.00 m
        from it)."""
        others = self._others(now_s)
        heard = {s.uav_id: s.where for s in others if not s.target and not s.unheard}
        return [
            heard[s.uav_id]
            for s in others
            if s.target
            and s.uav_id > self.uav_id
            and s.uav_id in heard
            and abs(s.where.z_m - heard[s.uav_id].z_m) > HOVER_M
            and horizontal_distance(s.where, heard[s.uav_id]) < HOVER_M
        ]

    def movers(self, now_s: float) -> list[Point]:
        """Where the UAVs after this one in id order are heard on their way
        (not hovering): this UAV holds rather than climb or descend past one
        (:func:`onboard_agent.route.next_leg`); each sees this one in its
        way (:meth:`obstacles`) and moves clear of it."""
        others = self._others(now_s)
        flying_to = {s.uav_id for s in others if s.target}
        return [
            s.where
            for s in others
            if not s.target
            and not s.unheard
            and not s.hovering
            and s.uav_id > self.uav_id
            and s.uav_id in flying_to
        ]

    def _tracks(
        self, others: list[Sighting], heard: dict[str, Point], track: tuple[Point, Point] | None
    ) -> list[Point]:
        """Of each UAV before this one in id order heard on its way, the
        point of its track nearest ``track``."""
        if track is None:
            return []
        return [
            _nearest_on(heard[s.uav_id], s.where, *track)
            for s in others
            if s.target and not s.unheard and s.uav_id < self.uav_id and s.uav_id in heard
        ]

    def _others(self, now_s: float) -> list[Sighting]:
        """Where the other airborne UAVs of the report may be: where each
        was heard, and the target each was flying to."""
        if self._report is None:
            return []
        since = now_s - self._received_s
        out = []
        for e in self._report.uavs:
            age = e.age_s + since
            if not e.airborne or e.uav_id == self.uav_id or age > STALE_S:
                continue
            unheard = age > UNHEARD_S
            hovering = e.target is not None and e.position.distance_to(e.target) < HOVER_M
            out.append(Sighting(e.uav_id, e.position, unheard, target=False, hovering=hovering))
            if e.target is not None:
                out.append(Sighting(e.uav_id, e.target, unheard, target=True))
        return out


def _stays(s: Sighting, heard: dict[str, Point]) -> bool:
    """Whether another UAV stays at ``s``: heard hovering there, unheard
    (its autopilot holds its last target), or the target it flies to, unless
    a climb (``heard`` maps each UAV to where it was heard)."""
    if s.unheard or s.hovering:
        return True
    where = heard.get(s.uav_id)
    climbing = where is not None and s.where.z_m > where.z_m + HOVER_M
    return s.target and not climbing


def _nearest_on(a: Point, b: Point, c: Point, d: Point) -> Point:
    """The point of track ``a``-``b`` (its height interpolated) nearest,
    horizontally, to track ``c``-``d``: at an end of either, or where the
    two cross."""
    ax, ay, bx, by = a.x_m, a.y_m, b.x_m, b.y_m
    ux, uy = bx - ax, by - ay
    length2 = ux * ux + uy * uy
    if length2 == 0.0:
        return a

    def along(x: float, y: float) -> float:
        return max(0.0, min(1.0, ((x - ax) * ux + (y - ay) * uy) / length2))

    candidates = [0.0, 1.0, along(c.x_m, c.y_m), along(d.x_m, d.y_m)]
    vx, vy = d.x_m - c.x_m, d.y_m - c.y_m
    cross = ux * vy - uy * vx
    if cross != 0.0:
        t = ((c.x_m - ax) * vy - (c.y_m - ay) * vx) / cross
        u = ((c.x_m - ax) * uy - (c.y_m - ay) * ux) / cross
        if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
            candidates.append(t)

    def at(t: float) -> Point:
        return Point(x_m=ax + t * ux, y_m=ay + t * uy, z_m=a.z_m + t * (b.z_m - a.z_m))

    return min((at(t) for t in candidates), key=lambda q: ground_distance(q, c, d))


def _coming(where: Point, target: Point, point: Point, radius_m: float) -> bool:
    """Whether a UAV heard at ``where`` flying to ``target`` is on its way
    to ``point`` (or to above it, to come down): moving, not climbing, its
    target within ``radius_m`` of ``point`` horizontally and at its height
    or above. A UAV hovering (holding where it is) is not on its way."""
    return (
        where.distance_to(target) >= HOVER_M
        and where.z_m >= target.z_m - HOVER_M
        and horizontal_distance(target, point) < radius_m
        and target.z_m > point.z_m - radius_m
    )


def _descending(where: Point, target: Point, point: Point, radius_m: float) -> bool:
    """Whether a UAV heard at ``where`` comes straight down through
    ``point`` to a target below it: its target right below it (within
    ``HOVER_M`` horizontally), ``point`` within ``radius_m`` of its column
    horizontally and between the two heights (more than ``HOVER_M`` above
    the target: one coming down *to* the point goes first only if nearer)."""
    return (
        horizontal_distance(where, target) < HOVER_M
        and horizontal_distance(where, point) < radius_m
        and target.z_m + HOVER_M < point.z_m < where.z_m
    )


def _leaving(where: Point, target: Point | None, point: Point, radius_m: float) -> bool:
    """Whether a UAV heard at ``where`` flies away from ``point`` to a
    target at least ``radius_m`` from it."""
    if target is None:
        return False
    away = target.distance_to(point)
    return away >= radius_m and away > where.distance_to(point)


def _in_column(where: Point, point: Point, here: Point, radius_m: float) -> bool:
    """Whether ``where`` is within ``radius_m`` of ``point`` horizontally,
    between its height and ``here``'s (1 m beyond either)."""
    low, high = sorted((point.z_m, here.z_m))
    return horizontal_distance(where, point) < radius_m and low - 1.0 < where.z_m < high + 1.0
