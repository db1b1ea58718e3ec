"""The validator detects each kind of violation (and accepts a valid plan)."""

from __future__ import annotations

import msgspec
import pytest

from ground_station.planner import (
    DeliverJob,
    Problem,
    Solution,
    Step,
    Unplaced,
    plan,
    validate,
)

replace = msgspec.structs.replace


@pytest.fixture
def base(fig6: Problem) -> tuple[Problem, Solution]:
    result = plan(fig6)
    assert validate(fig6, result) == []
    return fig6, result


def codes(problem: Problem, p: Solution) -> set[str]:
    return {v.code for v in validate(problem, p)}


def edit_step(p: Solution, uav: int, at: int, /, **changes: object) -> Solution:
    steps = list(p.uavs[uav].steps)
    steps[at] = replace(steps[at], **changes)
    uavs = list(p.uavs)
    uavs[uav] = replace(uavs[uav], steps=tuple(steps))
    return replace(p, uavs=tuple(uavs))


def set_steps(p: Solution, uav: int, steps: list[Step]) -> Solution:
    uavs = list(p.uavs)
    uavs[uav] = replace(uavs[uav], steps=tuple(steps))
    return replace(p, uavs=tuple(uavs))


def find(p: Solution, uav: int, kind: str, nth: int = 0) -> int:
    return [i for i, s in enumerate(p.uavs[uav].steps) if s.kind == kind][nth]


def edit_action(problem: Problem, action_id: str, **changes: object) -> Problem:
    actions = tuple(replace(a, **changes) if a.id == action_id else a for a in problem.actions)
    return replace(problem, actions=actions)


def edit_uav(problem: Problem, index: int, **changes: object) -> Problem:
    uavs = list(problem.uavs)
    uavs[index] = replace(uavs[index], **changes)
    return replace(problem, uavs=tuple(uavs))


def test_capability_violation(base) -> None:
    problem, p = base
    types = list(problem.uav_types)
    types[1] = replace(types[1], capabilities={"monitor": 0.0})
    assert "capability" in codes(replace(problem, uav_types=tuple(types)), p)


def test_below_reserve(base) -> None:
    problem, p = base
    assert "below_reserve" in codes(edit_uav(problem, 1, energy_wh=35.0), p)


def test_energy_overstated(base) -> None:
    problem, p = base
    i = find(p, 1, "inspect", 1)
    bad = edit_step(p, 1, i, energy_after_wh=p.uavs[1].steps[i].energy_after_wh + 5)
    assert "energy_mismatch" in codes(problem, bad)


def test_overcharged_battery(base) -> None:
    problem, p = base
    i = find(p, 1, "recharge")
    s = p.uavs[1].steps[i]
    bad = edit_step(p, 1, i, end_s=s.arrive_s + 1.0)  # a 30 s swap cut to 1 s
    assert "energy_mismatch" in codes(problem, bad)


def test_waypoint_twice_and_missing(base) -> None:
    problem, p = base
    i = find(p, 1, "inspect", 1)
    bad = edit_step(p, 1, i, index=0)
    found = codes(problem, bad)
    assert {"waypoint_duplicate", "waypoint_missing"} <= found


def test_monitor_gap(base) -> None:
    problem, p = base
    assert "monitor_gap" in codes(edit_action(problem, "a3-monitor", duration_s=900.0), p)


def test_monitor_handover_late(base) -> None:
    problem, p = base
    i = find(p, 0, "monitor")
    s = p.uavs[0].steps[i]
    bad = edit_step(p, 0, i, arrive_s=s.arrive_s + 20.0)
    assert "monitor_gap" in codes(problem, bad)


def test_monitor_k_slots_not_synchronised(base) -> None:
    problem, p = base
    assert "monitor_not_synchronised" in codes(edit_action(problem, "a3-monitor", k=2), p)


def test_monitor_wrong_position(base) -> None:
    problem, p = base
    i = find(p, 0, "monitor")
    x, y, z = p.uavs[0].steps[i].position_m
    assert "wrong_position" in codes(problem, edit_step(p, 0, i, position_m=(x, y, z + 5)))


