"""Wire fault commands on the world, scripted workers, and the ground truth."""

from __future__ import annotations

import pytest

from linecrew_runtime.scenarios import load
from proto import (
    BatteryFault,
    DrainFault,
    GpsFreeze,
    GripperFailure,
    KillVehicle,
    LinkDrop,
    MotorFailure,
    MoveWorker,
    Point,
)
from proto.site import TimedPoint, Worker
from sim_fleet.faults import OutsideSite, UnknownTarget, apply_fault
from sim_fleet.truth import sim_state
from sim_fleet.workers import worker_position
from sim_fleet.world import World

PAPER = load("paper")


@pytest.fixture
def world():
    return World(PAPER)


def test_battery_fault_sets_the_charge(world):
    reply = apply_fault(world, BatteryFault(uav_id="uav-1", fraction=0.25), PAPER.site)
    assert world.vehicle("uav-1").battery.soc == pytest.approx(0.25)
    assert reply.target == "uav-1" and "25%" in reply.detail


def test_motor_link_and_gps_faults_reach_the_vehicle(world):
    apply_fault(world, MotorFailure(uav_id="uav-2"), PAPER.site)
    apply_fault(world, LinkDrop(uav_id="uav-3", duration_s=7), PAPER.site)
    apply_fault(world, GpsFreeze(uav_id="uav-1", duration_s=3), PAPER.site)
    assert world.vehicle("uav-2").motors_failed
    assert world.vehicle("uav-3").link_down_until == pytest.approx(7)
    assert world.vehicle("uav-1").gps_frozen_until == pytest.approx(3)


def test_drain_kill_gripper_and_worker_faults(world):
    apply_fault(world, DrainFault(uav_id="uav-1", multiplier=3), PAPER.site)
    apply_fault(world, KillVehicle(uav_id="uav-2"), PAPER.site)
    apply_fault(world, GripperFailure(uav_id="uav-1"), PAPER.site)
    reply = apply_fault(
        world, MoveWorker(worker_id="W2", position=Point(x_m=1, y_m=2, z_m=3)), PAPER.site
    )
    assert world.vehicle("uav-1").drain_multiplier == 3
    assert world.vehicle("uav-2").motors_failed and world.vehicle("uav-2").link_down_until > 1e9
    assert world.vehicle("uav-1").gripper_failed
    assert world.workers["W2"] == (1, 2, 3) and reply.target == "W2"
    with pytest.raises(UnknownTarget, match="no worker 'W9'"):
        apply_fault(world, MoveWorker(worker_id="W9", position=Point(x_m=0, y_m=0)), PAPER.site)


@pytest.mark.parametrize("x_m", [1e308, -1e6, 5_000])
def test_a_worker_is_never_moved_outside_the_site(world, x_m):
    before = world.workers["W2"]
    away = MoveWorker(worker_id="W2", position=Point(x_m=x_m, y_m=0))
    with pytest.raises(OutsideSite, match="outside the site's area") as caught:
        apply_fault(world, away, PAPER.site)
    assert caught.value.field == "position" and world.workers["W2"] == before


def test_unknown_uav_is_a_clear_error(world):
    with pytest.raises(UnknownTarget, match="known: uav-1, uav-2, uav-3") as caught:
        apply_fault(world, MotorFailure(uav_id="ghost"), PAPER.site)
    assert caught.value.field == "uav_id"


def test_ground_truth_lists_every_vehicle_on_its_pad(world):
    world.step(1.0)
    state = sim_state(world, speedup=3.0)
    assert [v.uav_id for v in state.vehicles] == ["uav-1", "uav-2", "uav-3"]
    assert all(v.state == "landed" and not v.armed for v in state.vehicles)
    assert state.sim_time_s == pytest.approx(1.0)


def test_scripted_worker_moves_in_straight_lines_and_stops_at_the_end():
    start = Point(x_m=0, y_m=0, z_m=0)
    worker = Worker(
        id="W",
        position=start,
        path=[
            TimedPoint(at_s=10, position=Point(x_m=10, y_m=0, z_m=0)),
            TimedPoint(at_s=20, position=Point(x_m=10, y_m=0, z_m=20)),
        ],
    )
    assert worker_position(worker, 0) == start
    assert worker_position(worker, 5) == Point(x_m=5, y_m=0, z_m=0)
    assert worker_position(worker, 15) == Point(x_m=10, y_m=0, z_m=10)
    assert worker_position(worker, 99) == Point(x_m=10, y_m=0, z_m=20)
    assert worker_position(Worker(id="S", position=start), 50) == start
