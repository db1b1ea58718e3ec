"""Export of the tree: BehaviorTree.CPP v4 XML for Groot2, and ASCII."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from onboard_agent.main import main

PAPER_NODES = [
    "Mission Over?",
    "Is Battery Enough?",
    "Is Battery Full?",
    "Idle?",
    "Need to Drop the Tool?",
    "Has Agent the Tool?",
    "Is Agent near WP?",
    "Is Agent near Human Target?",
    "Is Agent near Charging Station?",
    "Go near WP",
    "Inspection",
    "Monitoring",
    "Pick Tool",
    "Deliver Tool",
    "Drop Tool",
    "Recharge",
]


def export(capsys, fmt: str) -> str:
    assert main(["tree", "--format", fmt]) == 0
    return capsys.readouterr().out


def test_xml_is_btcpp_v4_with_subtrees_and_a_model(capsys):
    root = ET.fromstring(export(capsys, "xml"))
    assert root.tag == "root" and root.get("BTCPP_format") == "4"
    trees = {t.get("ID"): t for t in root.findall("BehaviorTree")}
    assert root.get("main_tree_to_execute") == "MainTree" and "MainTree" in trees
    for expected in (
        "InspectionTask",
        "MonitoringTask",
        "ToolDeliveryTask",
        "DropTool",
        "Recharge",
        "RechargeTask",
        "WaitTask",
        "GoHomeTask",
        "BackToStation",
    ):
        assert expected in trees
    referenced = {s.get("ID") for s in root.iter("SubTree")}
    assert referenced <= set(trees)
    model = {m.get("ID"): m.tag for m in root.find("TreeNodesModel")}
    assert model["IsBatteryEnough"] == "Condition"
    assert model["GoNear"] == "Action"
    assert model["ForceRunning"] == "Decorator"
    builtin = {
        "ReactiveSequence",
        "ReactiveFallback",
        "Inverter",
        "ForceFailure",
        "SubTree",
        "BehaviorTree",
        "root",
        "TreeNodesModel",
    }
    for node in root.iter():
        if node.tag not in builtin and node.get("name") is not None:
            assert node.tag in model, node.tag
    names = {n.get("name") for n in root.iter()}
    for name in PAPER_NODES:
        assert name in names


def test_ascii_shows_the_tree(capsys):
    text = export(capsys, "ascii")
    assert text.startswith("[o] Main Tree")
    for name in PAPER_NODES:
        assert name in text


def test_unknown_format_is_an_error(capsys):
    with pytest.raises(SystemExit):
        main(["tree", "--format", "svg"])
