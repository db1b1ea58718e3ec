"""When a replan's tasks for a UAV ask the same of it (no new epoch, nothing
sent) and when they do not."""

from __future__ import annotations

import msgspec

from ground_station.planning import same_work
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
