"""Condition "Is Battery Enough?"."""

from onboard_agent import budget
from onboard_agent.behaviours.base import Condition


class IsBatteryEnough(Condition):
    """Energy for the next step of the head task, then the nearest station,
    with the reserve (see :mod:`onboard_agent.budget`). False while a
    battery-low recharge is running: that one goes on until the battery is full."""

    def holds(self) -> bool:
        return not self.ctx.recharging and budget.battery_enough(self.ctx)
