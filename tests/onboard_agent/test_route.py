"""Routes never pass near a person: a ground track that would is flown
over them in level and vertical legs (climb, across, down), and a target
placed beside a person on purpose (a drop above a worker) is still reached."""

from __future__ import annotations

import itertools
import math

import msgspec
import pytest

from onboard_agent import AgentConfig
from onboard_agent.route import (
    SIDESTEP_M,
    ground_distance,
    level_below,
    next_leg,
    own_level,
)
from onboard_agent.spots import Spots
from proto.telemetry import FlightState
from tests.onboard_agent.helpers import SCENARIO, Rig, on_a_spot, point

W2 = SCENARIO.site.worker("W2").position  # (-5, 15, 3)
CLEARANCE_M = SCENARIO.site.safety.people_clearance_m
CLEAR_M = CLEARANCE_M + AgentConfig().route_margin_m


def test_a_clear_line_is_flown_straight():
    assert next_leg(point(0, 0, 5), point(10, 0, 5), [W2], CLEAR_M) == point(10, 0, 5)
    high = point(-20, 15, 9)  # over W2 by more than the clearance all the way
    assert next_leg(point(0, 15, 9), high, [W2], CLEAR_M) == high


def test_a_track_over_a_person_climbs_then_crosses_level_then_goes_down():
    here, target = point(10, 10, 3), point(-9, 15, 6)  # the far slot, across W2
    assert ground_distance(W2, here, target) < CLEAR_M
    up = next_leg(here, target, [W2], CLEAR_M)
    assert up == point(10, 10, 6)  # the target's height clears W2 by 3 m
    across = next_leg(up, target, [W2], CLEAR_M)
    assert across == target
    low = point(-10, 10, 2.5)  # a pad approach: below W2's clearance band
    assert next_leg(point(-1, 15, 6), low, [W2], CLEAR_M) == point(-10, 10, 6)
    assert next_leg(point(-10, 10, 6), low, [W2], CLEAR_M) == low  # straight down


def test_a_uav_hovering_right_above_is_left_level_never_climbed_into():
    """Two UAVs hold beside a station, one 2 m above the other: the lower,
    granted its spot, leaves level; climbing over the upper one would fly
    straight into it. One lower than the UAV is still climbed over."""
    here, spot = point(0, 3, 7), point(0, 0, 3)
    above, below = point(0, 3, 9), point(0, 3, 5)
    assert next_leg(here, spot, [above], CLEAR_M) == point(0, 0, 7)
    assert next_leg(here, spot, [below], CLEAR_M) == point(0, 3, 5 + CLEAR_M)


def test_a_climb_or_a_descent_moves_level_first_clear_of_one_hovering_beside():
    """Chaos seed 13: a UAV climbing out of its spot to cross over a far
    waypoint rose into one hovering 0.8 m beside its column. It moves level
    to 2 m from that one first, then climbs (and crosses over it too). A
    person beside the column is no reason (a drop is above one; seed 16:
    UAVs sidestepping W3 beside C2 never landed and fell)."""
    here, target = point(1, 20, 6), point(5, -3, 17)
    beside = point(1.7, 20.4, 11.8)
    obstacles = [beside, point(5, -3, 17)]  # the far waypoint raises the crossing
    first = next_leg(here, target, obstacles, CLEAR_M, traffic=[beside])
    assert first.z_m == here.z_m  # level
    assert ground_distance(beside, first, first) >= SIDESTEP_M
    up = next_leg(first, target, obstacles, CLEAR_M, traffic=[beside])
    assert (up.x_m, up.y_m) == (first.x_m, first.y_m) and up.z_m >= beside.z_m + CLEAR_M
    # straight down onto a target: first clear of one hovering on the way
    hovering = point(0.5, 0, 9)
    down = next_leg(point(0, 0, 12), point(0, 0, 6), [hovering], CLEAR_M, traffic=[hovering])
    assert down.z_m == 12 and ground_distance(hovering, down, down) >= SIDESTEP_M
    person = point(1.5, 0, 3)  # a worker beside a spot (W3 stands 2 m from one of C2's)
    assert next_leg(point(0, 0, 9), point(0, 0, 3), [person], CLEAR_M) == point(0, 0, 3)
    neighbour = point(2, 0, 3)  # above the next spot, 2 m off: clear
    assert next_leg(point(0, 0, 9), point(0, 0, 3), [], CLEAR_M, traffic=[neighbour]) == point(
        0, 0, 3
    )


def test_uavs_at_different_places_cross_at_levels_2_m_apart():
    """Chaos seed 17: two UAVs took off from one station and crossed each
    other at 11.5 m both. Each crosses at a level of its own; hold heights
    over a station on the ground are levels of their own UAV."""
    for need in (3.0, 5.5, 11.5, 19.0):
        levels = [own_level(need, place, 3) for place in range(3)]
        assert all(z >= need for z in levels)
        assert min(abs(a - b) for a, b in itertools.combinations(levels, 2)) >= 2.0
    assert [own_level(5.0 + 2.0 * p, p, 3) for p in range(3)] == [5.0, 7.0, 9.0]
    assert own_level(6.0, 4, 100) == own_level(6.0, 0, 100)  # beyond 4 places, shared
    here, target = point(0, 0, 5), point(20, 0, 5)
    legs = [next_leg(here, target, [point(10, 0, 3)], CLEAR_M, layer=(p, 3)) for p in range(3)]
    assert [leg.z_m for leg in legs] == [own_level(3 + CLEAR_M, p, 3) for p in range(3)]


