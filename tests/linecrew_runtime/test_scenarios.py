"""Scenario files: the shipped ones load; broken ones say which field."""

from __future__ import annotations

import pytest

from linecrew_runtime.scenarios import ScenarioError, builtin_names, load, parse
from proto import DeliverAction, InspectAction, MonitorAction


def test_paper_scenario_matches_the_paper():
    scenario = load("paper")
    assert [u.id for u in scenario.fleet.uavs] == ["uav-1", "uav-2", "uav-3"]
    assert [t.name for t in scenario.fleet.types if t.gripper] == ["physical"]
    kinds = [type(a.action) for a in scenario.actions]
    assert kinds == [DeliverAction, InspectAction, MonitorAction, InspectAction]
    assert {t.id for t in scenario.site.towers} == {"T1", "T2", "T3"}


@pytest.mark.parametrize("name", builtin_names())
def test_every_shipped_scenario_loads(name):
    assert load(name).name == name


def test_missing_scenario_lists_the_known_ones():
    with pytest.raises(ScenarioError, match="paper"):
        load("no-such-scenario")


def _paper_text() -> str:
    from linecrew_runtime import scenarios

    return (scenarios._HERE / "paper.yaml").read_text()


def test_unknown_uav_type_names_the_field():
    text = _paper_text().replace("type: safety, home_station", "type: blimp, home_station")
    with pytest.raises(ScenarioError, match=r"\$\.fleet\.uavs\[2\]\.type"):
        parse(text.encode())


def test_unknown_home_station_names_the_field():
    text = _paper_text().replace("home_station: C3", "home_station: C9")
    with pytest.raises(ScenarioError, match=r"home_station: unknown station 'C9'"):
        parse(text.encode())


def test_bad_value_names_the_field():
    text = _paper_text().replace("battery_wh: 20.0", "battery_wh: -1", 1)
    with pytest.raises(ScenarioError, match=r"battery_wh"):
        parse(text.encode())
