"""Who holds a point, from the traffic report: a UAV heard at it, one
unheard whose target it was, and, of two sent to it, the nearer."""

from __future__ import annotations

import msgspec
import pytest

from onboard_agent.route import SIDESTEP_M, next_leg
from onboard_agent.surroundings import horizontal_distance
from onboard_agent.traffic import Traffic
from proto.geo import Point
from proto.telemetry import Traffic as TrafficReport
from proto.telemetry import TrafficEntry

SLOT = Point(x_m=0.0, y_m=0.0, z_m=6.0)


def report(*entries: TrafficEntry) -> Traffic:
    traffic = Traffic("uav-1")
    traffic.update(TrafficReport(uavs=list(entries)), 0.0)
    return traffic


def entry(at: Point, target: Point | None = None, age_s: float = 0.2) -> TrafficEntry:
    return TrafficEntry(uav_id="uav-2", position=at, airborne=True, age_s=age_s, target=target)


def p(x: float, y: float, z: float) -> Point:
    return Point(x_m=x, y_m=y, z_m=z)


def test_a_uav_heard_at_the_point_holds_it_and_is_known_heard():
    seen = report(entry(p(0.5, 0.0, 6.0))).holder(SLOT, 2.0, 0.0)
    assert seen is not None and (seen.uav_id, seen.unheard) == ("uav-2", False)


def test_one_unheard_holds_the_target_it_flew_to():
    traffic = report(entry(p(10.0, 0.0, 6.0), target=SLOT, age_s=5.0))
    seen = traffic.holder(SLOT, 2.0, 0.0)
    assert seen is not None and seen.unheard


@pytest.mark.parametrize(
    ("other_at", "other_target", "me", "yields"),
    [
        (p(0.0, 0.0, 8.5), p(0.0, 0.0, 6.0), p(2.9, 0.0, 6.0), True),  # coming down, nearer
        (p(2.0, 0.0, 8.5), p(0.0, 0.0, 8.5), p(3.5, 0.0, 6.0), True),  # to above it, to come down
        (p(0.0, 0.0, 8.5), p(0.0, 0.0, 8.5), p(2.9, 0.0, 6.0), False),  # hovering: maybe holding
        (p(0.0, 0.0, 3.0), p(0.0, 0.0, 11.0), p(2.9, 0.0, 6.0), False),  # climbing past it
        (p(0.0, 0.0, 8.5), p(0.0, 0.0, 6.0), p(2.0, 0.0, 6.0), False),  # I am nearer: I go
        (p(5.0, 0.0, 6.0), p(0.0, 0.0, 6.0), p(2.9, 0.0, 6.0), False),  # it is farther
        (p(0.0, 3.0, 6.0), p(0.0, 6.0, 6.0), p(2.9, 0.0, 6.0), False),  # sent elsewhere
        (p(0.0, 0.0, 2.0), p(0.0, 0.0, 2.0), p(2.9, 0.0, 6.0), False),  # below, not coming up
    ],
)
def test_of_two_uavs_sent_to_one_point_the_nearer_goes_first(other_at, other_target, me, yields):
    """Chaos seed 18: one UAV came back to a slot from beside it as another
    came down to it from above; each was more than 2 m from the slot."""
    traffic = report(entry(other_at, target=other_target))
    seen = traffic.holder(SLOT, 2.0, 0.0, here=me)
    assert (seen is not None and seen.uav_id == "uav-2") is yields
    assert traffic.holder(SLOT, 2.0, 0.0) is None  # nobody is at the point itself


def test_a_uav_leaving_the_point_no_longer_holds_it_for_one_level_with_it():
    """A relief level with the slot closes in as the UAV it relieves climbs
    away from it (the hand-over leaves no gap), not once it is 2 m off.
    From above (chaos seed 13: a relief crossing at 8.8 m over the slot as
    the UAV it relieved climbed out of it), a UAV in the column between
    holds it until it is above the relief."""
    leaving = report(entry(p(0.0, 0.0, 6.5), target=p(0.0, 0.0, 11.0)))
    assert leaving.holder(SLOT, 2.0, 0.0, here=p(3.0, 0.0, 6.0)) is None
    assert leaving.holder(SLOT, 2.0, 0.0, here=p(-0.2, 2.5, 8.8)) is not None
    higher = report(entry(p(0.2, -0.8, 8.5), target=p(0.2, -0.8, 13.0)))
    assert higher.holder(SLOT, 2.0, 0.0, here=p(-0.2, 1.3, 8.8)) is not None  # in the column
    above = report(entry(p(0.2, -0.8, 10.5), target=p(0.2, -0.8, 13.0)))
    assert above.holder(SLOT, 2.0, 0.0, here=p(-0.2, 1.3, 8.8)) is None  # out of it
    staying = report(entry(p(0.0, 0.0, 6.5), target=SLOT))
    assert staying.holder(SLOT, 2.0, 0.0, here=p(3.0, 0.0, 6.0)) is not None


