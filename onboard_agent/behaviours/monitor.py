"""Action "Monitoring": hold the slot around the worker, following them."""

from __future__ import annotations

from onboard_agent import targets
from onboard_agent.behaviours.base import AgentBehaviour, Status
from onboard_agent.context import Context
from proto.geo import Point
from proto.plan import MonitorTask


class Monitor(AgentBehaviour):
    """Keeps the slot's stand-off position (re-targeted when the worker
    moves) and counts the time spent there; SUCCESS after ``duration_s``.
    The time counted survives interruptions (it lives in the mission)."""

    def __init__(self, ctx: Context, name: str = "Monitoring") -> None:
        super().__init__(name, ctx)
        self._last_tick: float | None = None
        self._sent: Point | None = None
        self._sent_at = 0.0

    def initialise(self) -> None:
        self._last_tick = None
        self._sent = None

    def update(self) -> Status:
        ctx = self.ctx
        task = ctx.mission.head
        slot = targets.monitor_slot(ctx)
        if not isinstance(task, MonitorTask) or slot is None:
            self.feedback_message = "no worker to monitor"
            return Status.FAILURE
        ctx.mission.start(task)
        now = ctx.clock()
        if self._last_tick is not None:
            ctx.mission.add_monitored(task.task_id, now - self._last_tick)
        self._last_tick = now
        done_s = ctx.mission.monitored_s(task.task_id)
        if done_s >= task.duration_s:
            self.feedback_message = f"monitored {task.worker_id} for {task.duration_s:.0f} s"
            return Status.SUCCESS
        config = ctx.config
        moved = self._sent is None or self._sent.distance_to(slot) > config.follow_threshold_m
        if moved or now - self._sent_at >= config.goto_resend_s:
            ctx.autopilot.goto(slot)
            self._sent, self._sent_at = slot, now
        self.feedback_message = f"monitoring {task.worker_id}, {done_s:.0f}/{task.duration_s:.0f} s"
        return Status.RUNNING
