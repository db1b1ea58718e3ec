"""Shared pads, mid-task recharges and time-preserving removal."""

from __future__ import annotations

from itertools import pairwise

import msgspec

from ground_station.planner import (
    DeliverJob,
    InspectJob,
    Problem,
    RunningTask,
    Station,
    Viewpoint,
    plan,
    validate,
)
from ground_station.planner.export import export
from ground_station.planner.heuristic import build
from ground_station.planner.removal import remove_in_place
from ground_station.planner.replan import ActionAdded, Session
from linecrew.planner_tools.bench import replan_times
from linecrew.planner_tools.generator import generate

replace = msgspec.structs.replace


def test_one_pad_is_shared_in_turn(fig6: Problem) -> None:
    pad = Station(id="P", position_m=(0.0, 0.0, 0.0), pads=1, recharge="charge", full_charge_s=300)
    low = [replace(u, position_m=(0.0, 0.0, 0.0), energy_wh=15.0) for u in fig6.uavs]
    landing_only = tuple(replace(s, pads=0) for s in fig6.stations)
    far = InspectJob(
        id="far",
        waypoints=tuple(
            Viewpoint(position_m=(x, 30.0, 5.0), service_s=20.0) for x in (-20.0, 0.0, 20.0, 40.0)
        ),
    )
    problem = replace(fig6, stations=(pad, *landing_only), uavs=tuple(low), actions=(far,))
    result = plan(problem)
    assert validate(problem, result) == []
    on_pad = sorted(
        (s.arrive_s, s.end_s)
        for u in result.uavs
        for s in u.steps
        if s.kind == "recharge" and s.station == "P"
    )
    assert len(on_pad) >= 2
    for (_, end), (start, _) in pairwise(on_pad):
        assert start >= end - 1e-6


def test_long_inspection_is_split_by_a_recharge(fig6: Problem) -> None:
    line = InspectJob(
        id="line",
        waypoints=tuple(
            Viewpoint(position_m=(x, 12.0, 3.0), service_s=40.0) for x in range(-8, 9, 2)
        ),
    )
    one = (replace(fig6.uavs[1], energy_wh=100.0),)
    problem = replace(fig6, uavs=one, actions=(line,))
    result = plan(problem)
    assert validate(problem, result) == []
    kinds = [s.kind for s in result.uavs[0].steps]
    first, last = kinds.index("inspect"), len(kinds) - 1 - kinds[::-1].index("inspect")
    assert "recharge" in kinds[first:last]  # the inspection resumes after recharging
    assert sorted(s.index for s in result.uavs[0].steps if s.kind == "inspect") == list(range(9))


def test_time_preserving_removal_keeps_other_steps_in_time() -> None:
    problem = generate(8, 24, 11)
    ctx = build(problem)
    uid, route = max(ctx.routes.items(), key=lambda kv: len(kv[1].tasks))
    victim = route.tasks[0].action_id
    kept_before = [s for s in route.steps if s.action_id not in (None, victim)]
    assert remove_in_place(ctx, uid, lambda t: t.action_id == victim) is not None
    kept_after = [s for s in ctx.routes[uid].steps if s.action_id is not None]
    times_after = [(s.kind, s.arrive_s, s.end_s) for s in kept_after]
    assert times_after == [(s.kind, s.arrive_s, s.end_s) for s in kept_before]
    # Remove the victim everywhere and check the whole plan still validates.
    for other in ctx.placed_uavs(victim):
        assert remove_in_place(ctx, other, lambda t: t.action_id == victim) is not None
    ctx.unplaced.pop(victim, None)
    smaller = replace(problem, actions=tuple(a for a in problem.actions if a.id != victim))
    ctx.problem = smaller
    assert validate(smaller, export(ctx)) == []


def _running(fig6: Problem, remaining_s: float) -> Problem:
    deliver = replace(fig6.actions[0], weight=5.0)
    inspect = next(a for a in fig6.actions if a.id == "a4-inspect")
    uav1 = replace(
        fig6.uavs[0],
        position_m=inspect.waypoints[0].position_m,
        airborne=True,
        running=RunningTask(action_id="a4-inspect", index=0, remaining_s=remaining_s),
    )
    return replace(fig6, uavs=(uav1, fig6.uavs[1]), actions=(inspect, deliver))


