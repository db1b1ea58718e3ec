"""Builders for behaviour-tree tests: the paper's scenario, plans, a
hand-ticked agent on a fake autopilot."""

from __future__ import annotations

from collections.abc import Callable

from linecrew_runtime.scenarios import load
from onboard_agent import Agent, AgentConfig
from proto.geo import Point
from proto.plan import InspectTask, Plan, Task, Waypoint
from proto.spots import spot_owners, spot_positions
from tests.fakes.autopilot import FakeAutopilot, FakeClock

SCENARIO = load("paper")
TICK_S = 0.1


def on_a_spot(where: Point, station_id: str, uav_id: str = "uav-1") -> bool:
    """Whether ``where`` is above a spot of ``station_id`` that ``uav_id``
    may use: a shared one, or its own home spot."""
    station = SCENARIO.site.station(station_id)
    points, owners = spot_positions(station, SCENARIO.fleet), spot_owners(station, SCENARIO.fleet)
    spots = zip(points, owners, strict=True)
    return any(
        (where.x_m, where.y_m) == (p.x_m, p.y_m) for p, owner in spots if owner in (None, uav_id)
    )


def home_spot(uav_id: str) -> Point:
    """Where the simulator starts ``uav_id``: its own spot at home."""
    home = next(u.home_station for u in SCENARIO.fleet.uavs if u.id == uav_id)
    station = SCENARIO.site.station(home)
    spot = spot_owners(station, SCENARIO.fleet).index(uav_id)
    return spot_positions(station, SCENARIO.fleet)[spot]


def point(x: float, y: float, z: float = 0.0) -> Point:
    return Point(x_m=x, y_m=y, z_m=z)


def inspect_task(task_id: str = "t1", n: int = 3, service_s: float = 1.0, first: int = 0) -> Task:
    waypoints = [
        Waypoint(index=first + i, position=point(2.0 * i, 7.0, 3.0), service_s=service_s)
        for i in range(n)
    ]
    return InspectTask(task_id=task_id, action_id="a1", waypoints=waypoints)


def plan(*tasks: Task, epoch: int = 1, uav_id: str = "uav-1") -> Plan:
    return Plan(uav_id=uav_id, epoch=epoch, tasks=list(tasks))


class Rig:
    """An agent on a fake autopilot, with fake monotonic and wall clocks."""

    def __init__(
        self,
        uav_id: str = "uav-1",
        battery: float = 1.0,
        position: Point | None = None,
        config: AgentConfig | None = None,
        gs_alive: bool = True,
    ) -> None:
        self.clock = FakeClock(1000.0)
        self.wall = FakeClock(1.7e9)
        self.autopilot = FakeAutopilot(position or home_spot(uav_id), battery)
        self.agent = Agent(
            uav_id,
            SCENARIO,
            self.autopilot,
            config,
            clock=self.clock,
            wall=self.wall,
            link_clock=self.clock,
        )
        if gs_alive:
            self.agent.ground_station("gs", True)

    @property
    def mission(self):
        return self.agent.mission

    def tick(self, n: int = 1, arrive: bool = True) -> None:
        for _ in range(n):
            self.agent.tick()
            if arrive:
                self.autopilot.arrive()
            self.clock.advance(TICK_S)
            self.wall.advance(TICK_S)

    def run_until(self, predicate: Callable[[], object], max_ticks: int = 2000, **kw) -> int:
        for i in range(max_ticks):
            if predicate():
                return i
            self.tick(**kw)
        raise AssertionError(f"not reached in {max_ticks} ticks; path {self.agent.active_path()}")

    def leaf(self) -> str:
        """The deepest node that ran in the last tick."""
        path = self.agent.active_path()
        return path[-1] if path else ""

    def outcomes(self):
        return self.mission.take_outcomes()
