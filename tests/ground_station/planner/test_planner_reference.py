"""The CP-SAT reference optimiser (bench only): its plans are valid and it
finds the optimum where the planner's answer can be checked by hand."""

from __future__ import annotations

import json

import msgspec
import pytest

from ground_station.planner import (
    InspectAction,
    MonitorAction,
    Problem,
    RunningTask,
    Station,
    Uav,
    UavType,
    Waypoint,
    plan,
    score,
    validate,
)
from ground_station.planner.cli import bench_main

pytest.importorskip("ortools")
from ground_station.planner.reference import solve

DRONE = UavType(
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
        Waypoint(position_m=(300.0, 0.0, 20.0), service_s=30.0),
        Waypoint(position_m=(-300.0, 0.0, 20.0), service_s=30.0),
    )
    problem = _problem(InspectAction(id="I", waypoints=wps))
    ref = solve(problem, time_limit_s=30.0)
    assert ref.status == "OPTIMAL" and ref.plan is not None
    assert validate(problem, ref.plan) == []
    used = [up for up in ref.plan.uavs if up.steps]
    assert len(used) == 2  # in parallel: 31 s out, 30 s service, 31 s back
    assert ref.plan.metrics.makespan_s == pytest.approx(31 + 30 + 31)
    # flights rounded up to whole seconds: at most 1 s per leg in each term
    assert score(ref.plan)[1] <= score(plan(problem))[1] + 4.0


def test_a_watch_longer_than_a_battery_is_handed_over() -> None:
    # 40 Wh usable at 200 W hover is 720 s: a 1000 s watch needs two UAVs.
    watch = MonitorAction(id="M", worker_m=(100.0, 0.0, 20.0), standoff_m=10.0, duration_s=1000.0)
    problem = _problem(watch)
    ref = solve(problem, time_limit_s=30.0)
    assert ref.plan is not None and validate(problem, ref.plan) == []
    watchers = {up.uav_id for up in ref.plan.uavs for s in up.steps if s.kind == "monitor"}
    assert watchers == {"U0", "U1"}


def test_the_hint_is_used_and_a_bad_problem_is_refused() -> None:
    wps = tuple(Waypoint(position_m=(100.0 * i, 50.0, 20.0), service_s=10.0) for i in range(4))
    problem = _problem(InspectAction(id="I", waypoints=wps))
    ours = plan(problem, max_rounds=50)
    ref = solve(problem, time_limit_s=10.0, hint=ours)
    assert ref.plan is not None and validate(problem, ref.plan) == []
    running = msgspec.structs.replace(
        problem,
        uavs=(msgspec.structs.replace(problem.uavs[0], running=RunningTask(action_id="I")),),
    )
    refused = solve(running)
    assert refused.status == "UNSUPPORTED" and refused.plan is None


def test_bench_with_cpsat_reference(capsys) -> None:
    args = ["planner", "--sizes", "2x2", "--seeds", "1", "--improve-ms", "50", "--events", "5"]
    args += ["--repeat", "1", "--reference", "cpsat", "--reference-ms", "3000", "--json"]
    assert bench_main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    (run,) = doc["runs"]
    assert run["cpsat_status"] in ("OPTIMAL", "FEASIBLE") and run["violations"] == 0
    assert run["reference"]["score"] <= run["improved"]["score"]
