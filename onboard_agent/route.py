"""How a UAV flies to a target without passing near a person.

The autopilot flies to a position target, but not along a straight 3-D
line: it climbs or sinks more slowly than it moves across, so a line that
clears a worker on paper can pass at head height. A route whose ground
track passes within the clearance (the site's people clearance plus a
margin) of a worker below its height band is therefore flown in legs that
are each level or vertical: climb where the UAV is to a height that clears
every such worker, fly level to above the target, then go straight down to
it. Targets are themselves placed clear of people (slots beside them,
drops above them); a worker the target is beside, such as the one a tool
is dropped to, is passed at the target's height or higher; one above the
UAV where it is (another UAV holding higher at a station) is left level,
never climbed into. Flights to a
station are legged the same way at the UAV's own height there (see
:mod:`onboard_agent.spots`), so that UAVs heading for stations at once
cross at different heights. The spots of a raised station (a roof) are
cleared the same way: a UAV leaving one climbs clear of the deck before it
heads for a lower target, and one flying to another crosses above it. A
spot another UAV is granted or sits on is a column up to that UAV's hold
height (it comes down or climbs out through it): routes cross above it,
even to a spot beside it."""

from __future__ import annotations

import math
from collections.abc import Iterable

from proto.geo import Point

TOLERANCE_M = 0.3
"""This close (vertically to the crossing height, horizontally to above the
target) a leg counts as flown."""
ABOVE_M = 1.0
"""An obstacle this close horizontally and higher is right above the UAV:
climbing over it would fly into it."""
LEVEL_STEP_M = 2.0
"""Cruise levels of UAVs at neighbouring places in the fleet lie this far
apart (see :func:`own_level`), as their hold heights over a station do."""
LEVEL_BASE_M = 5.0
"""A level of the UAV at place 0: its hold height over a station on the
ground (the approach height plus one step, :mod:`onboard_agent.spots`), so
that each UAV's hold heights are levels of its own."""
MAX_LAYERS = 4
"""Places in the fleet that cruise at levels of their own; beyond it,
places share levels (place modulo this)."""
SIDESTEP_M = 2.0
"""A climb (or a descent) passes no UAV nearer than this horizontally (less
``TOLERANCE_M``: UAVs over neighbouring spots, 2 m apart, are clear): the
UAV first moves level this far from it (chaos seed 13: a UAV climbed out
of its spot into one hovering 0.8 m beside its column)."""


def ground_distance(p: Point, a: Point, b: Point) -> float:
    """Shortest horizontal distance from ``p`` to the ground track ``a``-``b``."""
    dx, dy = b.x_m - a.x_m, b.y_m - a.y_m
    length2 = dx * dx + dy * dy
    along = (p.x_m - a.x_m) * dx + (p.y_m - a.y_m) * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, along / length2))
    return math.hypot(a.x_m + t * dx - p.x_m, a.y_m + t * dy - p.y_m)


def next_leg(
    here: Point,
    target: Point,
    people: Iterable[Point],
    clear_m: float,
    cruise_z: float | None = None,
    columns: Iterable[Point] = (),
    layer: tuple[int, int] | None = None,
    traffic: Iterable[Point] = (),
    ahead: Iterable[Point] = (),
    verticals: Iterable[Point] = (),
    movers: Iterable[Point] = (),
) -> Point:
    """The point to send the autopilot now on the way from ``here`` to
    ``target``; with ``cruise_z`` the flight is legged anyway and crosses
    at that height at least (a height of the UAV's own, clear of others).
    ``columns`` are crossed above like ``people``, even beside the target
    (the spots where other UAVs land and take off). With ``layer`` (the
    UAV's place in the fleet, the fleet's size) a flight that crosses over
    something, higher than both its ends, does so at the UAV's own level
    (:func:`own_level`); a climb to the target's height stays one (k UAVs
    arriving at a worker's ring together are not held up by it).
    ``traffic`` (among ``people`` too) are where other UAVs are or are
    about to be: a climb or descent first moves level clear of them
    (:func:`_sidestep`); people beside a target are not, a drop is above one.
    Of those, ``ahead`` are where another UAV stays (hovers, or is about
    to) or has yet to pass: one beside the target is crossed above like a
    person on the way when the track passes over it (nearer than
    ``SIDESTEP_M``; chaos seed 20: a UAV flying to its spot passed level
    over one hovering above the next). Where one on its way is now (a UAV
    leaving the slot its relief flies to) is not. ``verticals`` are where
    UAVs climbing or descending straight are (those whose climb targets this
    UAV does not cross over): a leg across one's column within its height
    band waits, holding where the UAV is, until it has passed clear
    (:func:`_across`).
    ``movers`` are where UAVs after this one in id order are heard on their
    way: a climb or descent that would pass one holds where the UAV is
    (:func:`_vertical`); that UAV sees this one in its way and moves clear
    itself, so of two only one sidesteps (chaos seed 18: two sidestepping
    each other at once chose one point and met 0.97 m apart)."""
    if math.hypot(target.x_m - here.x_m, target.y_m - here.y_m) <= TOLERANCE_M:
        leg = _vertical(here, target, target, traffic, movers)  # straight up or down
        return _across(here, leg, verticals, clear_m)
    low = min(here.z_m, target.z_m)

    def near(points: Iterable[Point]) -> list[Point]:
        return [
            p
            for p in points
            if ground_distance(p, here, target) < clear_m and low < p.z_m + clear_m
        ]

    def above(p: Point) -> bool:
        return ground_distance(p, here, here) < ABOVE_M and p.z_m > here.z_m

    near_people, near_columns = near(people), near(columns)
    if not near_people and not near_columns and cruise_z is None:
        return _across(here, target, verticals, clear_m)
    passed_over = [p for p in ahead if ground_distance(p, here, target) < SIDESTEP_M - TOLERANCE_M]
    beside_target = [
        p
        for p in near_people
        if ground_distance(p, target, target) < clear_m and p not in passed_over
    ]
    crossed = [p for p in near_people if p not in beside_target] + near_columns
    needed = max(
        [target.z_m, cruise_z or -math.inf] + [p.z_m + clear_m for p in crossed if not above(p)]
    )
    crossing = max(here.z_m, needed)
    if layer is not None and crossing > max(here.z_m, target.z_m) + TOLERANCE_M:
        crossing = own_level(crossing, *layer)  # over something: at a level of its own
    elif layer is not None and here.z_m > needed + TOLERANCE_M:
        crossing = level_below(here.z_m, needed, *layer)  # higher than needed: its own, below
    if here.z_m < crossing - TOLERANCE_M:
        up = Point(x_m=here.x_m, y_m=here.y_m, z_m=crossing)
        return _vertical(here, up, target, traffic, movers)
    return _across(here, Point(x_m=target.x_m, y_m=target.y_m, z_m=crossing), verticals, clear_m)