def test_a_uav_landing_holds_every_point_of_its_column_below_it():
    """Chaos seed 15: uav-1 landed straight down from 17 m at a station
    while uav-2 flew in under it to a point 6 m above the same spot. The
    landing UAV (its target the ground below it) holds that point however
    far above it is and whoever is nearer; a point beside its column, or
    above it, is free."""
    landing = report(entry(p(0.0, 0.0, 15.0), target=p(0.0, 0.0, 0.0)))
    here = p(-3.0, 0.0, 11.7)
    seen = landing.holder(SLOT, 2.0, 0.0, here)
    assert seen is not None and seen.uav_id == "uav-2"
    assert landing.holder(p(3.0, 0.0, 6.0), 2.0, 0.0, here) is None
    assert landing.holder(p(0.0, 0.0, 20.0), 2.0, 0.0, p(-3.0, 0.0, 22.0)) is None
    flying_level = report(entry(p(0.0, 0.0, 15.0), target=p(9.0, 0.0, 15.0)))
    assert flying_level.holder(SLOT, 2.0, 0.0, here) is None


def test_a_climb_target_is_an_obstacle_for_uavs_after_the_climber_only():
    """Chaos seed 12: uav-1 and uav-2 climbed side by side out of C2, each
    crossing over the other's climb target, up to 150 m. The one later in
    id order crosses over the other's climb; the earlier one ignores it."""
    climb = TrafficEntry(
        uav_id="uav-2", position=p(3.0, 20.0, 5.0), airborne=True, age_s=0.2, target=p(3, 20, 13)
    )
    earlier = Traffic("uav-1")
    earlier.update(TrafficReport(uavs=[climb]), 0.0)
    assert p(3, 20, 13) not in earlier.obstacles(0.0)
    later = Traffic("uav-3")
    later.update(TrafficReport(uavs=[climb]), 0.0)
    assert p(3, 20, 13) in later.obstacles(0.0)
    level = msgspec.structs.replace(climb, target=p(9, 20, 5))  # on its way, level: counts
    earlier.update(TrafficReport(uavs=[level]), 0.0)
    assert p(9, 20, 5) in earlier.obstacles(0.0)


def test_of_two_uavs_whose_tracks_cross_the_later_in_id_order_crosses_over():
    """Chaos seed 20: uav-1 and uav-2 swapped slots on straight tracks at
    6-9 m and met head on. Where uav-1 is on its way is an obstacle for
    uav-2, which crosses over it at a level of its own; uav-1 flies on."""
    uav1_at, uav1_to = p(2.5, 10.5, 7.3), p(-12.0, 15.0, 6.0)
    uav2_at, uav2_to = p(-8.9, 15.0, 8.9), p(7.0, 10.0, 6.0)
    uavs = [
        TrafficEntry(uav_id="uav-1", position=uav1_at, airborne=True, target=uav1_to),
        TrafficEntry(uav_id="uav-2", position=uav2_at, airborne=True, target=uav2_to),
    ]
    seen = {}
    for me in ("uav-1", "uav-2"):
        seen[me] = Traffic(me)
        seen[me].update(TrafficReport(uavs=uavs), 0.0)
    assert uav1_at in seen["uav-2"].obstacles(0.0) and uav2_at not in seen["uav-1"].obstacles(0.0)
    clear = 2.5
    assert next_leg(uav1_at, uav1_to, seen["uav-1"].obstacles(0.0), clear, layer=(0, 3)) == uav1_to
    leg = next_leg(uav2_at, uav2_to, seen["uav-2"].obstacles(0.0), clear, layer=(1, 3))
    assert (leg.x_m, leg.y_m) == (uav2_at.x_m, uav2_at.y_m)  # up first, where it is
    assert leg.z_m >= uav1_at.z_m + clear


