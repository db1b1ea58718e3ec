"""Ground contact is a crash; the world records safety violations once each."""

from __future__ import annotations

import itertools
import logging
import math
import random
import re

import msgspec

import proto
from proto.codec import decode, encode
from sim_fleet import World
from sim_fleet import autopilot as ap
from sim_fleet.modes import FlightState
from sim_fleet.params import AutopilotParams
from sim_fleet.safety import SafetyMonitor
from sim_fleet.truth import sim_state
from sim_fleet.vehicle import Vehicle
from tests.sim_fleet.helpers import QUAD, airborne, command, run_until, scenario, world


def kinds(w):
    return [(v.kind, v.vehicle_id, _other(v)) for v in w.violations]


def _other(v) -> str:
    """A separation's other vehicle (its detail begins with it), else the detail."""
    return v.detail.split()[0] if v.kind == "separation" else v.detail


def goto(w, v, target):
    ap.position_target(v, target, None)
    run_until(w, lambda: v.position == target)


def test_guided_target_below_the_ground_is_a_crash_and_ground_contact():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 5.0)
    v.take_texts()
    ap.position_target(v, (3.0, 50.0, -4.0), None)  # clamped to z = 0
    assert v.target == (3.0, 50.0, 0.0)
    run_until(w, lambda: v.state is not FlightState.FLYING, max_s=30.0, dt=w.physics_step_s)
    assert v.state is FlightState.CRASHED and not v.armed and v.position[2] == 0.0
    assert "Crash: Disarming" in [t.text for t in v.take_texts()]
    [violation] = w.violations
    assert (violation.kind, violation.vehicle_id) == ("ground_contact", "u1")
    assert violation.position[2] == 0.0 and violation.time_s == w.time_s
    w.step(30.0)
    assert len(w.violations) == 1  # a crash is recorded once
    assert command(w, v, 400, 1).result == ap.Result.FAILED  # cannot arm a wreck


def test_velocity_command_into_the_ground_is_a_crash():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 2.0)
    ap.position_target(v, None, (0.0, 0.0, -1.5))
    run_until(w, lambda: v.state is FlightState.CRASHED, max_s=3.0)
    assert kinds(w) == [("ground_contact", "u1", "flown into the ground in GUIDED")]


def test_land_mode_on_the_pad_lands_normally_without_violations():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    command(w, v, ap.CMD_NAV_LAND)
    run_until(w, lambda: v.state is FlightState.LANDED)
    assert not v.armed and w.violations == []


def test_falling_after_a_motor_failure_is_a_crash_but_not_ground_contact():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    v.fail_motors()
    run_until(w, lambda: v.state is FlightState.CRASHED, max_s=5.0)
    assert w.violations == []


def test_landing_away_from_every_station_is_an_off_pad_landing():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    goto(w, v, (30.0, 30.0, 10.0))
    command(w, v, ap.CMD_NAV_LAND)
    run_until(w, lambda: v.state is FlightState.LANDED)
    [violation] = w.violations
    assert violation.kind == "off_pad_landing" and violation.vehicle_id == "u1"
    assert violation.position == (30.0, 30.0, 0.0)
    # back to L1 (a landing spot without recharge, counts as a pad); not by RTL:
    # arming re-homed the vehicle where it stands, as ArduCopter does
    airborne(w, v, 10.0)
    assert v.home == (30.0, 30.0, 0.0)
    goto(w, v, (0.0, 50.0, 10.0))
    command(w, v, ap.CMD_NAV_LAND)
    run_until(w, lambda: v.state is FlightState.LANDED)
    assert len(w.violations) == 1


def test_people_proximity_once_per_approach_and_only_airborne():
    w = world(n=2, homes=("S1", "L1"))  # u2 stays landed at L1
    v = w.vehicle("u1")
    airborne(w, v, 4.0)
    goto(w, v, (40.0, 0.0, 5.0))  # 2 m above W1 at (40, 0, 3): clear of 1.5 m
    assert w.violations == []
    goto(w, v, (40.0, 0.0, 4.0))  # 1 m above W1
    w.step(20.0)  # hovering there: still one record
    assert kinds(w) == [("people_proximity", "u1", "W1")]
    goto(w, v, (40.0, 0.0, 8.0))
    goto(w, v, (40.5, 0.0, 4.0))  # a second approach
    assert kinds(w) == [("people_proximity", "u1", "W1")] * 2
    w.move_worker("W1", (0.0, 50.0, 0.5))  # the worker walks to the landed u2
    w.step(5.0)
    assert len(w.violations) == 2


