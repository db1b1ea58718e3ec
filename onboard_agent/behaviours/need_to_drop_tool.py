"""Condition "Need to Drop the Tool?"."""

from onboard_agent.behaviours.base import Condition
from proto.plan import DeliverTask, PickTask


class NeedToDropTool(Condition):
    """A tool is held that the head task does not need (a cancelled delivery,
    or no task left)."""

    def holds(self) -> bool:
        tool = self.ctx.tool
        if tool is None:
            return False
        task = self.ctx.mission.head
        return not (isinstance(task, PickTask | DeliverTask) and task.tool == tool)
