from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from sim_fleet import physics

LIM = physics.Limits(horizontal_mps=5.0, up_mps=2.0, down_mps=1.0, accel_mps2=2.0)


def fly(start, target, *, dt=0.05, max_s=200.0):
    pos, vel, t = start, (0.0, 0.0, 0.0), 0.0
    peak_h = peak_up = peak_down = peak_acc = 0.0
    while pos != target:
        new_pos, new_vel = physics.step_to_target(pos, vel, target, LIM, dt)
        peak_acc = max(peak_acc, math.dist(new_vel, vel) / dt)
        pos, vel, t = new_pos, new_vel, t + dt
        peak_h = max(peak_h, math.hypot(vel[0], vel[1]))
        peak_up, peak_down = max(peak_up, vel[2]), max(peak_down, -vel[2])
        assert t < max_s, "never arrived"
    return t, peak_h, peak_up, peak_down, peak_acc


def test_reaches_target_within_speed_and_accel_limits():
    t, h, _, _, acc = fly((0.0, 0.0, 0.0), (100.0, 0.0, 0.0))
    assert h <= 5.0 + 1e-9 and acc <= 2.0 * math.sqrt(2) + 1e-6
    # 100 m at 5 m/s with 2 m/s^2 ramps: 20 s cruise + 2.5 s of ramps
    assert 22.0 < t < 25.0


def test_vertical_rates_are_separate():
    _, _, up, _, _ = fly((0.0, 0.0, 0.0), (0.0, 0.0, 20.0))
    _, _, _, down, _ = fly((0.0, 0.0, 20.0), (0.0, 0.0, 0.0))
    assert up == pytest.approx(2.0, abs=1e-6)
    assert down == pytest.approx(1.0, abs=1e-6)


@given(
    st.tuples(*(st.floats(-200, 200) for _ in range(2)), st.floats(0, 50)),
    st.tuples(*(st.floats(-200, 200) for _ in range(2)), st.floats(0, 50)),
)
def test_always_arrives_exactly(start, target):
    fly(start, target, dt=0.1, max_s=1000.0)


def test_falling_accelerates_down():
    pos, vel = (0.0, 0.0, 10.0), (1.0, 0.0, 0.0)
    pos, vel = physics.step_falling(pos, vel, 1.0)
    assert vel[2] == pytest.approx(-9.81)
    assert pos[0] == pytest.approx(1.0)