def test_a_uav_higher_than_its_flight_needs_crosses_at_a_level_of_its_own_below():
    """Chaos seed 14: two UAVs re-routed mid-climb flew level at 11.5 and
    11.8 m (the heights they had reached) into each other. One higher than
    its flight needs goes across at the level of its own next below, never
    below what the flight needs (then where it is); at a level it stays."""
    target, person = point(20, 0, 3), point(10, 0, 3)  # legged: crosses over 3 + CLEAR_M
    legs = [
        next_leg(point(0, 0, z), target, [person], CLEAR_M, layer=(p, 3))
        for p, z in ((0, 11.5), (1, 11.8), (2, 11.8))
    ]
    assert [leg.z_m for leg in legs] == [11.0, 7.0, 9.0]  # levels 5/11, 7/13, 9/15
    assert level_below(11.5, 10.0, 2, 3) == 11.5  # 9 is too low for this flight
    for z in (9.0, 9.2, 8.8, 9.35):  # at (or just off) its level: that level
        assert level_below(z, 3.0, 2, 3) == 9.0
    across = next_leg(point(0, 0, 9.2), target, [person], CLEAR_M, layer=(2, 3))
    assert across == point(20, 0, 9.0)


def test_a_target_placed_beside_a_person_is_reached_from_above():
    drop = point(W2.x_m, W2.y_m, W2.z_m + 1.5)  # a tool dropped 1.5 m above W2
    start = point(5, 5, 3)  # lower than the drop: climb first, never at head height
    assert next_leg(start, drop, [W2], CLEAR_M) == point(5, 5, drop.z_m)
    assert next_leg(point(5, 5, drop.z_m), drop, [W2], CLEAR_M) == drop


def _closest(path: list, person) -> float:
    """Closest approach of a path flown leg by leg, each leg level or vertical
    or straight (sampled every 10 cm)."""
    best = math.inf
    for a, b in itertools.pairwise(path):
        n = max(1, int(a.distance_to(b) / 0.1))
        for i in range(n + 1):
            t = i / n
            q = (
                a.x_m + t * (b.x_m - a.x_m),
                a.y_m + t * (b.y_m - a.y_m),
                a.z_m + t * (b.z_m - a.z_m),
            )
            best = min(best, math.dist(q, (person.x_m, person.y_m, person.z_m)))
    return best


W3 = SCENARIO.site.worker("W3").position  # (5, 20, 3), between C2 and its east side


@pytest.mark.parametrize(
    ("start", "crosses"),
    [(point(7, 21, 5), True), (point(8, 20, 4), True), (point(-1, 15, 6), False)],
)
def test_the_flight_to_a_station_from_beside_a_worker_keeps_the_clearance(start, crosses):
    """The link is lost beside a worker: the emergency flight to the nearest
    station (across the worker for the first two) never passes nearer any
    worker than the clearance."""
    rig = Rig(position=start, config=AgentConfig(agent_link_timeout_s=1.0))
    rig.autopilot.update(flight_state=FlightState.FLYING, mode="GUIDED", armed=True)
    rig.agent.ground_station("gs", False)
    path = [start]

    def flown() -> bool:
        here = rig.autopilot.state.position
        if here != path[-1]:
            path.append(here)
        return rig.autopilot.state.landed

    station = rig.agent.ctx.surroundings.nearest_station(start)
    assert (ground_distance(W3, start, station.position) < CLEARANCE_M) == crosses
    rig.run_until(flown, max_ticks=400)
    assert min(_closest(path, w) for w in (W2, W3)) >= CLEARANCE_M, path
    assert on_a_spot(path[-1], station.id)


def test_a_uav_on_a_roof_climbs_clear_of_the_deck_before_heading_for_a_lower_target():
    """Met live: uav-1 re-tasked just above its 6 m roof pad flew straight
    for a 3 m pick-up and sank into the deck (a crash, in the simulator)."""
    roof = next(s for s in SCENARIO.site.stations if s.id == "C1")
    roof = msgspec.structs.replace(roof, position=point(-10, 10, 6))
    site = msgspec.structs.replace(SCENARIO.site, stations=[roof])
    decks = Spots("uav-1", SCENARIO).raised_spots(site)
    assert decks and all(p.z_m == 6 for p in decks)
    here, pick_up = point(decks[0].x_m, decks[0].y_m, 6.5), point(1, 5, 3)
    up = next_leg(here, pick_up, decks, CLEAR_M)
    assert (up.x_m, up.y_m) == (here.x_m, here.y_m) and up.z_m >= 6 + CLEAR_M  # straight up
    across = next_leg(up, pick_up, decks, CLEAR_M)
    assert across == point(1, 5, up.z_m)  # level, above the deck, then down
    assert Spots("uav-1", SCENARIO).raised_spots(SCENARIO.site) == []  # ground pads: none


def test_a_uav_beside_the_target_that_the_track_passes_over_is_crossed_above():
    """Chaos seed 20: uav-2 flew level to its spot (3, 20) over the next
    spot, where uav-1 hovered 0.3 m higher before landing (0.93 m apart)."""
    here, spot = point(-7, 21, 11.5), point(3, 20, 11.5)
    hovering = point(1, 20, 11.8)  # 2 m from the spot, under the track
    leg = next_leg(
        here, spot, [hovering], CLEAR_M, layer=(1, 3), traffic=[hovering], ahead=[hovering]
    )
    assert (leg.x_m, leg.y_m) == (here.x_m, here.y_m) and leg.z_m >= hovering.z_m + CLEAR_M
    aside = point(3, 22, 11.8)  # beside the spot, off the track: still not crossed over
    assert (
        next_leg(here, spot, [aside], CLEAR_M, layer=(1, 3), traffic=[aside], ahead=[aside]) == spot
    )
