"""Gripper: grab at tool stations, release near a worker = recorded delivery."""

from __future__ import annotations

from sim_fleet import World
from sim_fleet import autopilot as ap
from sim_fleet.events import Result
from sim_fleet.modes import FlightState
from sim_fleet.params import AutopilotParams
from tests.sim_fleet.helpers import CARRIER, airborne, command, run_until, world
from tests.sim_fleet.small_world import small_world

GRIPPER = 211
GRAB, RELEASE = 1, 0


def goto(w, v, target):
    ap.position_target(v, target, None)
    run_until(w, lambda: v.position == target)


def test_hover_low_at_tool_station_grab_then_deliver_to_worker():
    w = world(vtype=CARRIER)
    v = w.vehicle("u1")
    airborne(w, v, 5.0)
    goto(w, v, (20.0, 0.0, 4.5))  # T1 holds the hammer at (20, 0, 3)
    assert command(w, v, GRIPPER, 1, GRAB).result is Result.ACCEPTED
    assert v.holding is not None and v.holding.name == "hammer"
    assert w.tool_stations["T1"].tools == []
    goto(w, v, (41.0, 0.0, 5.0))  # W1 at (40, 0, 3)
    assert command(w, v, GRIPPER, 1, RELEASE).result is Result.ACCEPTED
    assert v.holding is None
    [d] = w.deliveries
    assert (d.tool_id, d.vehicle_id, d.worker_id) == ("hammer", "u1", "W1")
    texts = [t.text for t in v.take_texts()]
    assert "Gripper: grabbed hammer at T1" in texts
    assert "Gripper: delivered hammer to W1" in texts


def test_cannot_grab_when_too_high_or_moving():
    w = world(vtype=CARRIER)
    v = w.vehicle("u1")
    airborne(w, v, 10.0)
    goto(w, v, (20.0, 0.0, 10.0))  # 7 m above the tools
    command(w, v, GRIPPER, 1, GRAB)
    assert v.holding is None
    ap.position_target(v, (20.0, 0.0, 4.0), None)
    w.step(3.0)  # still descending fast
    command(w, v, GRIPPER, 1, GRAB)
    assert v.holding is None or v.state is FlightState.FLYING


def test_release_away_from_workers_is_a_drop_not_a_delivery():
    w = world(vtype=CARRIER)
    v = w.vehicle("u1")
    airborne(w, v, 4.0)
    goto(w, v, (20.0, 0.0, 4.0))
    command(w, v, GRIPPER, 1, GRAB)
    goto(w, v, (20.0, 30.0, 4.0))
    command(w, v, GRIPPER, 1, RELEASE)
    assert w.deliveries == []
    [drop] = w.drops
    assert drop.tool_id == "hammer" and drop.tool_station_id is None


def test_vehicle_without_gripper_gets_unsupported():
    w = world()
    v = w.vehicle("u1")
    airborne(w, v, 4.0)
    goto(w, v, (20.0, 0.0, 4.0))
    assert command(w, v, GRIPPER, 1, GRAB).result is Result.UNSUPPORTED
    assert w.tool_stations["T1"].tools != []


def test_failed_gripper_acknowledges_but_does_nothing():
    w = world(vtype=CARRIER)
    v = w.vehicle("u1")
    w.fail_gripper("u1")
    airborne(w, v, 4.0)
    goto(w, v, (20.0, 0.0, 4.0))
    assert command(w, v, GRIPPER, 1, GRAB).result is Result.ACCEPTED
    assert v.holding is None


def test_grab_takes_only_from_the_nearest_station_even_when_it_is_empty():
    # small world: P-wrench at (1, 5, 3), P-allen_wrench 1 m east, W1 at (0, 10, 3)
    w = World(small_world(1), params=AutopilotParams(auto_disarm_s=None, warmup_s=0.0))
    v = w.vehicle("uav1")
    airborne(w, v, 4.5)
    goto(w, v, (1.2, 5.0, 4.5))
    command(w, v, GRIPPER, 1, GRAB)
    assert v.holding is not None and v.holding.name == "wrench"
    goto(w, v, (0.0, 11.0, 5.0))
    command(w, v, GRIPPER, 1, RELEASE)
    assert [d.tool_id for d in w.deliveries] == ["wrench"]
    goto(w, v, (1.2, 5.0, 4.5))  # back over the emptied wrench station
    v.take_texts()
    command(w, v, GRIPPER, 1, GRAB)
    assert v.holding is None
    assert [t.text for t in v.take_texts()] == ["Gripper: grabbed nothing"]
    assert [t.name for t in w.tool_stations["P-allen_wrench"].tools] == ["allen_wrench"]
    goto(w, v, (1.8, 5.0, 4.5))  # nearer the allen wrench now
    command(w, v, GRIPPER, 1, GRAB)
    assert v.holding is not None and v.holding.name == "allen_wrench"