def test_deliver_with_wrong_tool(base) -> None:
    problem, p = base
    bad = edit_step(p, 0, find(p, 0, "pick"), tool="hammer")
    found = codes(problem, bad)
    assert "deliver_without_tool" in found and "tool_not_at_station" in found


def test_pick_while_holding_a_tool(base) -> None:
    problem, p = base
    assert "pick_with_tool" in codes(edit_uav(problem, 0, tool="wrench"), p)


def test_deliver_missing(base) -> None:
    problem, p = base
    extra = DeliverJob(
        id="a5-deliver", tool="wrench", tool_station="tools", worker_m=(0.0, 10.0, 3.0)
    )
    assert "deliver_count" in codes(replace(problem, actions=(*problem.actions, extra)), p)


def test_pad_capacity(base) -> None:
    problem, p = base
    # uav1 recharges at C2 right when uav2 does: one pad only.
    i2 = find(p, 1, "recharge")
    s2 = p.uavs[1].steps[i2]
    stations = tuple(replace(s, pads=1) for s in problem.stations)
    alone = set_steps(p, 0, [])
    both = set_steps(
        alone,
        0,
        [
            Step(
                kind="wait",
                start_s=0.0,
                arrive_s=6.25,
                end_s=s2.arrive_s,
                position_m=(0.0, 20.0, 0.0),
                energy_after_wh=97.0,
                distance_m=10 * 2**0.5,
            ),
            replace(s2, start_s=s2.arrive_s, energy_after_wh=100.0, distance_m=0.0),
        ],
    )
    assert "pad_capacity" in codes(replace(problem, stations=stations), both)


def test_release_time(base) -> None:
    problem, p = base
    assert "before_release" in codes(edit_action(problem, "a2-inspect", release_s=500.0), p)


def test_time_discontinuity(base) -> None:
    problem, p = base
    i = find(p, 1, "inspect", 2)
    s = p.uavs[1].steps[i]
    assert "time_discontinuity" in codes(problem, edit_step(p, 1, i, start_s=s.start_s + 3))


def test_teleport(base) -> None:
    problem, p = base
    i = find(p, 1, "inspect", 1)
    s = p.uavs[1].steps[i]
    assert "travel_too_fast" in codes(problem, edit_step(p, 1, i, arrive_s=s.start_s + 0.1))


def test_service_too_short(base) -> None:
    problem, p = base
    i = find(p, 1, "inspect", 2)
    s = p.uavs[1].steps[i]
    assert "service_too_short" in codes(problem, edit_step(p, 1, i, end_s=s.arrive_s + 1))


def test_home_not_last(base) -> None:
    problem, p = base
    steps = list(p.uavs[1].steps)
    last = steps[-1]
    steps.append(
        replace(
            last,
            kind="wait",
            start_s=last.end_s,
            arrive_s=last.end_s,
            end_s=last.end_s + 5,
            station=None,
            distance_m=0.0,
        )
    )
    assert "home_not_last" in codes(problem, set_steps(p, 1, steps))


def test_unavailable_uav_has_steps(base) -> None:
    problem, p = base
    assert "uav_unavailable" in codes(edit_uav(problem, 0, available=False), p)


def test_unknown_uav(base) -> None:
    problem, p = base
    bad = replace(p, uavs=(*p.uavs, replace(p.uavs[0], uav_id="ghost")))
    assert "unknown_uav" in codes(problem, bad)


def test_unplaced_but_planned(base) -> None:
    problem, p = base
    bad = replace(p, unplaced=(Unplaced(action_id="a3-monitor", reason="k_exceeds_fleet"),))
    assert "unplaced_but_planned" in codes(problem, bad)


def test_wait_must_not_wander(base) -> None:
    problem, p = base
    i = find(p, 0, "wait")
    x, y, z = p.uavs[0].steps[i].position_m
    assert "wait_moves" in codes(problem, edit_step(p, 0, i, position_m=(x + 3, y, z)))
