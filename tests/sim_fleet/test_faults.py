"""Fault operations on the world and its vehicles."""

from __future__ import annotations

import pytest

from sim_fleet.modes import FlightState
from tests.sim_fleet.helpers import airborne, run_until, world


def test_battery_drop_to_level():
    w = world()
    v = w.vehicle("u1")
    v.set_battery_soc(0.15)
    assert v.battery.soc == pytest.approx(0.15)


def test_drain_multiplier_scales_energy():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v)
    v.drain_multiplier = 3.0
    before = v.battery.energy_wh
    w.step(60.0)
    assert before - v.battery.energy_wh == pytest.approx(3.0 * v.type.hover_power_w * 60.0 / 3600.0)


def test_motor_failure_falls_and_crashes():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 20.0)
    v.fail_motors()
    assert v.state is FlightState.FALLING and not v.armed
    took = run_until(w, lambda: v.state is FlightState.CRASHED, dt=0.05)
    assert took == pytest.approx((2 * 20.0 / 9.81) ** 0.5, abs=0.1)


def test_link_drop_is_timed_in_simulated_seconds():
    w = world()
    v = w.vehicle("u1")
    v.drop_link(5.0)
    assert not v.link_up()
    w.step(4.9)
    assert not v.link_up()
    w.step(0.2)
    assert v.link_up()


def test_kill_is_permanent_silence_and_a_fall():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    v.kill()
    w.step(100.0)
    assert not v.link_up() and v.state is FlightState.CRASHED


def test_gps_freeze_holds_reported_position_for_a_while():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    frozen = v.reported_position()[0]
    v.freeze_gps(10.0)
    from sim_fleet import autopilot as ap

    ap.position_target(v, (20.0, 50.0, 10.0), None)
    w.step(5.0)
    assert v.reported_position()[0] == frozen != v.position
    w.step(6.0)
    assert v.reported_position()[0] == v.position


def test_move_worker_changes_delivery_target():
    w = world()
    w.move_worker("W1", (1.0, 2.0, 3.0))
    assert w.workers["W1"] == (1.0, 2.0, 3.0)
    with pytest.raises(KeyError):
        w.move_worker("nobody", (0.0, 0.0, 0.0))
