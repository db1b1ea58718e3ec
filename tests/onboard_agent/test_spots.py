"""Landing at a station with a spot controller: claim a free spot, hold at
a height of one's own until it is granted, land on that spot only; an
emergency goes to the nearest station with room."""

from __future__ import annotations

import math

from onboard_agent.route import own_level
from onboard_agent.spots import STALE_S
from proto.plan import RechargeTask
from proto.spots import StationSpots, spot_positions
from proto.telemetry import Traffic, TrafficEntry
from tests.onboard_agent.helpers import SCENARIO, Rig, plan, point

C3 = SCENARIO.site.station("C3")
C3_SPOTS = spot_positions(C3, SCENARIO.fleet)  # uav-3's home spot, then 2 pads: x 8, 10, 12


def feed(station: str, granted: list, landed: list | None = None, stamp: float = 1.0):
    return StationSpots(
        station_id=station, stamp_s=stamp, granted=granted, landed=landed or [None] * len(granted)
    )


def test_a_recharge_claims_a_free_spot_holds_until_granted_then_lands_on_it():
    rig = Rig(battery=0.5, position=point(0, 7, 3))
    spots = rig.agent.ctx.spots
    spots.update(feed("C3", [None, None, None], landed=["uav-3", "uav-2", None]))
    task = RechargeTask(task_id="r1", station_id="C3", position=C3.position, until_fraction=0.9)
    rig.agent.offer_plan(plan(task))
    rig.tick(20)  # within STALE_S of the feed
    claim = spots.claim_due(rig.clock())  # what the comms layer sends
    assert (claim.uav_id, claim.station_id, claim.spot) == ("uav-1", "C3", 2)
    assert spots.claim_due(rig.clock()) is None  # just sent: not again at once
    state = rig.autopilot.state
    hold = spots.hold_point(C3, rig.agent.ctx.config.approach_alt_m)
    assert not state.landed and state.position == hold  # waits above C3, clear of it
    rig.clock.advance(1.0)
    again = spots.claim_due(rig.clock())
    assert (again.station_id, again.spot) == ("C3", 2)  # repeated until granted
    spots.update(feed("C3", [None, None, "uav-1"], landed=["uav-3", "uav-2", None], stamp=2.0))
    rig.run_until(lambda: rig.autopilot.state.landed)
    landed = rig.autopilot.state.position
    assert (landed.x_m, landed.y_m) == (C3_SPOTS[2].x_m, C3_SPOTS[2].y_m)


def test_uavs_waiting_for_one_station_hold_at_heights_of_their_own():
    holds = {
        Rig(uav_id=u).agent.ctx.spots.hold_point(C3, 3.0).z_m for u in ("uav-1", "uav-2", "uav-3")
    }
    heights = sorted(holds)
    assert len(heights) == 3 and heights[1] - heights[0] >= 2.0 and heights[2] - heights[1] >= 2.0


def test_an_emergency_lands_at_the_nearest_station_with_room():
    rig = Rig(position=point(9, 11, 5))  # right above C3, which is full
    spots = rig.agent.ctx.spots
    rig.autopilot.update(flight_state=rig.autopilot.state.flight_state.FLYING, armed=True)
    rig.agent.ground_station("gs", False)
    rig.clock.advance(10.0)
    spots.update(feed("C3", [None, "uav-2", None], landed=[None, None, "uav-3"]))
    spots.update(feed("C1", [None, None, None]))
    spots.update(feed("C2", [None, None, None]))
    rig.tick(5)
    claim = spots.claim_due(rig.clock())
    assert claim is not None and claim.station_id == "C2"  # C2 (0, 20) before C1 (-10, 10)
    assert claim.spot == 1  # spot 0 is uav-2's home


def test_a_grant_not_flown_to_is_given_back():
    rig = Rig()
    spots = rig.agent.ctx.spots
    spots.update(feed("C3", ["uav-1", None]))
    spots.landing_point(C3, rig.clock())
    assert spots.claim_due(rig.clock()) is None  # in use
    rig.clock.advance(6.0)
    release = spots.claim_due(rig.clock())
    assert release is not None and release.station_id is None


def test_a_spot_wanted_then_left_behind_is_not_claimed_on_and_on():
    """A UAV asked for a spot, then its plan took it elsewhere before the
    grant: it stops claiming, and a grant that comes late is given back
    (a stuck grant drew its emergency landing to the wrong station)."""
    rig = Rig()
    spots = rig.agent.ctx.spots
    spots.update(feed("C3", [None, None]))
    assert spots.landing_point(C3, rig.clock()) is None  # waits for a grant
    assert spots.claim_due(rig.clock()).station_id == "C3"
    rig.clock.advance(6.0)  # no longer asked where to land at C3
    assert spots.claim_due(rig.clock()) is None
    spots.update(feed("C3", [None, "uav-1", None], stamp=2.0))  # the late grant
    release = spots.claim_due(rig.clock())
    assert release is not None and release.station_id is None


