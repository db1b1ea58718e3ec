"""The tree as BehaviorTree.CPP v4 XML (loadable by Groot2) and as py_trees ASCII.

Reactive composites become ReactiveSequence / ReactiveFallback, py_trees'
Inverter and SuccessIsFailure become Inverter and ForceFailure, subtree roots
(``subtree_id``) become ``<SubTree ID=...>`` references with their own
``<BehaviorTree>``, and every leaf or custom decorator class is declared in
``<TreeNodesModel>``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import py_trees

from onboard_agent import idioms
from onboard_agent.behaviours.base import AgentBehaviour
from onboard_agent.config import AgentConfig
from onboard_agent.context import Context
from onboard_agent.energy import EnergyModel
from onboard_agent.mission import Mission
from onboard_agent.spots import Spots
from onboard_agent.surroundings import Surroundings
from onboard_agent.traffic import Traffic
from proto.fleet import Fleet, UavType
from proto.geo import GeoPoint
from proto.scenario import Scenario
from proto.site import Site

Behaviour = py_trees.behaviour.Behaviour
BUILTIN_DECORATORS = {"Inverter": "Inverter", "SuccessIsFailure": "ForceFailure"}
FORMATS = ("xml", "ascii")


def exportable_tree() -> Behaviour:
    """The Main Tree built on placeholders (nothing is ticked or connected)."""
    site = Site(origin=GeoPoint())
    uav_type = UavType(name="any", capabilities={})
    ctx = Context(
        uav_id="uav",
        config=AgentConfig(),
        autopilot=None,  # type: ignore[arg-type]
        mission=Mission("uav", site, lambda: 0.0),
        surroundings=Surroundings(site),
        spots=Spots("uav", Scenario(name="any", site=site, fleet=Fleet(types=[uav_type], uavs=[]))),
        traffic=Traffic("uav"),
        energy=EnergyModel(uav_type, 0.2),
        clock=lambda: 0.0,
        wall=lambda: 0.0,
    )
    return idioms.main_tree(ctx)


def render(root: Behaviour, fmt: str) -> str:
    """``root`` as ``xml`` (BehaviorTree.CPP v4) or ``ascii`` (py_trees)."""
    if fmt == "ascii":
        return py_trees.display.ascii_tree(root)
    if fmt == "xml":
        return to_btcpp_xml(root)
    raise ValueError(f"unknown format {fmt!r}: use one of {', '.join(FORMATS)}")


def to_btcpp_xml(root: Behaviour) -> str:
    """BehaviorTree.CPP v4 XML: one ``<BehaviorTree>`` per subtree."""
    main_id = getattr(root, "subtree_id", "MainTree")
    doc = ET.Element("root", BTCPP_format="4", main_tree_to_execute=main_id)
    models: dict[str, str] = {}
    pending = [root]
    written: set[str] = set()
    while pending:
        top = pending.pop(0)
        tree_id = getattr(top, "subtree_id", main_id)
        if tree_id in written:
            continue
        written.add(tree_id)
        tree = ET.SubElement(doc, "BehaviorTree", ID=tree_id)
        _node(tree, top, top, models, pending)
    model = ET.SubElement(doc, "TreeNodesModel")
    for node_id, kind in sorted(models.items()):
        ET.SubElement(model, kind, ID=node_id)
    ET.indent(doc)
    return ET.tostring(doc, encoding="unicode") + "\n"


def _node(
    parent: ET.Element,
    node: Behaviour,
    top: Behaviour,
    models: dict[str, str],
    pending: list[Behaviour],
) -> None:
    if node is not top and hasattr(node, "subtree_id"):
        ET.SubElement(parent, "SubTree", ID=node.subtree_id)
        pending.append(node)
        return
    cls = type(node).__name__
    if isinstance(node, py_trees.composites.Sequence):
        tag = "Sequence" if node.memory else "ReactiveSequence"
    elif isinstance(node, py_trees.composites.Selector):
        tag = "Fallback" if node.memory else "ReactiveFallback"
    elif isinstance(node, py_trees.decorators.Decorator):
        tag = BUILTIN_DECORATORS.get(cls, cls)
        if cls not in BUILTIN_DECORATORS:
            models[cls] = "Decorator"
    else:
        tag = cls
        models[cls] = node.kind if isinstance(node, AgentBehaviour) else "Action"
    element = ET.SubElement(parent, tag, name=node.name)
    for child in node.children:
        _node(element, child, top, models, pending)
