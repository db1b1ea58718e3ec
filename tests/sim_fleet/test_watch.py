"""The simulator's watched seconds: hovering above a worker, near enough, counts."""

from __future__ import annotations

import pytest

from sim_fleet import autopilot as ap
from sim_fleet.truth import sim_state
from tests.sim_fleet.helpers import airborne, run_until, world


def hover_at(w, v, target, seconds):
    ap.position_target(v, target, None)
    run_until(w, lambda: v.position == target)
    before = w.watch.seconds[("W1", v.id)]
    w.step(seconds)
    return w.watch.seconds[("W1", v.id)] - before


def test_a_hover_at_the_stand_off_counts_in_full_and_is_in_the_truth():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 6.0)
    assert hover_at(w, v, (35.0, 0.0, 6.0), 20.0) == pytest.approx(20.0, abs=0.06)
    [record] = sim_state(w, 1.0).watched
    assert (record.worker_id, record.uav_id) == ("W1", "u1")
    assert record.seconds == pytest.approx(w.watch.seconds[("W1", "u1")])


@pytest.mark.parametrize(
    "where",
    [(20.0, 0.0, 6.0), (35.0, 0.0, 2.0)],  # 20 m off (beyond 15 m); below the worker's head
    ids=["too-far", "too-low"],
)
def test_a_hover_too_far_or_below_the_worker_does_not_count(where):
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, where[2])
    assert hover_at(w, v, where, 20.0) == 0.0


def test_flying_past_does_not_count():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 6.0)
    ap.position_target(v, (80.0, 0.0, 6.0), None)  # straight over W1 at cruise speed
    run_until(w, lambda: v.position[0] > 60.0)
    assert w.watch.seconds[("W1", "u1")] < 1.0
