"""Invalid problems raise one clear error naming the field; impossible work
comes back as explicit unplaced reasons, never a crash."""

from __future__ import annotations

from pathlib import Path

import msgspec
import pytest
import yaml

from ground_station.planner import (
    InspectJob,
    MonitorJob,
    PlanningProblemError,
    Problem,
    Viewpoint,
    plan,
    plan_from_json,
    problem_from_json,
    problem_from_obj,
    validate,
)

FIXTURES = Path(__file__).parent / "fixtures"
replace = msgspec.structs.replace


def raw() -> dict:
    return yaml.safe_load((FIXTURES / "fig6.yaml").read_text())


def test_unknown_home_station_names_the_field() -> None:
    doc = raw()
    doc["uavs"][1]["home_station"] = "nowhere"
    with pytest.raises(PlanningProblemError) as err:
        problem_from_obj(doc)
    assert err.value.field == "$.uavs[1].home_station"
    assert "nowhere" in str(err.value)


def test_unknown_tool_station() -> None:
    doc = raw()
    doc["actions"][0]["tool_station"] = "shed"
    with pytest.raises(PlanningProblemError) as err:
        problem_from_obj(doc)
    assert err.value.field == "$.actions[0].tool_station"


def test_negative_durations() -> None:
    doc = raw()
    doc["actions"][2]["duration_s"] = -5
    with pytest.raises(PlanningProblemError) as err:
        problem_from_obj(doc)
    assert err.value.field == "$.actions[2].duration_s"
    doc = raw()
    doc["actions"][1]["waypoints"][0]["service_s"] = -1
    with pytest.raises(PlanningProblemError) as err:
        problem_from_obj(doc)
    assert err.value.field == "$.actions[1].waypoints[0].service_s"


def test_wrong_type_names_the_field() -> None:
    doc = raw()
    doc["uavs"][0]["energy_wh"] = "full"
    with pytest.raises(PlanningProblemError) as err:
        problem_from_obj(doc)
    assert err.value.field == "$.uavs[0].energy_wh"


def test_duplicate_ids_and_unknown_kinds() -> None:
    doc = raw()
    doc["actions"][1]["id"] = doc["actions"][0]["id"]
    with pytest.raises(PlanningProblemError, match="duplicate"):
        problem_from_obj(doc)
    doc = raw()
    doc["actions"][0]["kind"] = "dance"
    with pytest.raises(PlanningProblemError):
        problem_from_obj(doc)


def test_bad_json_documents() -> None:
    with pytest.raises(PlanningProblemError):
        problem_from_json(b"{not json")
    with pytest.raises(PlanningProblemError):
        plan_from_json(b'{"uavs": 3}')


def test_k_larger_than_fleet_is_unplaced(fig6: Problem) -> None:
    big = MonitorJob(id="big", worker_m=(0.0, 10.0, 3.0), k=3, duration_s=60.0)
    problem = replace(fig6, actions=(*fig6.actions, big))
    result = plan(problem)
    assert validate(problem, result) == []
    reasons = {(x.action_id, x.reason) for x in result.unplaced}
    assert ("big", "k_exceeds_fleet") in reasons


def test_unreachable_waypoint_is_unplaced_and_the_rest_planned(fig6: Problem) -> None:
    far = InspectJob(
        id="far",
        waypoints=(
            Viewpoint(position_m=(5.0, 5.0, 3.0), service_s=5.0),
            Viewpoint(position_m=(5000.0, 0.0, 3.0), service_s=5.0),
        ),
    )
    problem = replace(fig6, actions=(*fig6.actions, far))
    result = plan(problem)
    assert validate(problem, result) == []
    assert [(x.action_id, x.part, x.reason) for x in result.unplaced] == [
        ("far", 1, "unreachable_with_full_battery")
    ]
    planned = [s.index for u in result.uavs for s in u.steps if s.action_id == "far"]
    assert planned == [0]


def test_no_capable_uav(fig6: Problem) -> None:
    types = tuple(replace(t, capabilities={"inspect": 0.0}) for t in fig6.uav_types)
    problem = replace(fig6, uav_types=types)
    result = plan(problem)
    assert validate(problem, result) == []
    reasons = {x.action_id: x.reason for x in result.unplaced}
    assert reasons == {"a1-deliver": "no_capable_uav", "a3-monitor": "no_capable_uav"}


def test_no_uav_available(fig6: Problem) -> None:
    problem = replace(fig6, uavs=tuple(replace(u, available=False) for u in fig6.uavs))
    result = plan(problem)
    assert validate(problem, result) == []
    assert {x.action_id for x in result.unplaced} == {a.id for a in fig6.actions}


def test_uav_that_cannot_reach_a_station_above_reserve_just_lands(fig6: Problem) -> None:
    low = replace(fig6.uavs[0], energy_wh=10.0, airborne=True, position_m=(0.0, 0.0, 20.0))
    problem = replace(fig6, uavs=(low, fig6.uavs[1]))
    result = plan(problem)
    assert validate(problem, result) == []
    assert [s.kind for s in result.uavs[0].steps] == ["home"]
    assert result.uavs[0].steps[0].energy_after_wh >= 0


def test_uav_below_reserve_on_a_pad_recharges_first(fig6: Problem) -> None:
    problem = replace(fig6, uavs=(replace(fig6.uavs[0], energy_wh=10.0), fig6.uavs[1]))
    result = plan(problem)
    assert validate(problem, result) == []
    assert result.uavs[0].steps[0].kind == "recharge"


def test_plan_rejects_non_problem() -> None:
    with pytest.raises(PlanningProblemError):
        plan({"stations": []})  # type: ignore[arg-type]
