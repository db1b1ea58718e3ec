"""Action "Task Done": report the head task completed and move to the next."""

from __future__ import annotations

from onboard_agent.behaviours.base import AgentBehaviour, Status
from onboard_agent.context import Context


class FinishTask(AgentBehaviour):
    """Always SUCCESS: the head task's outcome goes to the outbox and the
    queue advances."""

    def __init__(self, ctx: Context, name: str = "Task Done") -> None:
        super().__init__(name, ctx)

    def update(self) -> Status:
        task = self.ctx.mission.head
        self.feedback_message = "no task"
        if task is not None:
            self.ctx.mission.complete(task)
            self.feedback_message = f"{task.task_id} completed"
        return Status.SUCCESS
