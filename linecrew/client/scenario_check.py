"""``linecrew scenario check FILE``: is this scenario runnable? Without
starting anything.

Checks, in order: the YAML (or JSON) syntax; the document against the
scenario types and its references (:func:`linecrew_runtime.scenarios.parse`, as
every process of a run loads it); fields no type knows (a misspelt field is
otherwise ignored and its default used); each scripted action as the
ground station would check it on submission (site, fleet, safety, tool
stock). Each problem is one line ``FILE:LINE: FIELD: message``; a valid
file gives one summary line and exit 0, an invalid one exit 1.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import re
import sys
from typing import Any

import msgspec
import yaml

from ground_station.inventory import reserve
from ground_station.validation import validate
from linecrew_runtime.scenarios import ScenarioError, parse
from proto.errors import RequestError
from proto.mission import ActionRecord, ActionState, DeliverAction
from proto.scenario import Scenario

PATH = re.compile(r"\$(?:\.[A-Za-z0-9_-]+|\[\d+\])*")


@dataclasses.dataclass(frozen=True)
class Problem:
    """One thing wrong with the file."""

    field: str  # JSON path, ``$`` for the whole document
    message: str
    line: int | None = None
    column: int | None = None

    def render(self, source: str) -> str:
        where = source + "".join(f":{n}" for n in (self.line, self.column) if n)
        return f"{where}: {self.field}: {self.message}"


def check(path: pathlib.Path) -> tuple[Scenario | None, list[Problem]]:
    """The scenario (if it decodes) and every problem found."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        return None, [Problem("$", f"cannot read: {exc.strerror or exc}")]
    try:
        root = _compose(data)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark else None
        column = mark.column + 1 if mark else None
        return None, [Problem("$", f"YAML syntax: {exc.problem or exc}", line, column)]
    except yaml.YAMLError as exc:
        return None, [Problem("$", f"YAML syntax: {exc}")]
    try:
        scenario = parse(data, json=path.suffix == ".json", source=str(path))
    except ScenarioError as exc:
        text = str(exc).removeprefix(f"{path}: ")
        field = (PATH.findall(text) or ["$"])[-1]
        message = text.replace(f" - at `{field}`", "").replace(f"{field}: ", "", 1)
        return None, [Problem(field, message, _line(root, field))]
    problems = [
        Problem(field, "unknown field (ignored by linecrew: misspelt?)", _line(root, field))
        for field in unknown_fields(yaml.safe_load(data), msgspec.inspect.type_info(Scenario))
    ]
    problems += [
        dataclasses.replace(p, line=_line(root, p.field)) for p in _check_actions(scenario)
    ]
    return scenario, problems


def _check_actions(scenario: Scenario) -> list[Problem]:
    """Each scripted action as the ground station checks a submission."""
    problems: list[Problem] = []
    accepted: list[ActionRecord] = []
    for i, scripted in enumerate(scenario.actions):
        prefix = f"$.actions[{i}]"
        try:
            validate(scripted.action, scenario.site, scenario.fleet, field=f"{prefix}.action")
            if isinstance(scripted.action, DeliverAction):
                reserve(scenario.site, accepted, scripted.action)
        except RequestError as exc:
            field = exc.field or f"{prefix}.action"
            if not field.startswith("$"):
                field = f"{prefix}.{field}"
            problems.append(Problem(field, f"{scripted.id}: {exc}"))
            continue
        accepted.append(
            ActionRecord(action_id=scripted.id, action=scripted.action, state=ActionState.ACCEPTED)
        )
    return problems


def _compose(data: bytes) -> yaml.Node | None:
    return yaml.compose(data.decode("utf-8", errors="replace"), Loader=yaml.SafeLoader)


def _line(root: yaml.Node | None, field: str) -> int | None:
    """The line of the deepest node of ``field`` that exists in the document."""
    node, line = root, (root.start_mark.line + 1 if root is not None else None)
    for token in re.findall(r"\.([A-Za-z0-9_-]+)|\[(\d+)\]", field):
        key, index = token
        child = None
        if key and isinstance(node, yaml.MappingNode):
            child = next((v for k, v in node.value if getattr(k, "value", None) == key), None)
            if child is not None:
                line = next(k for k, v in node.value if v is child).start_mark.line + 1
        elif index and isinstance(node, yaml.SequenceNode) and int(index) < len(node.value):
            child = node.value[int(index)]
            line = child.start_mark.line + 1
        if child is None:
            break
        node = child
    return line


