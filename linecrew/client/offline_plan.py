"""``linecrew plan FILE``: plan offline, from a planning problem or a scenario.

A *planning problem* is the planner's own format (stations, ``uav_types``,
``uavs`` with positions and energy, ``actions`` with a ``kind``; example:
``ground_station/planner/examples/paper.yaml``). A *scenario* is what
``linecrew up`` / ``demo`` run (``site``, ``fleet``, scripted ``actions``;
example: ``linecrew_runtime/scenarios/paper.yaml``): it is planned as the ground
station would at the start of the mission, every UAV on its home station
with a full battery, each scripted action released at its ``at_s``.
Everything after FILE goes to the planner (``-o``, ``--improve-ms``,
``--mode``; ``--validate PROBLEM PLAN`` checks a plan against a problem).
"""

from __future__ import annotations

import pathlib
import sys
import tempfile
from typing import Any

import msgspec
import yaml

import ground_station.planner as planner_pkg
import linecrew_runtime.scenarios as scenarios_pkg
from ground_station.planner.errors import PlanningProblemError
from ground_station.planner.load import problem_from_obj
from ground_station.planning import UavNow, build_problem, home_station
from linecrew.planner_tools.cli import plan_main as planner_main
from linecrew_runtime.scenarios import ScenarioError, load
from proto.mission import ActionRecord, ActionState
from proto.scenario import Scenario

PROBLEM_EXAMPLE = pathlib.Path(planner_pkg.__file__).parent / "examples" / "paper.yaml"
SCENARIO_EXAMPLE = pathlib.Path(scenarios_pkg.__file__).parent / "paper.yaml"
FORMATS = (
    f"a planning problem (stations, uav_types, uavs, actions; example {PROBLEM_EXAMPLE}) "
    f"or a scenario (site, fleet, actions; example {SCENARIO_EXAMPLE})"
)


def main(argv: list[str]) -> int:
    """Plan FILE (problem or scenario) with the offline planner; exit 2 on bad input."""
    if "--validate" in argv:
        return planner_main(argv)
    path, rest = argv[0], argv[1:]
    try:
        kind = sniff(path)
        if kind == "scenario":
            problem_file = _problem_file(load(path))
            print(f"{path}: a scenario, planned from its start", file=sys.stderr)
            try:
                return planner_main([str(problem_file), *rest])
            finally:
                problem_file.unlink(missing_ok=True)
        problem_from_obj(_read(path))  # its errors, with the format named
    except ScenarioError as exc:
        print(f"linecrew plan: {exc}", file=sys.stderr)
        return 2
    except PlanningProblemError as exc:
        message = f"{path}: planning problem: {exc}; format: {FORMATS}"
        print(f"linecrew plan: {message}", file=sys.stderr)
        return 2
    except ValueError as exc:
        print(f"linecrew plan: {exc}", file=sys.stderr)
        return 2
    return planner_main(argv)


def _read(path: str) -> Any:
    try:
        return yaml.safe_load(pathlib.Path(path).read_bytes())
    except OSError as exc:
        raise ValueError(f"{path}: {exc.strerror or exc}") from None
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0]
        raise ValueError(f"{path}: not YAML/JSON ({first}); plan takes {FORMATS}") from None


def sniff(path: str) -> str:
    """``"problem"`` or ``"scenario"``; ``ValueError`` naming both formats otherwise."""
    data = _read(path)
    if isinstance(data, dict):
        if {"site", "fleet"} <= data.keys():
            return "scenario"
        if {"stations", "uav_types", "uavs"} & data.keys():
            return "problem"
    raise ValueError(f"{path} is neither {FORMATS}")


def problem_of(scenario: Scenario) -> Any:
    """The planner's problem at the start of ``scenario``'s mission."""
    site, fleet = scenario.site, scenario.fleet
    battery = {t.name: t.battery_wh for t in fleet.types}
    uavs = [
        UavNow(
            uav_id=u.id,
            position=home_station(site, u).position,
            energy_wh=battery[u.type],
            available=True,
        )
        for u in fleet.uavs
    ]
    records = [
        ActionRecord(
            action_id=scripted.id,
            action=msgspec.structs.replace(scripted.action, release_s=scripted.at_s),
            state=ActionState.ACCEPTED,
        )
        for scripted in sorted(scenario.actions, key=lambda a: a.at_s)
    ]
    return build_problem(site, fleet, uavs, records, 0.0)


def _problem_file(scenario: Scenario) -> pathlib.Path:
    fd, name = tempfile.mkstemp(prefix=f"linecrew-{scenario.name}-", suffix=".json")
    with open(fd, "wb") as handle:
        handle.write(msgspec.json.encode(problem_of(scenario)))
    return pathlib.Path(name)
