"""A UAV flying a monitoring slot keeps it when the rest is replanned."""

from __future__ import annotations

import msgspec
import pytest

from ground_station.planner import Problem, RunningTask, plan, validate
from ground_station.planner.model import MonitorJob, slot_position

replace = msgspec.structs.replace


def _watching(paper: Problem, slot: int, bearing_deg: float) -> Problem:
    """uav1 watches ``slot`` of a k = 2 watch with 57 s left when the UAV on
    the other slot is gone (uav3 failed): uav2 comes from its pad, and uav1
    also has two deliveries to make (it is the only one with a gripper)."""
    monitor = next(a for a in paper.actions if isinstance(a, MonitorJob))
    monitor = replace(
        monitor, k=2, duration_s=57.0, start_s=0.0, standoff_m=4.0, bearing_deg=bearing_deg
    )
    wrench = next(a for a in paper.actions if a.id == "deliver-wrench")
    hammer = replace(
        wrench, id="deliver-hammer", tool="hammer", tool_station="hammer", worker_m=(5, 20, 3)
    )
    uav1, uav2, uav3 = paper.uavs
    uav1 = replace(
        uav1,
        position_m=slot_position(monitor, slot),
        airborne=True,
        energy_wh=50.0,
        running=RunningTask(action_id=monitor.id, index=slot),
    )
    uav2 = replace(uav2, position_m=(3.0, 20.0, 0.0), energy_wh=88.0)
    return replace(
        paper,
        uavs=(uav1, uav2, replace(uav3, available=False)),
        actions=(monitor, wrench, hammer),
    )


@pytest.mark.parametrize("slot", [0, 1])
@pytest.mark.parametrize("bearing_deg", [0.0, 90.0, 225.0])
def test_the_uav_on_a_slot_keeps_it_and_the_newcomer_takes_the_other(
    paper: Problem, slot: int, bearing_deg: float
) -> None:
    problem = _watching(paper, slot, bearing_deg)
    result = plan(problem)
    assert validate(problem, result) == []
    assert not result.unplaced
    segments = {u.uav_id: [s.index for s in u.steps if s.kind == "monitor"] for u in result.uavs}
    assert segments["uav1"][:1] == [slot]  # it goes on watching where it is
    assert segments["uav2"][:1] == [1 - slot]