def unknown_fields(obj: Any, info: Any, path: str = "$") -> list[str]:
    """Paths of mapping keys that no field of the expected type has."""
    ins = msgspec.inspect
    if isinstance(info, ins.StructType) and isinstance(obj, dict):
        fields = {f.encode_name: f for f in info.fields}
        found = []
        for key, value in obj.items():
            if key == info.tag_field:
                continue
            if key not in fields:
                found.append(f"{path}.{key}")
            else:
                found += unknown_fields(value, fields[key].type, f"{path}.{key}")
        return found
    if isinstance(info, ins.ListType | ins.VarTupleType | ins.SetType) and isinstance(obj, list):
        item = info.item_type
        return [x for i, v in enumerate(obj) for x in unknown_fields(v, item, f"{path}[{i}]")]
    if isinstance(info, ins.DictType) and isinstance(obj, dict):
        value = info.value_type
        return [x for k, v in obj.items() for x in unknown_fields(v, value, f"{path}.{k}")]
    if isinstance(info, ins.UnionType):
        chosen = _member(obj, info.types)
        return unknown_fields(obj, chosen, path) if chosen is not None else []
    return []


def _member(obj: Any, types: tuple[Any, ...]) -> Any:
    ins = msgspec.inspect
    if isinstance(obj, dict):
        structs = [t for t in types if isinstance(t, ins.StructType)]
        tagged = [t for t in structs if t.tag_field and obj.get(t.tag_field) == t.tag]
        if tagged:
            return tagged[0]
        return structs[0] if len(structs) == 1 else None
    if isinstance(obj, list):
        return next((t for t in types if isinstance(t, ins.ListType | ins.VarTupleType)), None)
    return None


def summary(scenario: Scenario) -> dict[str, Any]:
    """What the scenario holds, counted."""
    site, fleet = scenario.site, scenario.fleet
    return {
        "scenario": scenario.name,
        "site": site.id,
        "towers": len(site.towers),
        "lines": len(site.lines),
        "stations": len(site.stations),
        "tool_stations": len(site.tool_stations),
        "workers": len(site.workers),
        "uavs": len(fleet.uavs),
        "uav_types": len(fleet.types),
        "actions": len(scenario.actions),
    }


def _count(n: int, what: str) -> str:
    return f"{n} {what}" if n == 1 else f"{n} {what}s"


def _summary_line(source: str, c: dict[str, Any]) -> str:
    site = ", ".join(
        _count(c[key], what)
        for key, what in (
            ("towers", "tower"),
            ("lines", "line"),
            ("stations", "station"),
            ("tool_stations", "tool station"),
            ("workers", "worker"),
        )
    )
    return (
        f"{source}: valid scenario {c['scenario']!r} (site {c['site']}): {site}; "
        f"{_count(c['uavs'], 'UAV')} of {_count(c['uav_types'], 'type')}; "
        f"{_count(c['actions'], 'scripted action')}"
    )


def main(argv: list[str]) -> int:
    """``linecrew scenario check FILE [--json]``."""
    parser = argparse.ArgumentParser(
        prog="linecrew scenario",
        description="Scenario files. check FILE: validate one without starting a fleet "
        "(example: linecrew_runtime/scenarios/paper.yaml).",
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    verbs = parser.add_subparsers(dest="verb", required=True)
    check_parser = verbs.add_parser("check", help="validate a scenario file")
    check_parser.add_argument("file", type=pathlib.Path, help="a scenario (.yaml, .yml, .json)")
    check_parser.add_argument("--json", action="store_true", dest="json_", help="print JSON")
    args = parser.parse_args(argv)
    scenario, problems = check(args.file)
    source = str(args.file)
    if args.json or args.json_:
        print(
            json.dumps(
                {
                    "file": source,
                    "valid": not problems,
                    "problems": [dataclasses.asdict(p) for p in problems],
                    "summary": summary(scenario) if scenario and not problems else None,
                },
                indent=2,
            )
        )
    elif problems:
        for problem in problems:
            print(problem.render(source), file=sys.stderr)
    else:
        assert scenario is not None
        print(_summary_line(source, summary(scenario)))
    return 1 if problems else 0
