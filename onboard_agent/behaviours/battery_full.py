"""Condition "Is Battery Full?"."""

from onboard_agent.behaviours.base import Condition


class IsBatteryFull(Condition):
    """State of charge at or above ``battery_full_fraction``."""

    def holds(self) -> bool:
        return self.ctx.vehicle.battery_fraction >= self.ctx.config.battery_full_fraction
