"""Condition "Has Agent the Tool?"."""

from onboard_agent.behaviours.base import Condition
from proto.plan import DeliverTask, PickTask


class HasTool(Condition):
    """The gripper holds the tool of the head pick / deliver task."""

    def holds(self) -> bool:
        task = self.ctx.mission.head
        return isinstance(task, PickTask | DeliverTask) and self.ctx.tool == task.tool
