"""When a replan's tasks for a UAV ask the same of it (no new epoch, nothing
sent) and when they do not."""

from __future__ import annotations

import msgspec

from ground_station.planning import TAKEOFF_LEAD_S, lead_departures, same_work
from proto import GoHomeTask, MonitorTask, Point, WaitTask

SEGMENT = MonitorTask(
    task_id="watch.slot0.uav-3.7",
    action_id="watch",
    worker_id="W2",
    slot=0,
    slots=1,
    standoff_m=4,
    duration_s=213,
    end_s=1686,
)
HOME = GoHomeTask(task_id="uav-3.home", station_id="C2", position=Point(x_m=0, y_m=0))


def test_the_same_ids_with_jittered_estimates_are_the_same_work():
    jittered = msgspec.structs.replace(SEGMENT, end_s=1688, duration_s=214)
    assert same_work([SEGMENT, HOME], [jittered, HOME])
    wait = WaitTask(task_id="uav-3.wait1", until_s=1473.0)
    assert same_work([wait], [msgspec.structs.replace(wait, until_s=1473.6)])


def test_a_segment_cut_short_is_new_work_though_its_id_stays():
    """The UAV must leave 37 s earlier and another takes the rest: unless the
    shorter segment is sent, both hold the slot for those 37 s."""
    cut = msgspec.structs.replace(SEGMENT, end_s=1649, duration_s=176)
    assert not same_work([SEGMENT, HOME], [cut, HOME])


def test_other_ids_or_a_moved_wait_are_new_work():
    assert not same_work([SEGMENT, HOME], [HOME])
    wait = WaitTask(task_id="uav-3.wait1", until_s=1473.0)
    assert not same_work([wait], [msgspec.structs.replace(wait, until_s=1480.0)])


def test_a_wait_before_monitoring_ends_early_and_one_left_under_a_second_is_dropped():
    """Chaos seed 15: a wait cut to end where it starts (the take-off lead)
    was sent, finished at once and planned again, over and over. Waits
    before a segment end ``TAKEOFF_LEAD_S`` early; one shorter than a
    second is no task at all."""
    now = 1000.0
    segment = MonitorTask(
        task_id="m.slot0.uav-1.1", action_id="m", worker_id="W1", slot=0, slots=1,
        standoff_m=3.0, height_m=2.0, duration_s=60.0, start_s=now + 40.0, end_s=now + 100.0,
    )  # fmt: skip
    long_wait = WaitTask(task_id="uav-1.wait1", until_s=now + 30.0, start_s=now, end_s=now + 30.0)
    [kept, _] = lead_departures([long_wait, segment])
    assert isinstance(kept, WaitTask) and kept.until_s == now + 30.0 - TAKEOFF_LEAD_S
    short = msgspec.structs.replace(long_wait, until_s=now + 8.0, end_s=now + 8.0)
    assert lead_departures([short, segment]) == [segment]
    blink = msgspec.structs.replace(long_wait, until_s=now + 0.5, end_s=now + 0.5)
    home = GoHomeTask(task_id="uav-1.home", station_id="C1", position=Point(x_m=0, y_m=0, z_m=0))
    assert lead_departures([blink, home]) == [home]
