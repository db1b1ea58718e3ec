"""The CP-SAT reference optimiser (bench only): its plans are valid, it
finds the optimum where the planner's answer can be checked by hand, and it
sees plan shapes outside index-ordered inspection and pick-then-drop."""

from __future__ import annotations

import json

import msgspec
import pytest

from ground_station.planner import (
    Airframe,
    DeliverJob,
    InspectJob,
    MonitorJob,
    Problem,
    RunningTask,
    Station,
    ToolDepot,
    Uav,
    Viewpoint,
    plan,
    score,
    validate,
)
from linecrew.planner_tools.cli import bench_main
from linecrew.planner_tools.generator import generate

pytest.importorskip("ortools")
from linecrew.planner_tools.reference import solve

DRONE = Airframe(
    id="quad",
    capabilities={"inspect": 0.0, "monitor": 0.0},
    cruise_speed_mps=10.0,
    battery_wh=50.0,
    flight_power_w=200.0,
    hover_power_w=200.0,
)


def _problem(*actions, uavs=2) -> Problem:  # type: ignore[no-untyped-def]
    return Problem(
        stations=(Station(id="S0", position_m=(0.0, 0.0, 0.0), pads=1, recharge="swap"),),
        uav_types=(DRONE,),
        uavs=tuple(
            Uav(
                id=f"U{i}",
                type="quad",
                position_m=(0.0, 0.0, 0.0),
                home_station="S0",
                energy_wh=50.0,
            )
            for i in range(uavs)
        ),
        actions=actions,
    )


def test_two_waypoints_on_opposite_sides_go_to_two_uavs() -> None:
    wps = (
        Viewpoint(position_m=(300.0, 0.0, 20.0), service_s=30.0),
        Viewpoint(position_m=(-300.0, 0.0, 20.0), service_s=30.0),
    )
    problem = _problem(InspectJob(id="I", waypoints=wps))
    ref = solve(problem, time_limit_s=30.0)
    assert ref.status == "OPTIMAL" and ref.plan is not None
    assert validate(problem, ref.plan) == []
    used = [up for up in ref.plan.uavs if up.steps]
    assert len(used) == 2  # in parallel: 30.07 s out, 30 s service, 30.07 s back
    assert ref.plan.metrics.makespan_s == pytest.approx(30.1 + 30 + 30.1)
    # flights rounded up to 0.1 s: at most 0.1 s per leg in each term
    assert score(ref.plan)[1] <= score(plan(problem))[1] + 0.4


def test_a_watch_longer_than_a_battery_is_handed_over() -> None:
    # 40 Wh usable at 200 W hover is 720 s: a 1000 s watch needs two UAVs.
    watch = MonitorJob(id="M", worker_m=(100.0, 0.0, 20.0), standoff_m=10.0, duration_s=1000.0)
    problem = _problem(watch)
    ref = solve(problem, time_limit_s=30.0)
    assert ref.plan is not None and validate(problem, ref.plan) == []
    watchers = {up.uav_id for up in ref.plan.uavs for s in up.steps if s.kind == "monitor"}
    assert watchers == {"U0", "U1"}


def test_the_hint_is_used_and_a_bad_problem_is_refused() -> None:
    wps = tuple(Viewpoint(position_m=(100.0 * i, 50.0, 20.0), service_s=10.0) for i in range(4))
    problem = _problem(InspectJob(id="I", waypoints=wps))
    ours = plan(problem, max_rounds=50)
    ref = solve(problem, time_limit_s=10.0, hint=ours)
    assert ref.plan is not None and validate(problem, ref.plan) == []
    running = msgspec.structs.replace(
        problem,
        uavs=(msgspec.structs.replace(problem.uavs[0], running=RunningTask(action_id="I")),),
    )
    refused = solve(running)
    assert refused.status == "UNSUPPORTED" and refused.plan is None


def test_waypoints_are_flown_in_the_best_order_not_the_index_order() -> None:
    # Index order 0, 1, 2 zig-zags (486 m); 0, 2, 1 flies the square (404 m).
    wps = tuple(
        Viewpoint(position_m=p, service_s=5.0)
        for p in ((100.0, 0.0, 20.0), (0.0, 100.0, 20.0), (100.0, 100.0, 20.0))
    )
    problem = _problem(InspectJob(id="I", waypoints=wps), uavs=1)
    ref = solve(problem, time_limit_s=30.0)
    assert ref.status == "OPTIMAL" and ref.plan is not None
    assert validate(problem, ref.plan) == []
    order = [s.index for s in ref.plan.uavs[0].steps if s.kind == "inspect"]
    assert order in ([0, 2, 1], [1, 2, 0])
    assert ref.plan.metrics.distance_m == pytest.approx(100 + 100 + 2 * (100**2 + 20**2) ** 0.5)


def test_a_tool_is_carried_past_other_work() -> None:
    # home (0,0), tools (0,300), worker (300,300), waypoint half-way between:
    # pick, inspect on the way, then drop beats pick-drop as one block.
    courier = Airframe(
        id="courier",
        capabilities={"inspect": 0.0, "deliver": 0.0},
        cruise_speed_mps=10.0,
        battery_wh=50.0,
        flight_power_w=200.0,
        hover_power_w=200.0,
    )
    base = _problem(
        InspectJob(id="I", waypoints=(Viewpoint(position_m=(150.0, 300.0, 5.0), service_s=5.0),)),
        DeliverJob(
            id="D",
            tool="wrench",
            tool_station="T",
            worker_m=(300.0, 300.0, 5.0),
            pick_s=5.0,
            drop_s=5.0,
        ),
        uavs=1,
    )
    problem = msgspec.structs.replace(
        base,
        uav_types=(courier,),
        uavs=(msgspec.structs.replace(base.uavs[0], type="courier"),),
        tool_stations=(ToolDepot(id="T", position_m=(0.0, 300.0, 5.0), tools=("wrench",)),),
    )
    ref = solve(problem, time_limit_s=30.0)
    assert ref.status == "OPTIMAL" and ref.plan is not None
    assert validate(problem, ref.plan) == []
    kinds = [s.kind for s in ref.plan.uavs[0].steps if s.kind != "wait"]
    assert kinds == ["pick", "inspect", "deliver", "home"]


def test_a_tiny_corridor_is_proven_and_the_planner_validated_within_its_gap(capsys) -> None:
    problem = generate(2, 2, 2)
    ref = solve(problem, time_limit_s=30.0, workers=1)
    assert ref.status == "OPTIMAL" and ref.plan is not None
    assert validate(problem, ref.plan) == []
    assert ref.score_bound == pytest.approx(score(ref.plan)[1], rel=1e-3)
    args = ["planner", "--sizes", "2x2", "--seeds", "2", "--improve-ms", "50", "--events", "5"]
    args += ["--repeat", "1", "--reference", "cpsat", "--reference-ms", "1500", "--json"]
    assert bench_main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    (run,) = doc["runs"]
    (row,) = doc["summary"]
    assert run["cpsat"]["cpsat-planner"]["status"] == "OPTIMAL" and run["violations"] == 0
    assert run["optimum"] == pytest.approx(score(ref.plan)[1], rel=1e-3)
    assert set(run["references"]) == {"search", "paper-search", "cpsat-planner", "cpsat-paper"}
    (gap,) = row["gap_to_optimum_pct"]
    assert gap == pytest.approx((run["improved"]["score"] / run["optimum"] - 1) * 100)
    assert row["proven"] == 1 and row["gap_improved_pct"] >= 0.0
