"""Scenario files shipped with linecrew, and loading any scenario file.

``load("paper")`` gives the paper's simulated world; ``load("site.yaml")``
reads a file of your own (YAML or JSON, the :class:`proto.scenario.Scenario`
shape). Errors name the offending field.
"""

from __future__ import annotations

import pathlib

import msgspec

from proto.errors import LinecrewError
from proto.fleet import UavSpec
from proto.scenario import Scenario

_HERE = pathlib.Path(__file__).parent


class ScenarioError(LinecrewError):
    """A scenario name or file that cannot be loaded; fix the file, do not retry."""

    code = "invalid_scenario"


def builtin_names() -> list[str]:
    """Names of the scenarios shipped with linecrew."""
    return sorted(path.stem for path in _HERE.glob("*.yaml"))


def load(name_or_path: str, *, site: str | None = None) -> Scenario:
    """A shipped scenario by name, or a YAML / JSON file by path.

    The site id comes from the scenario; a ``site`` (a process's ``--site``
    or ``LINECREW_SITE``) that disagrees with it is an error naming both, so
    that no process of a run listens on another site's keys."""
    path = _HERE / f"{name_or_path}.yaml"
    if not path.exists():
        path = pathlib.Path(name_or_path)
    if not path.is_file():
        raise ScenarioError(
            f"no scenario {name_or_path!r}: not a file, nor one of {', '.join(builtin_names())}"
        )
    scenario = parse(path.read_bytes(), json=path.suffix == ".json", source=str(path))
    if site is not None and site != scenario.site.id:
        raise ScenarioError(
            f"site {site!r} (--site / LINECREW_SITE) disagrees with the scenario's site id "
            f"{scenario.site.id!r} ({path}); drop it or use the scenario's"
        )
    return scenario


def with_fleet_size(scenario: Scenario, uavs: int) -> Scenario:
    """``scenario`` with ``uavs`` UAVs cycling through its types and stations
    (ids ``uav-00``...), for benchmarks and scale tests. Scripted actions stay."""
    types = [t.name for t in scenario.fleet.types]
    stations = [s.id for s in scenario.site.stations]
    specs = [
        UavSpec(
            id=f"uav-{i:02d}", type=types[i % len(types)], home_station=stations[i % len(stations)]
        )
        for i in range(uavs)
    ]
    fleet = msgspec.structs.replace(scenario.fleet, uavs=specs)
    return msgspec.structs.replace(scenario, name=f"{scenario.name}-x{uavs}", fleet=fleet)


def parse(data: bytes, *, json: bool = False, source: str = "<scenario>") -> Scenario:
    """Decode and check a scenario document."""
    try:
        if json:
            scenario = msgspec.json.decode(data, type=Scenario)
        else:
            scenario = msgspec.yaml.decode(data, type=Scenario)
    except msgspec.DecodeError as exc:
        raise ScenarioError(f"{source}: {exc}") from exc
    _check_references(scenario, source)
    return scenario


def _check_references(scenario: Scenario, source: str) -> None:
    site, fleet = scenario.site, scenario.fleet
    type_names = {t.name for t in fleet.types}
    station_ids = {s.id for s in site.stations}
    for i, uav in enumerate(fleet.uavs):
        if uav.type not in type_names:
            raise ScenarioError(f"{source}: $.fleet.uavs[{i}].type: unknown type {uav.type!r}")
        if uav.home_station not in station_ids:
            raise ScenarioError(
                f"{source}: $.fleet.uavs[{i}].home_station: unknown station {uav.home_station!r}"
            )
    if len({u.id for u in fleet.uavs}) != len(fleet.uavs):
        raise ScenarioError(f"{source}: $.fleet.uavs: duplicate UAV ids")
    tower_ids = {t.id for t in site.towers}
    for i, line in enumerate(site.lines):
        unknown = set(line.tower_ids) - tower_ids
        if unknown:
            raise ScenarioError(f"{source}: $.site.lines[{i}]: unknown towers {sorted(unknown)}")
