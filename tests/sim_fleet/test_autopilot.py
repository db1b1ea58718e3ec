"""ArduCopter's accept/deny rules, one command at a time."""

from __future__ import annotations

import pytest

from sim_fleet import autopilot as ap
from sim_fleet.events import Result
from sim_fleet.modes import FlightState, Mode
from tests.sim_fleet.helpers import airborne, command, world

ARM, MODE, TAKEOFF, SPEED, GRIPPER = 400, 176, 22, 178, 211


@pytest.fixture
def wv():
    w = world()
    return w, w.vehicle("u1")


def test_arm_needs_an_armable_mode(wv):
    w, v = wv
    command(w, v, MODE, 1, Mode.LAND)
    out = command(w, v, ARM, 1)
    assert out.result is Result.FAILED and out.text == "Arm: Mode not armable"
    command(w, v, MODE, 1, Mode.GUIDED)
    assert command(w, v, ARM, 1).result is Result.ACCEPTED
    assert command(w, v, ARM, 1).result is Result.ACCEPTED  # already armed


def test_arm_needs_enough_battery_unless_forced(wv):
    w, v = wv
    command(w, v, MODE, 1, Mode.GUIDED)
    v.battery.set_soc(0.1)
    out = command(w, v, ARM, 1)
    assert out.result is Result.FAILED
    assert out.text == "PreArm: Battery 1 below minimum arming capacity"
    assert command(w, v, ARM, 1, ap.FORCE_MAGIC).result is Result.ACCEPTED


def test_takeoff_only_armed_in_guided(wv):
    w, v = wv
    assert command(w, v, TAKEOFF, *[0] * 6, 10).result is Result.FAILED  # disarmed
    command(w, v, ARM, 1)  # STABILIZE is armable...
    assert v.armed
    assert command(w, v, TAKEOFF, *[0] * 6, 10).result is Result.FAILED  # ...but has no takeoff
    command(w, v, MODE, 1, Mode.GUIDED)
    assert command(w, v, TAKEOFF, *[0] * 6, 0).result is Result.FAILED  # not above us
    assert command(w, v, TAKEOFF, *[0] * 6, 10).result is Result.ACCEPTED
    assert v.state is FlightState.TAKING_OFF
    assert command(w, v, TAKEOFF, *[0] * 6, 20).result is Result.FAILED  # already flying


def test_takeoff_command_int_needs_relative_alt_frame(wv):
    w, v = wv
    command(w, v, MODE, 1, Mode.GUIDED)
    command(w, v, ARM, 1)
    assert command(w, v, TAKEOFF, *[0] * 6, 10, frame=0).result is Result.DENIED
    assert command(w, v, TAKEOFF, *[0] * 6, 10, frame=3).result is Result.ACCEPTED


def test_disarm_in_flight_fails_unless_forced_then_falls(wv):
    w, v = wv
    airborne(w, v)
    assert command(w, v, ARM, 0).result is Result.FAILED
    assert v.armed
    assert command(w, v, ARM, 0, ap.FORCE_MAGIC).result is Result.ACCEPTED
    assert v.state is FlightState.FALLING


def test_set_mode_rules(wv):
    _, v = wv
    assert ap.set_mode(v, 0, Mode.GUIDED).result is Result.DENIED  # no custom-mode flag
    out = ap.set_mode(v, 1, 2)  # ALT_HOLD: not simulated
    assert out.result is Result.FAILED and out.text == "No such mode 2"
    assert ap.set_mode(v, 1, Mode.RTL).result is Result.ACCEPTED and v.mode is Mode.RTL


def test_change_speed(wv):
    w, v = wv
    command(w, v, MODE, 1, Mode.GUIDED)
    assert command(w, v, SPEED, 1, 0).result is Result.DENIED  # speed must be > 0
    assert command(w, v, SPEED, 7, 3).result is Result.DENIED  # no such speed type
    assert command(w, v, SPEED, 1, 3).result is Result.ACCEPTED and v.speed_mps == 3
    assert command(w, v, SPEED, 1, 99).result is Result.ACCEPTED
    assert v.speed_mps == 2 * v.type.cruise_speed_mps  # the cap
    assert command(w, v, SPEED, 2, 1).result is Result.ACCEPTED and v.climb_mps == 1
    assert command(w, v, SPEED, 3, 0.5).result is Result.ACCEPTED and v.descent_mps == 0.5
    command(w, v, MODE, 1, Mode.LAND)
    assert command(w, v, SPEED, 1, 3).result is Result.FAILED


def test_gripper_unsupported_without_one(wv):
    w, v = wv
    out = command(w, v, GRIPPER, 1, 1)
    assert out.result is Result.UNSUPPORTED


def test_unknown_command_is_unsupported_and_odd_params_are_safe(wv):
    w, v = wv
    nan = float("nan")
    assert command(w, v, 31337).result is Result.UNSUPPORTED
    assert command(w, v, ARM, nan).result is Result.DENIED
    assert command(w, v, MODE, nan, nan).result is Result.DENIED
    assert command(w, v, SPEED, nan, 3).result is Result.DENIED
    assert command(w, v, ap.CMD_NAV_LAND, 0, 0, 0, nan).result is Result.ACCEPTED  # yaw NaN


def test_position_target_ignored_outside_guided_flight(wv):
    w, v = wv
    ap.position_target(v, (10.0, 10.0, 10.0), None)
    assert v.target is None  # landed
    airborne(w, v)
    command(w, v, MODE, 1, Mode.STABILIZE)
    ap.position_target(v, (10.0, 10.0, 10.0), None)
    assert v.target != (10.0, 10.0, 10.0)


def test_velocity_command_expires(wv):
    w, v = wv
    airborne(w, v)
    ap.position_target(v, None, (1.0, 0.0, 0.0))
    w.step(2.0)
    assert v.velocity[0] == pytest.approx(1.0)
    w.step(3.0)  # no refresh for more than 3 s: stop
    assert v.velocity_cmd is None
    w.step(2.0)
    assert v.velocity == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
