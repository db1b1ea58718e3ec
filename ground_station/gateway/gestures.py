"""Gestures to actions: the crew's gesture-recognition entry of the paper.

A vocabulary (YAML, ``gestures.yaml`` by default) maps a gesture name to an
action template; the gesture's target (a tower, a line or a worker of the
site) fills it in. Unknown gestures are refused with the known list.
"""

from __future__ import annotations

import math
import pathlib
from typing import Literal

import msgspec

from proto.errors import InvalidAction, UnknownGesture
from proto.geo import Point
from proto.mission import Action, DeliverAction, InspectAction, MonitorAction, WaypointSpec
from proto.site import Site

DEFAULT_VOCABULARY = pathlib.Path(__file__).with_name("gestures.yaml")


class Template(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """What one gesture asks for."""

    kind: Literal["inspect", "monitor", "deliver"]
    target: Literal["tower", "line", "worker"]
    priority: float = 1.0
    standoff_m: float = 4.0
    service_s: float = 10.0
    uavs: int = 1
    duration_s: float = 120.0
    tool: str | None = None


class Vocabulary:
    """Gesture name -> action template."""

    def __init__(self, templates: dict[str, Template]) -> None:
        self.templates = templates

    @classmethod
    def load(cls, path: str | pathlib.Path | None = None) -> Vocabulary:
        """Read a vocabulary file (the shipped one by default)."""
        data = pathlib.Path(path or DEFAULT_VOCABULARY).read_bytes()
        return cls(msgspec.yaml.decode(data, type=dict[str, Template]))

    def action(self, gesture: str, target: str, site: Site) -> Action:
        """The action ``gesture`` at ``target`` asks for."""
        template = self.templates.get(gesture)
        if template is None:
            raise UnknownGesture(
                f"unknown gesture {gesture!r}",
                field="gesture",
                known=sorted(self.templates),
            )
        match template.kind:
            case "inspect":
                return InspectAction(
                    priority=template.priority, waypoints=_inspection_points(template, target, site)
                )
            case "monitor":
                _worker(site, target)
                return MonitorAction(
                    priority=template.priority,
                    worker_id=target,
                    uavs=template.uavs,
                    standoff_m=template.standoff_m,
                    duration_s=template.duration_s,
                )
        _worker(site, target)
        tool = template.tool
        station = next((s for s in site.tool_stations if tool in {t.name for t in s.tools}), None)
        if tool is None or station is None:
            raise InvalidAction(f"no tool station holds {tool!r}", field="gesture")
        return DeliverAction(
            priority=template.priority,
            tool=tool,
            tool_station_id=station.id,
            worker_id=target,
        )


def _worker(site: Site, worker_id: str) -> None:
    if site.worker(worker_id) is None:
        raise InvalidAction(f"unknown worker {worker_id!r}", field="target")


def _inspection_points(template: Template, target: str, site: Site) -> list[WaypointSpec]:
    towers = {t.id: t for t in site.towers}
    if template.target == "tower":
        if target not in towers:
            raise InvalidAction(f"unknown tower {target!r}", field="target")
        top = towers[target].position
        offsets = [(math.cos(a), math.sin(a)) for a in (0, math.pi / 2, math.pi, 3 * math.pi / 2)]
        points = [
            Point(
                x_m=top.x_m + template.standoff_m * dx,
                y_m=top.y_m + template.standoff_m * dy,
                z_m=top.z_m,
            )
            for dx, dy in offsets
        ]
    else:
        line = next((line for line in site.lines if line.id == target), None)
        if line is None:
            raise InvalidAction(f"unknown line {target!r}", field="target")
        points = [
            Point(
                x_m=towers[t].position.x_m,
                y_m=towers[t].position.y_m - template.standoff_m,
                z_m=towers[t].position.z_m,
            )
            for t in line.tower_ids
        ]
    return [WaypointSpec(position=p, service_s=template.service_s) for p in points]