def test_cut_off_from_the_controller_it_lands_on_a_shared_spot_last_seen_free():
    """A partition must never keep a UAV in the air: once the feed is older
    than STALE_S, a shared spot the last feed showed free is landed on,
    never another UAV's home spot."""
    rig = Rig(battery=0.5, position=point(9, 14, 6))
    spots = rig.agent.ctx.spots
    spots.update(feed("C3", [None, None, None], landed=[None, "uav-2", None]))
    task = RechargeTask(task_id="r1", station_id="C3", position=C3.position, until_fraction=0.9)
    rig.agent.offer_plan(plan(task))
    rig.tick(20)
    assert not rig.autopilot.state.landed  # holding: no grant yet
    rig.clock.advance(STALE_S)
    rig.run_until(lambda: rig.autopilot.state.landed)
    landed = rig.autopilot.state.position
    assert (landed.x_m, landed.y_m) == (C3_SPOTS[2].x_m, C3_SPOTS[2].y_m)


def test_uavs_cut_off_together_land_at_home_each_on_its_own_spot():
    """Chaos seeds 11, 13, 14: UAVs cut off at once all heard the same last
    feed and landed on the one spot it showed free. Cut off, each flies to
    its home spot, which no other UAV is ever granted."""
    landed = {}
    for uav in ("uav-1", "uav-3"):
        rig = Rig(uav_id=uav, position=point(2, 18, 6))  # beside C2, far from home
        rig.autopilot.update(flight_state=rig.autopilot.state.flight_state.FLYING, armed=True)
        spots = rig.agent.ctx.spots
        for station in ("C1", "C2", "C3"):
            spots.update(feed(station, [None, None, None]))  # the same last feed
        rig.agent.ground_station("gs", False)
        rig.clock.advance(STALE_S + 1.0)  # the link's timeout and the feed's at once
        rig.run_until(lambda r=rig: r.autopilot.state.landed)
        p = rig.autopilot.state.position
        landed[uav] = (p.x_m, p.y_m)
    homes = {
        u: spot_positions(SCENARIO.site.station(s), SCENARIO.fleet)[0]
        for u, s in (("uav-1", "C1"), ("uav-3", "C3"))
    }
    assert landed == {u: (h.x_m, h.y_m) for u, h in homes.items()}


def test_a_station_never_heard_is_landed_on_a_spot_never_between_two():
    """No controller heard at all (one restarted while cut off): at home the
    home spot, elsewhere a shared spot, never the station's centre."""
    spots = Rig(uav_id="uav-2").agent.ctx.spots
    c2 = SCENARIO.site.station("C2")
    assert spots.landing_point(c2, 0.0) == spot_positions(c2, SCENARIO.fleet)[0]
    assert spots.landing_point(C3, 0.0) in C3_SPOTS[1:]
    assert spots.cleared("C3") and spots.cleared("C2")


def test_a_flight_to_a_station_crosses_at_the_uav_s_own_hold_height():
    rig = Rig(uav_id="uav-2", position=point(0, 7, 4))
    rig.autopilot.update(flight_state=rig.autopilot.state.flight_state.FLYING, armed=True)
    task = RechargeTask(task_id="r1", station_id="C3", position=C3.position, until_fraction=0.9)
    rig.agent.offer_plan(plan(task))
    heights = set()
    rig.run_until(
        lambda: rig.autopilot.state.landed or heights.add(rig.autopilot.state.position.z_m)
    )
    hold = rig.agent.ctx.spots.hold_point(C3, rig.agent.ctx.config.approach_alt_m).z_m
    assert hold in heights and max(heights) == hold


def test_before_its_position_is_known_a_uav_claims_no_spot_at_another_station():
    """Issue 21: an agent that starts on its home spot ticks before the
    autopilot's first position (the origin until then, on a loaded machine
    for longer). The nearest station from that made-up point (C1) must not
    be claimed: its grant would stick and the UAV would fly off its own
    pad to land beside another UAV at C1, both then taking off together."""
    c2 = SCENARIO.site.station("C2")
    home = spot_positions(c2, SCENARIO.fleet)[0]  # where the simulator starts uav-2
    rig = Rig(uav_id="uav-2", position=point(0, 0, 0))
    rig.autopilot.update(known=False)
    spots = rig.agent.ctx.spots
    spots.update(feed("C1", [None, None, None], landed=["uav-1", None, None]))
    spots.update(feed("C2", [None, None, None], landed=["uav-2", None, None]))
    spots.update(feed("C3", [None, None, None], landed=["uav-3", None, None]))
    rig.agent.offer_plan(plan(uav_id="uav-2"))  # nothing to do: back to a station
    claims = []
    for _ in range(10):
        rig.tick()
        claims.append(spots.claim_due(rig.clock()))
    assert [c for c in claims if c is not None] == []  # nearest to an unknown place: none
    assert spots.granted("C1") is None and not rig.autopilot.state.armed
    rig.autopilot.update(known=True, position=home)  # the first fix: on its home spot
    rig.tick()
    claim = spots.claim_due(rig.clock())
    assert claim is not None and (claim.station_id, claim.spot) == ("C2", 0)
    spots.update(feed("C2", ["uav-2", None, None], landed=["uav-2", None, None], stamp=2.0))
    rig.tick(10)
    assert "takeoff" not in [name for name, _ in rig.autopilot.calls]  # stays on its pad
    assert rig.autopilot.state.landed and rig.autopilot.state.position == home


