"""Action "Wait": hold (on the pad if landed) until the task's time."""

from __future__ import annotations

from onboard_agent.behaviours.base import AgentBehaviour, Status
from onboard_agent.context import Context
from proto.plan import WaitTask


class WaitUntil(AgentBehaviour):
    """SUCCESS once the wall clock reaches ``until_s``. Sends nothing: a
    landed UAV stays landed, a flying one holds its last position target."""

    def __init__(self, ctx: Context, name: str = "Wait") -> None:
        super().__init__(name, ctx)

    def update(self) -> Status:
        task = self.ctx.mission.head
        if not isinstance(task, WaitTask):
            self.feedback_message = "no wait task"
            return Status.FAILURE
        self.ctx.mission.start(task)
        left = task.until_s - self.ctx.wall()
        if left <= 0:
            self.feedback_message = "wait over"
            return Status.SUCCESS
        self.feedback_message = f"waiting {left:.0f} s"
        return Status.RUNNING
