"""The double-task invariant on the simulator's truth: two UAVs hovering at
one spot watching the same worker for longer than a hand-over."""

from __future__ import annotations

from linecrew.chaos import Checker
from proto import Point, SimState, VehicleTruth, WatchRecord

STEP_S = 5.0  # mission seconds between samples (x10, two samples a wall second)


class World:
    """Synthetic truth: UAVs at fixed points, each watching a worker or not."""

    def __init__(self) -> None:
        self.t = 100.0
        self.seconds: dict[tuple[str, str], float] = {}
        self.checker = Checker(reserve_fraction=0.2)

    def step(self, where: dict[str, tuple[float, float]], watching: dict[str, str]) -> None:
        """Advance one sample: UAVs at ``where`` (x, y), those in
        ``watching`` credited watching their worker meanwhile."""
        self.t += STEP_S
        for uav, worker in watching.items():
            self.seconds[worker, uav] = self.seconds.get((worker, uav), 0.0) + STEP_S
        vehicles = [
            VehicleTruth(
                uav_id=uav,
                position=Point(x_m=x, y_m=y, z_m=6.0),
                battery_fraction=0.8,
                state="flying",
                armed=True,
            )
            for uav, (x, y) in where.items()
        ]
        watched = [
            WatchRecord(worker_id=w, uav_id=u, seconds=s) for (w, u), s in self.seconds.items()
        ]
        truth = SimState(sim_time_s=self.t, speedup=10.0, vehicles=vehicles, watched=watched)
        self.checker.sample(self.t / 10.0, None, None, None, truth)

    def doubles(self) -> list[str]:
        return [v.detail for v in self.checker.violations if v.invariant == "double_task"]


SLOT = (4.0, 0.0)
NEAR_SLOT = (4.5, 1.0)  # 1.1 m away: the same spot
OTHER_SLOT = (-4.0, 0.0)  # the opposite slot of a second monitor of the worker
HOLD_OUT = (7.0, 0.0)  # a relief holding farther out until its window begins


def test_two_uavs_watching_from_one_spot_past_a_hand_over_are_reported_once():
    world = World()
    both = {"uav-1": "W2", "uav-2": "W2"}
    for _ in range(6):  # 30 s together: a hand-over may take that long
        world.step({"uav-1": SLOT, "uav-2": NEAR_SLOT}, both)
    assert world.doubles() == []
    for _ in range(4):
        world.step({"uav-1": SLOT, "uav-2": NEAR_SLOT}, both)
    assert world.doubles() == [
        "W2 watched by uav-1 and uav-2 from one spot for over 30 s from sim 105 s "
        "(simulator's truth)"
    ]
    assert world.checker.checks["double_task"] == 10


def test_a_hand_over_other_slots_and_a_uav_not_watching_are_not_doubles():
    world = World()
    for _ in range(4):  # the relief holds out, then takes the slot; the other leaves
        world.step({"uav-1": SLOT, "uav-2": HOLD_OUT}, {"uav-1": "W2", "uav-2": "W2"})
    for _ in range(4):
        world.step({"uav-1": NEAR_SLOT, "uav-2": SLOT}, {"uav-1": "W2", "uav-2": "W2"})
    for _ in range(20):
        world.step({"uav-1": (30.0, 30.0), "uav-2": SLOT}, {"uav-2": "W2"})
    for _ in range(20):  # two monitors of one worker, opposite slots
        world.step({"uav-1": OTHER_SLOT, "uav-2": SLOT}, {"uav-1": "W2", "uav-2": "W2"})
    for _ in range(20):  # near the slot but watching nothing (e.g. passing, credited nothing)
        world.step({"uav-1": NEAR_SLOT, "uav-2": SLOT}, {"uav-2": "W2"})
    for _ in range(20):  # one spot, but watching two different workers
        world.step({"uav-1": NEAR_SLOT, "uav-2": SLOT}, {"uav-1": "W1", "uav-2": "W2"})
    assert world.doubles() == []


def test_a_second_episode_of_the_same_pair_is_reported_again():
    world = World()
    both = {"uav-1": "W2", "uav-2": "W2"}
    for _episode in range(2):
        for _ in range(8):
            world.step({"uav-1": SLOT, "uav-2": NEAR_SLOT}, both)
        world.step({"uav-1": SLOT, "uav-2": HOLD_OUT}, both)
    assert [d.split(" from sim ")[1] for d in world.doubles()] == [
        "105 s (simulator's truth)",
        "150 s (simulator's truth)",
    ]
