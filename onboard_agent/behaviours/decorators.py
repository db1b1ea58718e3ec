"""The two decorators the paper's trees need that py_trees lacks."""

from __future__ import annotations

import py_trees

from onboard_agent.context import Context

Status = py_trees.common.Status


class ForceRunning(py_trees.decorators.Decorator):
    """RUNNING whatever the child returns (the Main Tree never ends)."""

    def update(self) -> Status:
        self.feedback_message = f"child {self.decorated.status.value}"
        return Status.RUNNING


class TaskGuard(py_trees.decorators.Decorator):
    """Fails the head task when its subtree fails ``attempts`` times: the
    failure is reported (reason: the failing leaf's feedback) and the queue
    moves on, instead of retrying a hopeless task forever. A leaf that fails
    *retryable* (it already retried with backoff: the autopilot not ready or
    refusing to arm) fails the task at once, marked retryable with the leaf's
    code, so the ground station can replan it (later or on another UAV)."""

    def __init__(self, name: str, child: py_trees.behaviour.Behaviour, ctx: Context) -> None:
        super().__init__(name=name, child=child)
        self.ctx = ctx

    def update(self) -> Status:
        status = self.decorated.status
        if status is not Status.FAILURE:
            self.feedback_message = ""
            return status
        tip = self.decorated.tip() or self.decorated
        reason = f"{tip.name}: {tip.feedback_message}"
        code = getattr(tip, "failure_code", "") or "task_failed"
        retryable = bool(getattr(tip, "retryable", False))
        task = self.ctx.mission.head
        if task is not None:
            attempts = self.ctx.mission.note_failure(task)
            if retryable or attempts >= self.ctx.config.task_attempts:
                self.ctx.mission.fail(task, reason, code=code, retryable=retryable)
        self.feedback_message = reason
        return Status.FAILURE
