"""Submissions are checked against the site and fleet; errors name the field."""

from __future__ import annotations

import pytest

from ground_station.validation import InvalidAction, validate
from linecrew_runtime.scenarios import load
from proto import DeliverAction, InspectAction, MonitorAction, Point, WaypointSpec

PAPER = load("paper")


def check(action):
    validate(action, PAPER.site, PAPER.fleet)


def test_the_papers_actions_are_valid():
    for scripted in PAPER.actions:
        check(scripted.action)


@pytest.mark.parametrize(
    ("action", "field", "text"),
    [
        (InspectAction(waypoints=[]), "action.waypoints", "at least one"),
        (MonitorAction(worker_id="W9", duration_s=10), "action.worker_id", "unknown worker"),
        (MonitorAction(worker_id="W1", uavs=4, duration_s=10), "action.uavs", "fleet has 3"),
        (
            DeliverAction(tool="wrench", tool_station_id="nowhere", worker_id="W1"),
            "action.tool_station_id",
            "unknown tool station",
        ),
        (
            DeliverAction(tool="laser", tool_station_id="tp-wrench", worker_id="W1"),
            "action.tool",
            "not at tp-wrench",
        ),
        (
            InspectAction(waypoints=[WaypointSpec(position=Point(x_m=2e6, y_m=0, z_m=5))]),
            "action.waypoints[0].position",
            "outside the site's area",
        ),
        (
            InspectAction(waypoints=[WaypointSpec(position=Point(x_m=0, y_m=7, z_m=-3))]),
            "action.waypoints[0].position.z_m",
            "below the minimum flight altitude 2 m",
        ),
        (
            InspectAction(waypoints=[WaypointSpec(position=Point(x_m=0, y_m=7, z_m=1.5))]),
            "action.waypoints[0].position.z_m",
            "below the minimum flight altitude",
        ),
        (
            MonitorAction(worker_id="W1", uavs=3, duration_s=100_000),
            "action.duration_s",
            "cannot cover 100000 s even with hand-overs",
        ),
        (
            InspectAction(waypoints=[WaypointSpec(position=Point(x_m=float("nan"), y_m=0))]),
            "action.waypoints[0].position.x_m",
            "finite",
        ),
        (MonitorAction(worker_id="W1", duration_s=1e9), "action.duration_s", "over a week"),
    ],
)
def test_bad_actions_name_the_field(action, field, text):
    with pytest.raises(InvalidAction, match=text) as caught:
        check(action)
    assert caught.value.field == field
    assert caught.value.code == "invalid_action"


def test_delivery_needs_a_gripper_uav():
    fleet = PAPER.fleet.__class__(
        types=[t for t in PAPER.fleet.types if not t.gripper],
        uavs=[u for u in PAPER.fleet.uavs if u.type != "physical"],
    )
    with pytest.raises(InvalidAction, match="able to deliver"):
        validate(PAPER.actions[0].action, PAPER.site, fleet)
