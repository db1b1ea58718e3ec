"""Property tests: every plan validates, every action is placed or has a
reason, and planning is deterministic."""

from __future__ import annotations

import msgspec
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ground_station.planner import (
    Airframe,
    DeliverJob,
    InspectJob,
    MonitorJob,
    Options,
    Problem,
    RunningTask,
    Solution,
    Station,
    ToolDepot,
    Uav,
    Viewpoint,
    plan,
    validate,
)
from linecrew.planner_tools.generator import generate

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
coord = st.floats(min_value=-1500, max_value=1500, allow_nan=False).map(lambda v: round(v, 1))
point = st.tuples(coord, coord, st.floats(min_value=0, max_value=40).map(lambda v: round(v, 1)))


@st.composite
def problems(draw: st.DrawFn) -> Problem:
    stations = [
        Station(
            id=f"S{i}",
            position_m=draw(point),
            pads=draw(st.integers(0, 2)),
            recharge=draw(st.sampled_from(["swap", "charge"])),
            swap_s=draw(st.sampled_from([30.0, 120.0])),
            full_charge_s=draw(st.sampled_from([300.0, 1200.0])),
        )
        for i in range(draw(st.integers(1, 3)))
    ]
    tools = [ToolDepot(id="T0", position_m=draw(point), tools=("wrench",))]
    caps = st.dictionaries(
        st.sampled_from(["inspect", "monitor", "deliver"]),
        st.sampled_from([0.0, 0.5, 1.0]),
        min_size=1,
    )
    types = [
        Airframe(
            id=f"type{i}",
            capabilities=draw(caps),
            cruise_speed_mps=draw(st.sampled_from([5.0, 12.0])),
            battery_wh=draw(st.sampled_from([20.0, 60.0])),
            flight_power_w=draw(st.sampled_from([150.0, 300.0])),
            hover_power_w=draw(st.sampled_from([100.0, 280.0])),
        )
        for i in range(2)
    ]
    uavs = []
    for i in range(draw(st.integers(1, 4))):
        t = draw(st.sampled_from(types))
        home = draw(st.sampled_from(stations))
        uavs.append(
            Uav(
                id=f"U{i}",
                type=t.id,
                position_m=home.position_m,
                home_station=home.id,
                energy_wh=t.battery_wh * draw(st.sampled_from([0.5, 0.9, 1.0])),
                available=draw(st.booleans()) or i == 0,
            )
        )
    actions = []
    for i in range(draw(st.integers(1, 6))):
        kind = draw(st.sampled_from(["inspect", "monitor", "deliver"]))
        common = {
            "id": f"A{i}",
            "weight": float(draw(st.integers(1, 3))),
            "release_s": draw(st.sampled_from([0.0, 0.0, 300.0])),
        }
        if kind == "inspect":
            wps = [
                Viewpoint(position_m=draw(point), service_s=draw(st.sampled_from([0.0, 30.0])))
                for _ in range(draw(st.integers(1, 5)))
            ]
            actions.append(InspectJob(waypoints=tuple(wps), **common))
        elif kind == "monitor":
            actions.append(
                MonitorJob(
                    worker_m=draw(point),
                    k=draw(st.integers(1, 3)),
                    standoff_m=8.0,
                    duration_s=draw(st.sampled_from([60.0, 400.0, 1500.0])),
                    **common,
                )
            )
        else:
            actions.append(
                DeliverJob(tool="wrench", tool_station="T0", worker_m=draw(point), **common)
            )
    return Problem(
        stations=tuple(stations),
        tool_stations=tuple(tools),
        uav_types=tuple(types),
        uavs=tuple(uavs),
        actions=tuple(actions),
        reserve_fraction=draw(st.sampled_from([0.1, 0.2, 0.3])),
    )


def accounted(problem: Problem, p: Solution) -> None:
    planned = {s.action_id for u in p.uavs for s in u.steps if s.action_id}
    unplaced = {x.action_id for x in p.unplaced}
    for a in problem.actions:
        assert a.id in planned or a.id in unplaced, a.id
    for x in p.unplaced:
        assert x.reason


@SETTINGS
@given(problems(), st.sampled_from(["complete", "paper"]))
def test_random_problems_validate_and_account_for_every_action(problem, mode) -> None:
    p = plan(problem, Options(mode=mode))
    assert validate(problem, p) == []
    accounted(problem, p)


@settings(max_examples=15, deadline=None)
@given(problems())
def test_planning_is_deterministic(problem) -> None:
    assert plan(problem) == plan(problem)


@settings(max_examples=12, deadline=None)
@given(
    st.integers(1, 8),
    st.integers(1, 12),
    st.integers(0, 10_000),
    st.sampled_from(["complete", "paper"]),
)
def test_corridor_instances_validate(n_uavs, n_actions, seed, mode) -> None:
    problem = generate(n_uavs, n_actions, seed)
    p = plan(problem, Options(mode=mode))
    assert validate(problem, p) == []
    accounted(problem, p)


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from([5.0, 60.0, 200.0]))
def test_running_tasks_are_kept_or_redone_and_plans_validate(seed, remaining_s) -> None:
    problem = generate(6, 12, seed)
    inspections = [a for a in problem.actions if isinstance(a, InspectJob)]
    if not inspections:
        return
    target = inspections[0]
    types = {t.id: t for t in problem.uav_types}
    uavs = list(problem.uavs)
    for i, u in enumerate(uavs):
        if "inspect" in types[u.type].capabilities:
            uavs[i] = msgspec.structs.replace(
                u,
                position_m=target.waypoints[0].position_m,
                airborne=True,
                running=RunningTask(action_id=target.id, index=0, remaining_s=remaining_s),
            )
            break
    actions = tuple(msgspec.structs.replace(a, release_s=0.0) for a in problem.actions)
    problem = msgspec.structs.replace(problem, uavs=tuple(uavs), actions=actions)
    for p in (plan(problem), plan(problem, max_rounds=10)):
        assert validate(problem, p) == []
        accounted(problem, p)