def test_hold_points_stand_clear_of_the_column_above_every_spot():
    """A UAV comes down to its spot (and climbs out of one) straight
    through the heights others hold at: never through their column."""
    spots = Rig().agent.ctx.spots
    hold = spots.hold_point(C3, 3.0)
    separation = SCENARIO.site.safety.separation_m
    for spot in C3_SPOTS:
        assert math.hypot(hold.x_m - spot.x_m, hold.y_m - spot.y_m) >= separation + 2.0


def test_a_route_to_a_station_crosses_above_the_column_of_a_spot_in_use():
    """Chaos seed 15: uav-1, on its way to C2's shared spot, crossed uav-2's
    home spot at 5.6 m as uav-2 came down onto it from its hold height. A
    spot another UAV is granted (or sits on) is a column up to that UAV's
    hold height: the route climbs above it first."""
    c2 = SCENARIO.site.station("C2")
    spots_c2 = spot_positions(c2, SCENARIO.fleet)
    start = point(spots_c2[0].x_m + 4.0, c2.position.y_m, 5.0)  # east of uav-2's home spot
    rig = Rig(battery=0.5, position=start)
    rig.autopilot.update(flight_state=rig.autopilot.state.flight_state.FLYING, armed=True)
    spots = rig.agent.ctx.spots
    spots.update(feed("C2", ["uav-2", "uav-1", None]))  # uav-2 comes home, spot 1 is ours
    task = RechargeTask(task_id="r1", station_id="C2", position=c2.position, until_fraction=0.9)
    rig.agent.offer_plan(plan(task))
    rig.tick(2, arrive=False)
    climb = [arg for name, arg in rig.autopilot.calls if name == "goto"][-1]
    uav2_hold = spots.hold_point(c2, rig.agent.ctx.config.approach_alt_m)  # uav-1's own
    assert (climb.x_m, climb.y_m) == (start.x_m, start.y_m)  # up where it is
    assert climb.z_m >= uav2_hold.z_m + 2.0 + 2.0  # above uav-2's hold height (2 m higher)
    spots.update(feed("C2", [None, "uav-1", None], stamp=2.0))  # uav-2 gone elsewhere
    rig.tick(2, arrive=False)
    level = [arg for name, arg in rig.autopilot.calls if name == "goto"][-1]
    w3 = SCENARIO.site.worker("W3").position
    clear = SCENARIO.site.safety.people_clearance_m + rig.agent.ctx.config.route_margin_m
    # the column is free: across at uav-1's lowest level clear of W3 on the way
    assert level.z_m == own_level(w3.z_m + clear, *spots.layer)


def test_the_point_above_a_granted_spot_is_flown_to_once_no_uav_hovers_by_it():
    """Chaos seed 15: uav-1 came down to its spot at C2 1 m from uav-2,
    hovering at an inspection waypoint beside it. The point above a granted
    spot is kept clear of like any other; the hold point is not."""
    c2 = SCENARIO.site.station("C2")
    above = spot_positions(c2, SCENARIO.fleet)[1]
    rig = Rig(battery=0.5, position=point(above.x_m, above.y_m - 8.0, 5.0))
    rig.autopilot.update(flight_state=rig.autopilot.state.flight_state.FLYING, armed=True)
    spots = rig.agent.ctx.spots
    spots.update(feed("C2", [None, "uav-1", None]))
    waypoint = point(above.x_m, above.y_m + 1.0, 3.0)  # uav-2 inspects there
    hovering = TrafficEntry(uav_id="uav-2", position=waypoint, airborne=True, target=waypoint)
    rig.agent.ctx.traffic.update(Traffic(uavs=[hovering]), rig.clock())
    task = RechargeTask(task_id="r1", station_id="C2", position=c2.position, until_fraction=0.9)
    rig.agent.offer_plan(plan(task))
    start = rig.autopilot.state.position
    rig.tick(5)
    assert rig.autopilot.state.position == start  # holds off where it is
    rig.agent.ctx.traffic.update(Traffic(uavs=[]), rig.clock())  # uav-2 moved on
    rig.run_until(lambda: rig.autopilot.state.landed)
    landed = rig.autopilot.state.position
    assert (landed.x_m, landed.y_m) == (above.x_m, above.y_m)
