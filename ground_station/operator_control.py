"""Operators taking a UAV out of the plan (:class:`proto.rpc.ControlUav`):
the command in force for each UAV and the tasks that carry it out. A
controlled UAV is no planner's: its work goes to the others and its plan
is the command's task until the operator says ``resume``. Commands live
in memory: a restarted ground station plans every UAV again."""

from __future__ import annotations

import dataclasses
import time

from proto.plan import GoHomeTask, LandTask, Task, WaitTask
from proto.rpc import Command
from proto.scenario import Scenario

FOREVER_S = 10 * 365 * 86400.0
"""How long a hold lasts: until the operator ends it."""


@dataclasses.dataclass(frozen=True)
class Order:
    """A command in force and the tasks that carry it out."""

    command: Command
    tasks: list[Task]


class OperatorControl:
    """The operator's commands in force, by UAV."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.orders: dict[str, Order] = {}

    def order(self, uav_id: str, command: Command, now_s: float) -> None:
        """``command`` for ``uav_id`` from ``now_s`` (``resume`` ends control)."""
        if command is Command.RESUME:
            self.orders.pop(uav_id, None)
            return
        stamp = time.strftime("%H%M%S", time.gmtime(now_s))  # a new id for each second's order
        task_id = f"{uav_id}.{command}.{stamp}"
        tasks: list[Task]
        if command is Command.HOLD:  # no planned end: the plan shows none
            until = now_s + FOREVER_S
            tasks = [WaitTask(task_id=task_id, until_s=until, start_s=now_s, end_s=now_s)]
        elif command is Command.RETURN:
            home = self.scenario.site.station(self._home(uav_id))
            assert home is not None  # the scenario's fleet names existing stations
            tasks = [GoHomeTask(task_id=task_id, station_id=home.id, position=home.position)]
        else:
            tasks = [LandTask(task_id=task_id, start_s=now_s, end_s=now_s)]
        self.orders[uav_id] = Order(command, tasks)

    def finished(self, uav_id: str, task_id: str) -> None:
        """A command's task ended (a return landed): the UAV stays controlled, idle."""
        order = self.orders.get(uav_id)
        if order is not None:
            rest = [t for t in order.tasks if t.task_id != task_id]
            self.orders[uav_id] = dataclasses.replace(order, tasks=rest)

    def command(self, uav_id: str) -> Command | None:
        """The command in force for ``uav_id``, if any."""
        order = self.orders.get(uav_id)
        return order.command if order else None

    @property
    def controlled(self) -> frozenset[str]:
        """The UAVs under an operator's command."""
        return frozenset(self.orders)

    def _home(self, uav_id: str) -> str:
        return next(u.home_station for u in self.scenario.fleet.uavs if u.id == uav_id)