def test_the_later_uav_crosses_over_the_track_of_an_earlier_one_not_only_where_it_was():
    """Chaos seed 17: uav-1 and uav-2, re-routed mid-climb out of C2 to
    targets at one height, crossed there 0.97 m apart: where uav-1 was heard
    lay 3 m off uav-2's track, but uav-1's track crossed it. The point of
    uav-1's track nearest uav-2's is an obstacle for uav-2 (given its track)."""
    uav1_at, uav1_to = p(-0.3, 19.1, 12.5), p(7.0, 10.0, 12.4)
    uav2_at, uav2_to = p(2.9, 19.7, 12.7), p(2.0, 15.0, 12.4)
    uavs = [
        TrafficEntry(uav_id="uav-1", position=uav1_at, airborne=True, target=uav1_to),
        TrafficEntry(uav_id="uav-2", position=uav2_at, airborne=True, target=uav2_to),
    ]
    seen = {}
    for me in ("uav-1", "uav-2"):
        seen[me] = Traffic(me)
        seen[me].update(TrafficReport(uavs=uavs), 0.0)
    clear = 2.5
    where_heard_only = seen["uav-2"].obstacles(0.0)
    assert next_leg(uav2_at, uav2_to, where_heard_only, clear, layer=(1, 3)) == uav2_to
    crossing = seen["uav-2"].obstacles(0.0, (uav2_at, uav2_to))
    ahead = seen["uav-2"].ahead(0.0, (uav2_at, uav2_to))
    leg = next_leg(uav2_at, uav2_to, crossing, clear, layer=(1, 3), traffic=crossing, ahead=ahead)
    assert (leg.x_m, leg.y_m) == (uav2_at.x_m, uav2_at.y_m)  # up first, where it is
    assert leg.z_m >= 12.4 + clear
    mine = seen["uav-1"].obstacles(0.0, (uav1_at, uav1_to))  # uav-2's target is on its way
    theirs = seen["uav-1"].ahead(0.0, (uav1_at, uav1_to))
    assert (
        next_leg(uav1_at, uav1_to, mine, clear, layer=(0, 3), traffic=mine, ahead=theirs).z_m
        != leg.z_m
    )


@pytest.mark.parametrize(
    ("track", "nearest"),
    [
        ((p(0, -5, 0), p(0, 5, 0)), p(0, 0, 7)),  # crossing: where they cross, height between
        ((p(20, 3, 0), p(30, 3, 0)), p(10, 0, 8)),  # beyond its end: its end
        ((p(4, 8, 0), p(4, 2, 0)), p(4, 0, 7.4)),  # ends short of it: the projection
    ],
)
def test_the_nearest_point_of_another_track_to_mine(track, nearest):
    from onboard_agent.traffic import _nearest_on

    got = _nearest_on(p(-10, 0, 6), p(10, 0, 8), *track)
    assert got.distance_to(nearest) < 1e-9


def test_a_relief_is_not_sent_over_the_slot_the_uav_it_relieves_is_leaving():
    """The 1,500 s hand-over: a relief made to cross over the slot it flies
    to (the UAV it relieves, earlier in id order, heard leaving it) came in
    from above, and nobody watched the worker for 9 s."""
    aside, hold = p(0.0, 3.0, 6.0), p(3.0, 0.0, 6.0)  # along the ring, and out on the bearing
    relieved = TrafficEntry(uav_id="uav-1", position=SLOT, airborne=True, target=aside)
    relief = Traffic("uav-2")
    relief.update(TrafficReport(uavs=[relieved]), 0.0)
    track = (hold, SLOT)
    obstacles, ahead = relief.obstacles(0.0, track), relief.ahead(0.0, track)
    assert SLOT in obstacles and SLOT not in ahead and aside in ahead
    assert (
        next_leg(hold, SLOT, obstacles, 2.5, layer=(1, 3), traffic=obstacles, ahead=ahead) == SLOT
    )
    hovering = msgspec.structs.replace(relieved, target=SLOT)  # staying there: crossed above
    relief.update(TrafficReport(uavs=[hovering]), 0.0)
    obstacles, ahead = relief.obstacles(0.0, track), relief.ahead(0.0, track)
    leg = next_leg(hold, SLOT, obstacles, 2.5, layer=(1, 3), traffic=obstacles, ahead=ahead)
    assert leg.z_m >= SLOT.z_m + 2.5


def test_a_uav_waits_to_cross_the_column_of_a_later_one_climbing_through_its_height():
    """Chaos seed 14: uav-1 and uav-3 climbed out of neighbouring spots of
    C2; uav-1, re-routed at 12.6 m, flew level east across uav-3's column as
    uav-3 climbed through 12 m (0.88 m). uav-1 ignores uav-3's climb target
    (seed 12's rule), so it holds where it is until uav-3 is clear above."""
    here, target = p(-1.0, 20.0, 12.6), p(12.0, 20.0, 12.4)

    def seen_by_uav1(climber_z: float) -> Traffic:
        climb = TrafficEntry(
            uav_id="uav-3", position=p(1.0, 20.0, climber_z), airborne=True, target=p(1, 20, 21)
        )
        traffic = Traffic("uav-1")
        traffic.update(TrafficReport(uavs=[climb]), 0.0)
        return traffic

    def leg(traffic: Traffic) -> Point:
        obstacles = traffic.obstacles(0.0, (here, target))
        return next_leg(
            here, target, obstacles, 2.5, layer=(0, 3), verticals=traffic.verticals(0.0)
        )

    low = seen_by_uav1(11.3)
    assert next_leg(here, target, low.obstacles(0.0, (here, target)), 2.5, layer=(0, 3)) == target
    assert leg(low) == here  # holds
    assert leg(seen_by_uav1(15.5)) == target  # climbed clear: goes
    uav1_climbing = TrafficEntry(uav_id="uav-1", position=here, airborne=True, target=p(-1, 20, 17))
    later = Traffic("uav-3")
    later.update(TrafficReport(uavs=[uav1_climbing]), 0.0)
    assert later.verticals(0.0) == []  # never waits for one before it (it crosses over its climb)
    assert p(-1, 20, 17) in later.obstacles(0.0)


