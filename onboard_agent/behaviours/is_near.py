"""Conditions "Is Agent near X?" and "No X?"."""

from onboard_agent.behaviours.base import Condition
from onboard_agent.context import Context
from onboard_agent.targets import Target


class IsNear(Condition):
    """The UAV is within the target's radius (and hovering, for targets
    that need it)."""

    def __init__(self, target: Target, ctx: Context, name: str | None = None) -> None:
        super().__init__(name or f"Is Agent near {target.label}?", ctx)
        self.target = target

    def holds(self) -> bool:
        return self.target.reached(self.ctx)


class NoPlace(Condition):
    """The target has no point now (nowhere to go for it)."""

    def __init__(self, target: Target, ctx: Context, name: str | None = None) -> None:
        super().__init__(name or f"No {target.label}?", ctx)
        self.target = target

    def holds(self) -> bool:
        return self.target.locate(self.ctx) is None
