"""Action "Monitoring": hold the slot around the worker, following them."""

from __future__ import annotations

from onboard_agent import targets
from onboard_agent.behaviours.base import AgentBehaviour, Status
from onboard_agent.context import Context
from proto.geo import Point
from proto.plan import MonitorTask


class Monitor(AgentBehaviour):
    """Keeps the slot's stand-off position (re-targeted when the worker
    moves) and counts the time spent there. A planned segment is a time
    window: SUCCESS at its ``end_s`` (mission seconds), so the k UAVs of a
    slot set leave together and a relieved UAV stays until its relief's
    start (then beside the slot until the relief is there: see
    :func:`targets.awaiting_relief`); a task without times ends after
    ``duration_s`` on station. The time counted survives interruptions (it
    lives in the mission)."""

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
        if self._last_tick is not None and _in_window(task, ctx.wall()):
            ctx.mission.add_monitored(task.task_id, now - self._last_tick)
        self._last_tick = now
        done_s = ctx.mission.monitored_s(task.task_id)
        over = ctx.wall() >= task.end_s if task.end_s > 0 else done_s >= task.duration_s
        if over and not targets.awaiting_relief(ctx):
            self.feedback_message = f"monitored {task.worker_id} for {done_s:.0f} s"
            return Status.SUCCESS
        config = ctx.config
        moved = self._sent is None or self._sent.distance_to(slot) > config.follow_threshold_m
        if moved or now - self._sent_at >= config.goto_resend_s:
            ctx.goto(slot)
            self._sent, self._sent_at = slot, now
        if over:
            self.feedback_message = f"watching {task.worker_id} until {task.relieved_by} is there"
        else:
            self.feedback_message = (
                f"monitoring {task.worker_id}, {done_s:.0f}/{task.duration_s:.0f} s"
            )
        return Status.RUNNING


def _in_window(task: MonitorTask, now_s: float) -> bool:
    """Whether ``now_s`` lies in the task's planned window (always, for a
    task without times): seconds on station before the window (a relief
    that arrived early) are not this task's work."""
    return task.end_s <= 0 or task.window_start_s <= now_s