def test_a_uav_waits_to_cross_the_column_of_a_later_one_descending_through_its_height():
    """Chaos seed 13: uav-1 at W1's drop point, climbing to cross over uav-2
    hovering at (0, 7, 6.5), turned level at 5.8 m across uav-2's column the
    moment uav-2 began to descend in it (to 3 m, just outside the height
    band) and passed 1.00 m from it. uav-1 holds until uav-2 is below."""
    here, target = p(1.0, 5.0, 5.8), p(0.0, 10.0, 5.5)

    def seen_by_uav1(z: float, hovering: bool = False) -> Traffic:
        at = p(0.0, 7.0, z)
        descent = TrafficEntry(
            uav_id="uav-2", position=at, airborne=True, target=at if hovering else p(0, 7, 3)
        )
        traffic = Traffic("uav-1")
        traffic.update(TrafficReport(uavs=[descent]), 0.0)
        return traffic

    def leg(traffic: Traffic) -> Point:
        obstacles = traffic.obstacles(0.0, (here, target))
        return next_leg(
            here, target, obstacles, 2.5, layer=(0, 3), verticals=traffic.verticals(0.0)
        )

    assert leg(seen_by_uav1(6.3)) == here  # holds while uav-2 comes down through its height
    assert leg(seen_by_uav1(4.5)) == here
    assert leg(seen_by_uav1(3.0, hovering=True)) == target  # arrived below: goes
    uav2 = Traffic("uav-2")
    uav2.update(
        TrafficReport(
            uavs=[TrafficEntry(uav_id="uav-1", position=here, airborne=True, target=p(1, 5, 4))]
        ),
        0.0,
    )
    assert uav2.verticals(0.0) == []  # a later UAV never waits for an earlier one's descent


def test_of_two_uavs_climbing_and_descending_past_each_other_only_the_later_moves_aside():
    """Chaos seed 18: uav-1 climbing out of C2's spot (1, 20) and uav-2
    coming down to a waypoint 1.4 m beside it sidestepped each other at
    once, to one point, and met 0.97 m apart. uav-1 holds while uav-2,
    on its way, is in its climb; uav-2 sees uav-1 in its descent and moves
    clear of it; once uav-2 hovers there, uav-1 moves aside itself."""
    one_at, one_to = p(1.0, 20.0, 10.0), p(1.0, 20.0, 17.0)
    two_at, two_to = p(0.0, 21.0, 12.4), p(0.0, 21.0, 3.0)

    def seen_by(uav_id: str, other: TrafficEntry) -> Traffic:
        traffic = Traffic(uav_id)
        traffic.update(TrafficReport(uavs=[other]), 0.0)
        return traffic

    def leg(traffic: Traffic, here: Point, target: Point) -> Point:
        obstacles = traffic.obstacles(0.0, (here, target))
        return next_leg(
            here,
            target,
            obstacles,
            2.5,
            layer=(0, 3),
            traffic=obstacles,
            movers=traffic.movers(0.0),
        )

    two = TrafficEntry(uav_id="uav-2", position=two_at, airborne=True, target=two_to)
    one = TrafficEntry(uav_id="uav-1", position=one_at, airborne=True, target=one_to)
    assert leg(seen_by("uav-1", two), one_at, one_to) == one_at  # holds
    aside = leg(seen_by("uav-2", one), two_at, two_to)
    assert aside.z_m == two_at.z_m and horizontal_distance(aside, one_at) >= SIDESTEP_M
    assert seen_by("uav-2", one).movers(0.0) == []  # never holds for one before it
    hovering = msgspec.structs.replace(two, target=two_at)
    beside = leg(seen_by("uav-1", hovering), one_at, one_to)
    assert beside.z_m == one_at.z_m and horizontal_distance(beside, two_at) >= SIDESTEP_M
    far = msgspec.structs.replace(two, position=p(6.0, 21.0, 12.4), target=p(6.0, 21.0, 3.0))
    assert leg(seen_by("uav-1", far), one_at, one_to) == one_to  # none in the way: climbs