def test_running_task_is_interrupted_only_when_j3_says_it_pays(fig6: Problem) -> None:
    long_left = _running(fig6, 120.0)
    result = plan(long_left)
    assert validate(long_left, result) == []
    kinds = [(s.kind, s.action_id) for s in result.uavs[0].steps]
    first_inspect = kinds.index(("inspect", "a4-inspect"))
    assert kinds.index(("deliver", "a1-deliver")) < first_inspect  # interrupted
    resumed = result.uavs[0].steps[first_inspect]
    assert resumed.index == 0 and resumed.end_s - resumed.arrive_s >= 5.0  # redone in full

    short_left = _running(fig6, 5.0)
    result = plan(short_left)
    assert validate(short_left, result) == []
    first = result.uavs[0].steps[0]
    assert (first.kind, first.action_id, first.index) == ("inspect", "a4-inspect", 0)


def _holds_at(result, point, kind):
    return sorted(
        (s.arrive_s, s.end_s, u.uav_id)
        for u in result.uavs
        for s in u.steps
        if s.kind == kind and s.position_m == point
    )


def test_two_inspections_of_one_point_take_turns(fig6: Problem) -> None:
    point = (3.0, 12.0, 4.0)
    both = tuple(
        InspectJob(id=f"look-{n}", waypoints=(Viewpoint(position_m=point, service_s=60.0),))
        for n in (1, 2)
    )
    problem = replace(fig6, actions=both)
    result = plan(problem, max_rounds=50)
    assert validate(problem, result) == []
    first, second = _holds_at(result, point, "inspect")
    assert second[0] >= first[1] - 1e-6  # one after the other, never both at the point


def test_picks_at_one_tool_station_take_turns(fig6: Problem) -> None:
    physical = replace(fig6.uavs[0], id="uav3", position_m=(0.0, 20.0, 0.0), home_station="C2")
    deliveries = tuple(
        DeliverJob(id=f"bring-{n}", tool="wrench", tool_station="tools", worker_m=w, pick_s=60.0)
        for n, w in ((1, (0.0, 10.0, 3.0)), (2, (8.0, 2.0, 3.0)))
    )
    problem = replace(fig6, uavs=(*fig6.uavs, physical), actions=deliveries)
    result = plan(problem, max_rounds=50)
    assert validate(problem, result) == []
    station = fig6.tool_stations[0].position_m
    first, second = _holds_at(result, station, "pick")
    assert second[0] >= first[1] - 1e-6


def test_the_validator_reports_two_uavs_hovering_at_one_point_at_once(fig6: Problem) -> None:
    result = plan(fig6)
    assert validate(fig6, result) == []
    one, other = (next(s for s in u.steps if s.kind == "inspect") for u in result.uavs[:2])
    # the second UAV's inspection moved onto the first's point and time
    moved = replace(other, position_m=one.position_m, arrive_s=one.arrive_s, end_s=one.end_s)
    steps = tuple(moved if s is other else s for s in result.uavs[1].steps)
    uavs = (result.uavs[0], replace(result.uavs[1], steps=steps), *result.uavs[2:])
    found = [v for v in validate(fig6, replace(result, uavs=uavs)) if v.code == "separation"]
    assert found and found[0].uav_id in {result.uavs[0].uav_id, result.uavs[1].uav_id}


def test_a_point_added_live_between_two_held_points_waits_for_both(fig6: Problem) -> None:
    """A new point nearer than the separation to two points that were apart
    joins them into one hold: bookings made at either still count."""
    second = replace(fig6.uavs[1], id="uav3")  # two inspectors: a and b at once
    look = [
        InspectJob(id=f"look-{n}", waypoints=(Viewpoint(position_m=p, service_s=s),))
        for n, p, s in (("a", (3.0, 12.0, 4.0), 30.0), ("b", (4.6, 12.0, 4.0), 90.0))
    ]
    session = Session(replace(fig6, uavs=(*fig6.uavs, second), actions=tuple(look)))
    between = (3.8, 12.0, 4.0)
    added = InspectJob(id="look-c", waypoints=(Viewpoint(position_m=between, service_s=30.0),))
    result = session.apply(ActionAdded(action=added))
    assert validate(session.problem, result) == []
    held = {
        s.action_id: (s.arrive_s, s.end_s)
        for u in result.uavs
        for s in u.steps
        if s.kind == "inspect"
    }
    assert held["look-a"][1] > held["look-b"][0]  # a and b were held at once
    assert held["look-c"][0] >= max(held["look-a"][1], held["look-b"][1]) - 1e-6


def test_waits_beside_a_monitoring_slot_take_turns_through_a_replan_stream() -> None:
    """Two UAVs that leave one slot in turn never wait beside it at once
    (seed 2's stream at 50x500 did after its fifth event)."""
    problem = generate(50, 500, 2)
    _, violations = replan_times(problem, 500, events=5, seed=2)
    assert violations == 0
