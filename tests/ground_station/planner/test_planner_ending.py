"""The end of the mission (``Problem.end``): home however many recharges
away, or any station with a pad free for good; the validator checks both."""

from __future__ import annotations

import msgspec
import pytest

from ground_station.planner import (
    Airframe,
    InspectJob,
    PlanningProblemError,
    Problem,
    Solution,
    Station,
    Uav,
    UavPlan,
    Viewpoint,
    plan,
    problem_from_obj,
    validate,
)
from linecrew.planner_tools.generator import generate

replace = msgspec.structs.replace
# 0.01 Wh/m, 40 Wh above the reserve: 4 km on a full battery.
TYPE = Airframe(
    id="t",
    capabilities={"inspect": 0.0},
    cruise_speed_mps=10.0,
    battery_wh=50.0,
    flight_power_w=360.0,
    hover_power_w=300.0,
)


def corridor(end: str = "home", work_x: float = 12500.0, pads: int = 1) -> Problem:
    """Stations S0..S4 every 3 km; an inspection at ``work_x``: from 12.5 km
    on, home is four recharges away from it."""
    stations = tuple(
        Station(id=f"S{i}", position_m=(3000.0 * i, 0.0, 0.0), pads=pads, full_charge_s=600.0)
        for i in range(5)
    )
    uav = Uav(id="U0", type="t", position_m=(0.0, 0.0, 0.0), home_station="S0", energy_wh=50.0)
    point = Viewpoint(position_m=(work_x, 0.0, 20.0), service_s=30.0)
    work = InspectJob(id="A", waypoints=(point,))
    return Problem(stations=stations, uav_types=(TYPE,), uavs=(uav,), actions=(work,), end=end)  # type: ignore[arg-type]


def after_work(p: Solution, uav: int = 0) -> list:
    """The steps after the UAV's last piece of work."""
    steps = p.uavs[uav].steps
    last = max(i for i, s in enumerate(steps) if s.action_id is not None)
    return list(steps[last + 1 :])


def test_home_four_recharges_away_is_reached() -> None:
    problem = corridor()
    p = plan(problem)
    assert validate(problem, p) == []
    assert p.uavs[0].steps[-1].station == "S0"
    back = [s for s in after_work(p) if s.kind == "recharge"]
    assert [s.station for s in back] == ["S4", "S3", "S2", "S1"]
    # Each 3 km hop needs 30 Wh over the 10 Wh reserve: charged to 40, not 50.
    assert all(39.9 < s.energy_after_wh < 40.1 for s in back)


def test_a_plan_ending_away_from_home_is_flagged() -> None:
    problem = corridor()
    p = plan(problem)
    steps = list(p.uavs[0].steps)
    cut = max(i for i, s in enumerate(steps) if s.kind == "recharge")
    away = Solution(uavs=(UavPlan(uav_id="U0", steps=tuple(steps[: cut + 1])),))
    assert {v.code for v in validate(problem, away)} >= {"not_home"}
    assert validate(replace(problem, end="any_station"), away) == []


def test_any_station_ends_at_the_nearest_free_station() -> None:
    home, anywhere = corridor(pads=2), corridor("any_station", pads=2)
    p_home, p_any = plan(home), plan(anywhere)
    assert validate(anywhere, p_any) == []
    assert p_any.uavs[0].steps[-1].station == "S4"
    assert [s.kind for s in after_work(p_any)] == ["home"]
    assert p_any.metrics.makespan_s < p_home.metrics.makespan_s


def parked(end: str, pads: int = 1) -> Problem:
    """Two UAVs landed on S4 at the start, with nothing to do."""
    problem = corridor(end, pads=pads)
    u0 = replace(problem.uavs[0], position_m=problem.stations[4].position_m)
    return replace(problem, uavs=(u0, replace(u0, id="U1")), actions=())


def test_two_uavs_parked_on_one_pad_are_flagged() -> None:
    idle = Solution(uavs=(UavPlan(uav_id="U0"), UavPlan(uav_id="U1")))
    assert {v.code for v in validate(parked("any_station"), idle)} == {"pad_capacity"}
    assert [v.code for v in validate(parked("home"), idle)] == ["not_home", "not_home"]
    hovering = parked("any_station")
    hovering = replace(hovering, uavs=(replace(hovering.uavs[0], airborne=True),))
    assert [v.code for v in validate(hovering, Solution(uavs=idle.uavs[:1]))] == ["end_station"]


def test_any_station_parks_but_never_on_a_stations_last_pad() -> None:
    problem = parked("any_station", pads=2)
    p = plan(problem)
    assert validate(problem, p) == []
    assert p.uavs[0].steps == ()
    assert p.uavs[1].steps[-1].station == "S3"
    one_pad = parked("any_station")  # the last pad stays free for the others' ways home
    assert {u.steps[-1].station for u in plan(one_pad).uavs} == {"S0"}


def test_a_parked_uav_holds_its_pad_against_later_recharges() -> None:
    # U1 must recharge on S4 (one pad) to reach work 1.5 km past it.
    far = corridor("any_station", work_x=13500.0)
    watcher = replace(TYPE, id="w", capabilities={"monitor": 0.0})
    u0 = replace(parked("any_station").uavs[0], type="w")
    problem = replace(far, uav_types=(TYPE, watcher), uavs=(u0, replace(far.uavs[0], id="U1")))
    p = plan(problem)
    assert validate(problem, p) == []
    assert any(s.kind == "recharge" and s.station == "S4" for s in p.uavs[1].steps)
    stays = replace(p, uavs=(UavPlan(uav_id="U0"), p.uavs[1]))
    assert {v.code for v in validate(problem, stays)} == {"pad_capacity"}


@pytest.mark.parametrize("end", ["home", "any_station"])
def test_corridor_bench_instances_end_where_the_policy_says(end: str) -> None:
    problem = replace(generate(10, 40, 3), end=end)
    p = plan(problem)
    assert validate(problem, p) == []
    homes = {u.id: u.home_station for u in problem.uavs}
    ends = {u.uav_id: u.steps[-1].station for u in p.uavs if u.steps}
    if end == "home":
        assert all(ends[u] == homes[u] for u in ends)


def test_the_policy_is_read_and_checked_from_a_document() -> None:
    doc = msgspec.to_builtins(corridor())
    assert problem_from_obj(doc).end == "home"
    assert problem_from_obj({**doc, "end": "any_station"}).end == "any_station"
    with pytest.raises(PlanningProblemError) as err:
        problem_from_obj({**doc, "end": "nearest"})
    assert err.value.field == "$.end"


def test_the_scenario_fleet_threads_the_policy_home_by_default() -> None:
    from ground_station.planning import build_problem
    from linecrew_runtime.scenarios import load
    from proto.fleet import MissionEnd

    scenario = load("paper")
    fleet = scenario.fleet
    assert build_problem(scenario.site, fleet, [], [], 0.0).end == "home"
    anywhere = replace(fleet, end=MissionEnd.ANY_STATION)
    assert build_problem(scenario.site, anywhere, [], [], 0.0).end == "any_station"
