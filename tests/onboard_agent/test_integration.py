"""The agent process against a sim_fleet vehicle over real MAVLink and a real
Zenoh router. The simulator's state is the truth; waits are on conditions."""

from __future__ import annotations

import math

from proto.geo import Point
from proto.plan import DeliverTask, InspectTask, PickTask, RechargeTask, Waypoint
from proto.spots import spot_positions
from proto.telemetry import OutcomeResult
from tests.onboard_agent.conftest import fast_scenario
from tests.onboard_agent.helpers import plan
from tests.support.processes import wait_until

SITE = fast_scenario().site


def waypoints(*xy: tuple[float, float], first: int = 0) -> list[Waypoint]:
    return [
        Waypoint(index=first + i, position=Point(x_m=x, y_m=y, z_m=3.0), service_s=0.2)
        for i, (x, y) in enumerate(xy)
    ]


def vehicle(fleet):
    return fleet.fleet.world.vehicle("uav-1")


def test_inspection_completes_with_per_waypoint_progress(router, fleet, gs, agent):
    task = InspectTask(task_id="i1", action_id="a1", waypoints=waypoints((-7, 7), (0, 7), (7, 7)))
    gs.send(plan(task))
    wait_until(lambda: gs.outcome("i1"), 40, "inspection outcome")
    outcome = gs.outcome("i1")
    assert outcome.result is OutcomeResult.COMPLETED, outcome
    assert outcome.waypoints_done == [0, 1, 2]
    assert outcome.epoch == 1
    v = vehicle(fleet)
    wait_until(lambda: v.state == "landed" and not v.armed, 30, "landed back on a station")
    station = min(
        SITE.stations,
        key=lambda s: s.position.distance_to(Point(x_m=v.position[0], y_m=v.position[1])),
    )
    assert abs(station.position.x_m - v.position[0]) < 1.0


def test_split_inspection_recharges_midway_and_resumes(router, fleet, gs, agent):
    v = vehicle(fleet)
    fleet.call(lambda: v.set_battery_soc(0.7))
    first = InspectTask(task_id="i1", action_id="a1", waypoints=waypoints((-7, 7), (0, 7)))
    station = SITE.station("C1")
    recharge = RechargeTask(
        task_id="r1", station_id="C1", position=station.position, until_fraction=0.95
    )
    rest = InspectTask(task_id="i2", action_id="a1", waypoints=waypoints((7, 7), (7, 14), first=2))
    gs.send(plan(first, recharge, rest))
    wait_until(lambda: gs.outcome("r1"), 60, "recharge outcome")
    assert gs.outcome("i1").waypoints_done == [0, 1]
    assert gs.outcome("r1").result is OutcomeResult.COMPLETED
    assert fleet.call(lambda: v.battery.soc) > 0.9  # the swap happened on the pad
    wait_until(lambda: gs.outcome("i2"), 40, "second half of the inspection")
    assert gs.outcome("i2").result is OutcomeResult.COMPLETED
    assert gs.outcome("i2").waypoints_done == [2, 3]


def test_delivery_moves_the_tool_to_the_worker(router, fleet, gs, agent):
    # a MAVLink gripper cannot name a tool: each tool waits at its own pick-up point
    rack = SITE.tool_station("tp-wrench")
    pick = PickTask(
        task_id="p1",
        action_id="d",
        tool="wrench",
        tool_station_id="tp-wrench",
        position=rack.position,
        pick_s=0.2,
    )
    deliver = DeliverTask(task_id="d1", action_id="d", tool="wrench", worker_id="W1", drop_s=0.2)
    gs.send(plan(pick, deliver))
    wait_until(lambda: gs.outcome("d1"), 40, "delivery outcome")
    assert gs.outcome("p1").result is OutcomeResult.COMPLETED
    assert gs.outcome("d1").result is OutcomeResult.COMPLETED
    deliveries = fleet.call(lambda: list(fleet.fleet.world.deliveries))
    assert [(d.tool_id, d.vehicle_id, d.worker_id) for d in deliveries] == [
        ("wrench", "uav-1", "W1")
    ]


def long_inspection():
    points = [(-7, 7), (0, 7), (7, 7), (7, 14), (0, 14), (-7, 14)] * 2
    return InspectTask(task_id="i1", action_id="a1", waypoints=waypoints(*points))


def test_ground_station_lost_lands_the_uav_on_a_station(router, fleet, gs, agent):
    v = vehicle(fleet)
    gs.send(plan(long_inspection()))
    wait_until(lambda: gs.status and gs.status.progress > 0, 30, "inspection under way")
    gs.down()
    wait_until(lambda: v.state == "landed" and not v.armed, 30, "UAV landed")
    here = Point(x_m=v.position[0], y_m=v.position[1])
    spots = [p for s in SITE.stations for p in spot_positions(s, fast_scenario().fleet)]
    assert min(math.hypot(p.x_m - here.x_m, p.y_m - here.y_m) for p in spots) < 0.5
    assert gs.outcome("i1") is None  # nobody to tell yet
    gs.up()
    wait_until(lambda: gs.outcome("i1"), 10, "failure reported once the link is back")
    outcome = gs.outcome("i1")
    assert outcome.result is OutcomeResult.FAILED
    assert "ground station unreachable" in outcome.reason
    assert 0 < len(outcome.waypoints_done) < 12


def test_brief_drop_out_changes_nothing(router, fleet, gs, agent):
    task = InspectTask(
        task_id="i1", action_id="a1", waypoints=waypoints((-7, 7), (0, 7), (7, 7), (7, 14))
    )
    gs.send(plan(task))
    wait_until(lambda: gs.status and gs.status.progress > 0, 30, "inspection under way")
    gone_at = gs.status.stamp_s
    gs.down()  # for about half the agent's 1.5 s link timeout, timed by its own status
    wait_until(lambda: gs.status.stamp_s >= gone_at + 0.7, 10, "agent ticking on")
    gs.up()
    wait_until(lambda: gs.outcome("i1"), 40, "inspection outcome")
    assert gs.outcome("i1").result is OutcomeResult.COMPLETED
    assert all(s.state != "emergency" for s in gs.statuses)
    assert agent.stop() == 0  # SIGTERM: stops ticking, closes bus and MAVLink, exits 0
    assert "agent uav-1 stopped" in agent.output()
