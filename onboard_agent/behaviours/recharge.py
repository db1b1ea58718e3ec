"""Action "Recharge": stay landed on the pad until the battery is charged."""

from __future__ import annotations

from collections.abc import Callable

from onboard_agent.behaviours.base import AgentBehaviour, Status
from onboard_agent.context import Context


class Recharge(AgentBehaviour):
    """SUCCESS when the state of charge reaches ``until_fraction(ctx)``,
    RUNNING before. With ``latch`` (the Main Tree's battery-low recharge) it
    sets ``ctx.recharging`` so "Is Battery Enough?" stays false until full."""

    def __init__(
        self,
        ctx: Context,
        until_fraction: Callable[[Context], float],
        *,
        latch: bool = False,
        name: str = "Recharge",
    ) -> None:
        super().__init__(name, ctx)
        self.until_fraction = until_fraction
        self.latch = latch

    def initialise(self) -> None:
        if self.latch:
            self.ctx.recharging = True

    def update(self) -> Status:
        fraction = self.ctx.vehicle.battery_fraction
        goal = self.until_fraction(self.ctx)
        if fraction >= goal:
            self.feedback_message = f"charged {fraction:.0%}"
            if self.latch:
                self.ctx.recharging = False
            return Status.SUCCESS
        self.feedback_message = f"charging {fraction:.0%} of {goal:.0%}"
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if self.latch and new_status is Status.INVALID:
            self.ctx.recharging = False
