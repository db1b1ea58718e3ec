"""Stations may stand above the terrain (a pad on a roof): vehicles rest on,
take off from and land on the deck; away from it the ground is the terrain.
Altitudes on the wire: AMSL = origin + site z, relative = above home."""

from __future__ import annotations

import pytest

from sim_fleet import Fleet, FleetConfig, FleetThread
from sim_fleet import autopilot as ap
from sim_fleet.modes import FlightState
from sim_fleet.params import AutopilotParams
from tests.sim_fleet.helpers import airborne, command, run_until, scenario, station, world
from tests.sim_fleet.mavclient import Client, mavlink

# one pad at (0, 0, 6); based there, u1's home spot is beside it at (2, 0, 6) (proto.spots)
ROOF = station("ROOF", 0.0, 0.0, 6.0)
YARD = station("YARD", 30.0, 0.0)
STATIONS = (ROOF, YARD)


def site(home: str):
    w = world(stations=STATIONS, homes=(home,))
    return w, w.vehicle("u1")


def goto(w, v, target):
    ap.position_target(v, target, None)
    run_until(w, lambda: v.position == target or v.state is FlightState.CRASHED, max_s=120)


def land(w, v):
    assert command(w, v, ap.CMD_NAV_LAND).result == 0
    run_until(w, lambda: v.state is not FlightState.LANDING, max_s=120)


def test_the_ground_is_a_decks_top_over_it_and_the_terrain_elsewhere():
    w, _ = site("ROOF")
    assert w.ground_z(0.0, 0.0) == w.ground_z(1.0, 0.5) == w.ground_z(2.9, 0.0) == 6.0
    assert w.ground_z(3.5, 0.0) == w.ground_z(1.0, 1.5) == w.ground_z(30.0, 0.0) == 0.0


def test_a_vehicle_rests_on_its_roof_pad_and_takes_off_above_home():
    w, v = site("ROOF")
    assert v.position == v.home == (2.0, 0.0, 6.0)
    assert command(w, v, 176, 1, 4).result == 0
    assert command(w, v, 400, 1).result == 0
    assert command(w, v, ap.CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 0.0).result == ap.Result.FAILED
    assert command(w, v, ap.CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 4.0).result == 0
    run_until(w, lambda: v.state is FlightState.FLYING)
    assert v.position == (2.0, 0.0, 10.0)


def test_below_a_roofs_top_away_from_it_is_flying_and_the_terrain_is_a_crash():
    w, v = site("ROOF")
    airborne(w, v, 4.0)
    goto(w, v, (10.0, 0.0, 1.0))  # below the roof, beside it
    assert v.state is FlightState.FLYING and w.violations == []
    goto(w, v, (10.0, 0.0, -1.0))
    assert v.state is FlightState.CRASHED and v.position == (10.0, 0.0, 0.0)
    assert [x.kind for x in w.violations] == ["ground_contact"]


def test_flying_into_a_raised_deck_below_its_top_is_a_crash():
    w, v = site("YARD")
    airborne(w, v, 4.0)
    goto(w, v, (0.0, 0.0, 4.0))
    assert v.state is FlightState.CRASHED and v.position[2] == 6.0
    assert [x.kind for x in w.violations] == ["ground_contact"]


def test_landing_onto_a_roof_pad_is_no_crash_and_landing_beside_it_reaches_the_terrain():
    w, v = site("YARD")
    airborne(w, v, 4.0)
    goto(w, v, (0.0, 0.0, 9.0))
    land(w, v)
    assert v.state is FlightState.LANDED and v.position == (0.0, 0.0, 6.0)
    assert not v.armed and w.violations == []
    airborne(w, v, 3.0)
    goto(w, v, (0.0, 4.0, 9.0))
    land(w, v)
    assert v.state is FlightState.LANDED and v.position == (0.0, 4.0, 0.0)
    assert [x.kind for x in w.violations] == ["off_pad_landing"]


def test_rtl_climbs_above_home_and_lands_back_on_the_roof():
    w, v = site("ROOF")
    airborne(w, v, 4.0)
    goto(w, v, (30.0, 10.0, 3.0))
    peak = 0.0

    def landed() -> bool:
        nonlocal peak
        peak = max(peak, v.position[2])
        return v.state is FlightState.LANDED

    assert command(w, v, ap.CMD_NAV_RETURN_TO_LAUNCH).result == 0
    run_until(w, landed)
    assert peak == pytest.approx(6.0 + v.params.rtl_alt_m, abs=0.05)
    assert v.position == pytest.approx((2.0, 0.0, 6.0)) and w.violations == []


def test_mavlink_altitudes_are_amsl_and_above_home_and_absolute_targets_are_honoured():
    sc = scenario(stations=STATIONS, homes=("ROOF",))
    origin_mm = round(sc.site.origin.alt_m * 1000)
    config = FleetConfig(
        speedup=10.0, rate_hz=50.0, base_port=0, params=AutopilotParams(warmup_s=0.0)
    )
    runner = FleetThread(Fleet(sc, config)).start()
    client = Client(runner.fleet.ports["u1"], target_system=1)
    v = runner.fleet.world.vehicle("u1")
    try:
        on_roof = client.wait("GLOBAL_POSITION_INT")
        assert (on_roof.alt - origin_mm, on_roof.relative_alt) == (6000, 0)
        client.conn.mav.command_long_send(1, 1, 512, 0, 242, 0, 0, 0, 0, 0, 0)  # REQUEST_MESSAGE
        home = client.wait("HOME_POSITION")
        assert home.altitude - origin_mm == 6000
        client.conn.mav.command_long_send(1, 1, 176, 0, 1, 4, 0, 0, 0, 0, 0)
        client.conn.mav.command_long_send(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0)
        client.conn.mav.command_long_send(1, 1, 22, 0, 0, 0, 0, 0, 0, 0, 3.0)
        client.wait("GLOBAL_POSITION_INT", lambda m: m.relative_alt > 2900, timeout_s=20.0)
        lat, lon, alt = runner.fleet.world.geo.to_geodetic((10.0, 0.0, 4.0))  # beside the roof
        client.conn.mav.set_position_target_global_int_send(
            0, 1, 1, mavlink.MAV_FRAME_GLOBAL_INT, 0b110111111000,
            round(lat * 1e7), round(lon * 1e7), alt, 0, 0, 0, 0, 0, 0, 0, 0,
        )  # fmt: skip
        low = client.wait("GLOBAL_POSITION_INT", lambda m: m.relative_alt < -1900, timeout_s=20.0)
        assert low.alt - origin_mm == pytest.approx(low.relative_alt + 6000, abs=1)
        client.wait("GLOBAL_POSITION_INT", lambda m: m.vz == 0 and m.alt - origin_mm == 4000)
        assert runner.call(lambda: v.position[2]) == pytest.approx(4.0)
    finally:
        client.close()
        runner.stop()
