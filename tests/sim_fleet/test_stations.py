"""Charging pads: swap vs charge times, and queueing when pads are full."""

from __future__ import annotations

import pytest

from proto.site import BatterySwap
from sim_fleet import autopilot as ap
from sim_fleet.modes import FlightState
from tests.sim_fleet.helpers import airborne, command, run_until, station, world

CHARGE_S = 1000.0
SWAP_S = 30.0


def test_charge_time_is_proportional_to_missing_energy():
    w = world(homes=("S1",), soc=0.6)
    v = w.vehicle("u1")
    took = run_until(w, lambda: v.battery.soc >= 1.0, dt=1.0)
    assert took == pytest.approx(0.4 * CHARGE_S, abs=1.5)  # dt = 1 s resolution
    w.step(1.0)
    assert w.station_status("u1") == ("S1", "charged")


def test_swap_takes_fixed_time_whatever_the_level():
    for soc in (0.3, 0.9):
        w = world(homes=("S2",), soc=soc)
        v = w.vehicle("u1")
        w.step(SWAP_S - 1.0)
        assert v.battery.soc == pytest.approx(soc)
        w.step(2.0)
        assert v.battery.soc == 1.0


def test_landing_on_a_pad_recharges():
    w = world(soc=0.8)
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    ap.position_target(v, (0.0, 0.0, 10.0), None)  # over S1
    run_until(w, lambda: v.position == (0.0, 0.0, 10.0))
    command(w, v, ap.CMD_NAV_LAND)
    run_until(w, lambda: v.state is FlightState.LANDED)
    low = v.battery.soc
    assert low < 0.8
    w.step(10.0)
    assert w.station_status("u1") == ("S1", "charging")
    run_until(w, lambda: v.battery.soc >= 1.0, dt=1.0)
    assert any(t.text == "Pad: battery full at S1" for t in v.take_texts())


def test_more_vehicles_than_pads_queue_in_arrival_order():
    stations = (
        station("P", 0.0, 0.0, pads=2, recharge=BatterySwap(swap_s=SWAP_S)),
        station("L1", 0.0, 50.0),
    )
    w = world(n=3, stations=stations, homes=("P", "P", "P"), soc=0.5)
    w.step(0.1)
    status = [w.station_status(f"u{i}") for i in (1, 2, 3)]
    assert status == [("P", "charging"), ("P", "charging"), ("P", "queued")]
    w.step(SWAP_S)
    assert [w.vehicle(f"u{i}").battery.soc for i in (1, 2, 3)] == [1.0, 1.0, 0.5]
    # u1 leaves the pad: u3 gets it and is swapped SWAP_S later
    u1 = w.vehicle("u1")
    airborne(w, u1, 5.0)
    assert w.station_status("u1") is None
    assert w.station_status("u3") == ("P", "charging")
    w.step(SWAP_S + 0.5)
    assert w.vehicle("u3").battery.soc == 1.0


def test_armed_vehicle_is_not_charged():
    w = world(homes=("S1",), soc=0.5)
    v = w.vehicle("u1")
    command(w, v, 176, 1, 4)
    command(w, v, 400, 1)
    w.step(100.0)
    assert v.battery.soc == 0.5 and w.station_status("u1") is None