def test_separation_recorded_once_under_the_lower_id():
    w = world(n=3, homes=("S1", "S2", "L1"))
    u1, u2, u3 = (w.vehicle(f"u{i}") for i in (1, 2, 3))
    airborne(w, u1, 10.0)
    airborne(w, u2, 10.0)
    x = u1.home[0]  # u1's home spot at S1
    goto(w, u2, (x + 0.6, 0.0, 10.0))  # u2 comes to u1
    w.step(10.0)
    assert kinds(w) == [("separation", "u1", "u2")]
    # where both were and what they did: a chaos report must be diagnosable
    assert re.fullmatch(
        r"u2 0\.\d\d m apart: u1 flying \w+ at \(.+\), u2 flying \w+ at \(.+\)",
        w.violations[0].detail,
    ), w.violations[0].detail
    goto(w, u2, (x, 0.0, 11.5))  # 1.5 m: clear again
    goto(w, u2, (x, 0.3, 10.5))
    assert kinds(w) == [("separation", "u1", "u2")] * 2
    # u3 landed at L1: coming down to 0.8 m above it is a near collision too
    goto(w, u1, (0.0, 50.0, 3.0))
    assert len(w.violations) == 2
    goto(w, u1, (0.0, 50.0, 0.8))
    assert kinds(w)[2:] == [("separation", "u1", "u3")]
    assert u3.state is FlightState.LANDED


def test_a_separation_is_logged_with_how_the_two_came_together(caplog):
    """The flight recorder: each vehicle's positions and targets over the
    last seconds, so a near collision in a chaos run can be diagnosed."""
    w = world(n=2, homes=("S1", "S2"))
    u1, u2 = w.vehicle("u1"), w.vehicle("u2")
    airborne(w, u1, 10.0)
    airborne(w, u2, 10.0)
    with caplog.at_level(logging.WARNING, logger="sim_fleet.world"):
        goto(w, u2, (0.6, 0.0, 10.0))
    [record] = [r for r in caplog.records if "separation u1/u2" in r.getMessage()]
    track = record.getMessage().splitlines()[1:]
    assert len(track) >= 10
    assert all("u1 (" in line and "u2 (" in line for line in track)
    assert "-> (0.6, 0.0, 10.0) flying" in track[-1]  # where u2 was sent


def test_a_crash_is_logged_with_how_the_vehicle_got_there(caplog):
    w = world(n=1, homes=("S1",))
    u1 = w.vehicle("u1")
    airborne(w, u1, 10.0)
    with caplog.at_level(logging.WARNING, logger="sim_fleet.world"):
        u1.battery.set_soc(0.0)  # empty: the motors stop
        w.step(20.0)
    assert u1.state is FlightState.CRASHED
    [record] = [r for r in caplog.records if "crash u1" in r.getMessage()]
    assert len(record.getMessage().splitlines()) > 5


def test_safety_distances_come_from_the_scenario():
    sc = scenario(n=2, homes=("S1", "S2"))
    rules = proto.Safety(people_clearance_m=3.0, separation_m=5.0)
    site = msgspec.structs.replace(sc.site, safety=rules)
    w = World(msgspec.structs.replace(sc, site=site), params=AutopilotParams(warmup_s=0.0))
    u1, u2 = w.vehicle("u1"), w.vehicle("u2")
    airborne(w, u1, 10.0)
    airborne(w, u2, 10.0)
    goto(w, u2, (4.0, 0.0, 10.0))
    goto(w, u1, (40.0, 0.0, 5.5))  # 2.5 m above W1
    assert [v.kind for v in w.violations] == ["separation", "people_proximity"]


def test_sim_state_reports_violations_as_proto_records():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 5.0)
    ap.position_target(v, (0.0, 50.0, 0.0), None)
    run_until(w, lambda: v.state is FlightState.CRASHED, max_s=30.0, dt=w.physics_step_s)
    state = sim_state(w, 1.0)
    [violation] = state.violations
    assert isinstance(violation, proto.SafetyViolation)
    assert (violation.kind, violation.uav_id) == ("ground_contact", "u1")
    assert violation.position == proto.Point(x_m=0.0, y_m=50.0, z_m=0.0)
    assert violation.sim_time_s == w.time_s
    assert decode(encode(state), proto.SimState) == state


def test_pairwise_sweep_finds_exactly_the_close_pairs():
    rng = random.Random(7)
    sc = scenario(n=60)
    vehicles = [
        Vehicle(spec, QUAD, sysid=i + 1, home=(0.0, 0.0, 0.0))
        for i, spec in enumerate(sc.fleet.uavs)
    ]
    for v in vehicles:
        v.state = FlightState.FLYING
        v.position = (rng.uniform(0, 10), rng.uniform(0, 10), rng.uniform(0, 3))
    landed = {vehicles[0].id, vehicles[1].id}  # two on the ground: never a pair
    vehicles[0].state = vehicles[1].state = FlightState.LANDED
    vehicles[1].position = (vehicles[0].position[0] + 0.5, *vehicles[0].position[1:])
    monitor = SafetyMonitor(proto.Safety(separation_m=1.0), [], 1.0)
    monitor.check(vehicles, {}, 0.0)
    found = {(v.vehicle_id, _other(v)) for v in monitor.violations}
    want = {
        tuple(sorted((a.id, b.id)))
        for a, b in itertools.combinations(vehicles, 2)
        if math.dist(a.position, b.position) < 1.0 and not {a.id, b.id} <= landed
    }
    assert found == want and len(found) == len(monitor.violations) > 0
    monitor.check(vehicles, {}, 0.05)  # nothing moved: nothing new
    assert len(monitor.violations) == len(found)
