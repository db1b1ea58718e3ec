from __future__ import annotations

import pytest

from sim_fleet.battery import Battery, cell_voltage


def test_draw_removes_power_times_time():
    b = Battery(100.0)
    b.draw(360.0, 100.0)  # 360 W for 100 s = 10 Wh
    assert b.energy_wh == pytest.approx(90.0)
    assert b.soc == pytest.approx(0.9)
    assert b.consumed_wh == pytest.approx(10.0)


def test_draw_stops_at_empty_and_reports_powered_time():
    b = Battery(1.0)
    powered = b.draw(3600.0, 10.0)  # 1 Wh lasts 1 s at 3600 W
    assert powered == pytest.approx(1.0)
    assert b.empty and b.energy_wh == 0.0


def test_voltage_falls_with_charge_and_sags_under_load():
    assert cell_voltage(1.0) == pytest.approx(4.2)
    assert cell_voltage(0.0) == pytest.approx(3.3)
    socs = [i / 20 for i in range(21)]
    volts = [cell_voltage(s) for s in socs]
    assert volts == sorted(volts)
    b = Battery(100.0, soc=0.5, cells=4)
    rest = b.voltage_v()
    b.load_w = 400.0
    assert b.voltage_v() < rest
    assert b.current_a() == pytest.approx(400.0 / b.open_circuit_v())


def test_add_and_set_soc_clamp_to_capacity():
    b = Battery(50.0, soc=0.2)
    b.add(100.0)
    assert b.soc == 1.0
    b.set_soc(-1.0)
    assert b.soc == 0.0
