"""The paper's Fig. 6: hand-over of a monitoring slot with no gap."""

from __future__ import annotations

from ground_station.planner import Problem, plan, validate


def _kinds(steps):
    return [s.kind for s in steps]


def test_fig6_structure(fig6: Problem) -> None:
    result = plan(fig6)
    assert validate(fig6, result) == []
    assert result.unplaced == ()
    uav1, uav2 = result.uavs
    # Only uav1 can deliver: its plan starts with the pick and the delivery.
    assert _kinds(uav1.steps)[:2] == ["pick", "deliver"]
    assert all(s.kind not in ("pick", "deliver") for s in uav2.steps)
    # uav2 inspects first, then monitors, breaks off to recharge, and resumes.
    mon2 = [i for i, s in enumerate(uav2.steps) if s.kind == "monitor"]
    assert uav2.steps[0].kind == "inspect" and uav2.steps[0].action_id == "a2-inspect"
    assert len(mon2) == 2
    between = _kinds(uav2.steps[mon2[0] + 1 : mon2[1]])
    assert "recharge" in between
    # uav1 takes the slot exactly when uav2 leaves: no gap in coverage.
    mon1 = [i for i, s in enumerate(uav1.steps) if s.kind == "monitor"]
    assert len(mon1) == 1
    first2, take1, back2 = uav2.steps[mon2[0]], uav1.steps[mon1[0]], uav2.steps[mon2[1]]
    assert take1.arrive_s <= first2.end_s + 1e-6
    assert back2.arrive_s <= take1.end_s + 1e-6
    assert take1.index == first2.index == back2.index == 0
    # A wait synchronises uav1 with the hand-over.
    assert uav1.steps[mon1[0] - 1].kind == "wait"
    # The second inspection fills uav1's idle time before the hand-over.
    inspect1 = [s for s in uav1.steps[: mon1[0]] if s.kind == "inspect"]
    assert inspect1 and all(s.action_id == "a4-inspect" for s in inspect1)
    # Monitoring lasts its full duration from a common start.
    assert back2.end_s - first2.arrive_s >= 400 - 1e-6


def test_paper_example_plans_everything(paper: Problem) -> None:
    result = plan(paper)
    assert validate(paper, result) == []
    assert result.unplaced == ()
    assert result.metrics.makespan_s > 0