def _across(here: Point, leg: Point, verticals: Iterable[Point], clear_m: float) -> Point:
    """``leg``, or where the UAV is while the leg would pass within
    ``clear_m`` of the column of one of ``verticals`` (horizontally) with it
    within ``clear_m`` of the leg's height band: chaos seed 14, a UAV re-routed
    mid-climb flew level across the column of one climbing beside it out
    of the next spot (0.88 m)."""
    low, high = min(here.z_m, leg.z_m) - clear_m, max(here.z_m, leg.z_m) + clear_m
    for c in verticals:
        if ground_distance(c, here, leg) < clear_m and low < c.z_m < high:
            return here
    return leg


def _vertical(
    here: Point, to: Point, target: Point, obstacles: Iterable[Point], movers: Iterable[Point]
) -> Point:
    """The leg up or down from ``here`` to ``to`` (right above or below it)
    on the way to ``target``: ``to``, or where the UAV is while a mover is
    in the way (:func:`_in_way`), or first level clear of an obstacle in
    the way (:func:`_sidestep`)."""
    if _in_way(here, to.z_m, movers):
        return here
    blocking = _in_way(here, to.z_m, obstacles)
    return _sidestep(here, target, blocking) if blocking else to


def _in_way(here: Point, to_z: float, points: Iterable[Point]) -> list[Point]:
    """The ``points`` a climb or descent at ``here`` to ``to_z`` would pass
    within ``SIDESTEP_M`` of (horizontally), from the UAV's height to 1 m
    past ``to_z``."""
    up = to_z > here.z_m
    low, high = (here.z_m, to_z + 1.0) if up else (to_z - 1.0, here.z_m)
    return [
        p
        for p in points
        if ground_distance(p, here, here) < SIDESTEP_M - TOLERANCE_M and low < p.z_m < high
    ]


def _sidestep(here: Point, target: Point, blocking: list[Point]) -> Point:
    """Where to move level first, clear of the ``blocking`` obstacles of a
    climb or descent: ``SIDESTEP_M`` from the nearest, away from it (right
    below or above it: towards the target)."""
    p = min(blocking, key=lambda b: ground_distance(b, here, here))
    dx, dy = here.x_m - p.x_m, here.y_m - p.y_m
    if math.hypot(dx, dy) < TOLERANCE_M:
        dx, dy = target.x_m - here.x_m, target.y_m - here.y_m
    if math.hypot(dx, dy) < TOLERANCE_M:
        dx, dy = 1.0, 0.0
    scale = (SIDESTEP_M + TOLERANCE_M) / math.hypot(dx, dy)
    return Point(x_m=p.x_m + dx * scale, y_m=p.y_m + dy * scale, z_m=here.z_m)


def level_below(z_m: float, at_least_m: float, place: int, fleet_size: int) -> float:
    """The cruise level of the UAV at ``place`` at or below ``z_m`` (within
    ``TOLERANCE_M``: its own) and not below ``at_least_m``; ``z_m`` if there
    is none. Where a UAV higher than its flight needs (re-routed mid-climb,
    flying on from a hold) goes across, on its way down (chaos seed 14: two
    re-routed mid-climb flew level at 11.5 and 11.8 m into each other)."""
    layers = max(1, min(fleet_size, MAX_LAYERS))
    below = own_level(z_m - LEVEL_STEP_M * layers + TOLERANCE_M, place, fleet_size)
    return below if below >= at_least_m else z_m


def own_level(z_m: float, place: int, fleet_size: int) -> float:
    """The lowest cruise level at or above ``z_m`` of the UAV at ``place``
    in a fleet of ``fleet_size``: levels ``LEVEL_STEP_M`` apart from one
    place to the next, so two UAVs crossing at once never cruise at one
    height (chaos seed 17: two took off from one station and crossed at
    11.5 m both)."""
    layers = max(1, min(fleet_size, MAX_LAYERS))
    cycle = LEVEL_STEP_M * layers
    base = LEVEL_BASE_M + LEVEL_STEP_M * (place % layers)
    return base + cycle * math.ceil((z_m - base) / cycle - 1e-9)
