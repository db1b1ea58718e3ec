"""Flight states, energy and failure of one vehicle, stepped by hand."""

from __future__ import annotations

import pytest

from sim_fleet import autopilot as ap
from sim_fleet.modes import FlightState, Mode
from sim_fleet.params import AutopilotParams
from tests.sim_fleet.helpers import QUAD, airborne, command, run_until, world


def test_takeoff_reaches_altitude_and_hovers():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 12.0)
    assert v.state is FlightState.FLYING and v.position[2] == 12.0
    assert v.velocity == (0.0, 0.0, 0.0)


def test_ground_and_disarmed_draw_no_energy():
    w = world()
    v = w.vehicle("u1")
    w.step(600.0)
    assert v.battery.soc == 1.0
    command(w, v, 176, 1, Mode.GUIDED)
    command(w, v, 400, 1)
    w.step(5.0)  # armed on the ground, auto-disarm off
    assert v.armed and v.battery.soc == 1.0


def test_hover_energy_is_hover_power_times_time():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    before = v.battery.energy_wh
    w.step(120.0)
    assert before - v.battery.energy_wh == pytest.approx(QUAD.hover_power_w * 120.0 / 3600.0)


def test_cruise_energy_is_flight_power_times_time():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    ap.position_target(v, (0.0, 50.0 + 500.0, 10.0), None)
    run_until(w, lambda: v.velocity[1] == pytest.approx(QUAD.cruise_speed_mps))
    before = v.battery.energy_wh
    w.step(60.0)  # still cruising: 500 m at 5 m/s is 100 s
    assert before - v.battery.energy_wh == pytest.approx(QUAD.flight_power_w * 60.0 / 3600.0)


def test_land_mode_descends_lands_and_disarms():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    assert command(w, v, ap.CMD_NAV_LAND).result == 0
    assert v.state is FlightState.LANDING
    run_until(w, lambda: v.state is FlightState.LANDED)
    assert not v.armed and v.position[2] == 0.0


def test_rtl_climbs_returns_home_and_lands():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 5.0)
    ap.position_target(v, (30.0, 20.0, 5.0), None)
    run_until(w, lambda: v.position == (30.0, 20.0, 5.0))
    peak = 0.0

    def home_and_landed():
        nonlocal peak
        peak = max(peak, v.position[2])
        return v.state is FlightState.LANDED

    assert command(w, v, ap.CMD_NAV_RETURN_TO_LAUNCH).result == 0
    run_until(w, home_and_landed)
    assert peak == pytest.approx(v.params.rtl_alt_m, abs=0.05)
    assert v.position == pytest.approx(v.home) and not v.armed


def test_auto_disarm_after_delay_on_ground():
    w = world(params=AutopilotParams(auto_disarm_s=10.0, warmup_s=0.0))
    v = w.vehicle("u1")
    command(w, v, 176, 1, Mode.GUIDED)
    command(w, v, 400, 1)
    w.step(9.0)
    assert v.armed
    w.step(2.0)
    assert not v.armed


def test_out_of_energy_in_the_air_falls_and_crashes_with_statustext():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 20.0)
    v.take_texts()
    v.battery.set_soc(0.001)  # ~0.1 Wh: about a second of hover
    run_until(w, lambda: v.state is FlightState.FALLING, max_s=5.0)
    run_until(w, lambda: v.state is FlightState.CRASHED, max_s=5.0)
    assert v.position[2] == 0.0 and not v.armed
    texts = [t.text for t in v.take_texts()]
    assert "Battery 1 empty: motors stopped" in texts
    assert "Crash: Disarming" in texts
    assert command(w, v, 400, 1).result == ap.Result.FAILED


def test_low_and_critical_battery_warnings_once_each():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    v.take_texts()
    v.battery.set_soc(0.205)
    for _ in range(3):  # hover 300 W on 100 Wh: 5 %/min, crosses 20 % then 10 %
        w.step(60.0)
    texts = [t.text for t in v.take_texts()]
    assert sum("is low" in t for t in texts) == 1
    assert sum("is critical" in t for t in texts) == 1
