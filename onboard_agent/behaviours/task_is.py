"""Condition: the head task is of a given kind."""

from onboard_agent.behaviours.base import Condition
from onboard_agent.context import Context


class TaskIs(Condition):
    """The head task is one of ``kinds`` (task classes)."""

    def __init__(self, name: str, ctx: Context, *kinds: type) -> None:
        super().__init__(name, ctx)
        self.kinds = kinds

    def holds(self) -> bool:
        return isinstance(self.ctx.mission.head, self.kinds)
