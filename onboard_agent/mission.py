"""The agent's task queue: plans in (with epoch fencing and validation),
progress per task, outcomes out.

Epoch fencing: a plan replaces the queue only if its epoch is newer than
the one in force; an older or equal epoch is ignored, a plan addressed to
another UAV is rejected (each of its tasks gets a failure outcome). Outcomes
wait in an outbox until the comms layer can deliver them (so failures met
while the ground station is unreachable are reported when it returns).
"""

from __future__ import annotations

import collections
import enum
import logging
from collections.abc import Callable

from onboard_agent.validation import task_problem
from proto.plan import InspectTask, MonitorTask, Plan, Task, Waypoint
from proto.site import Site
from proto.telemetry import OutcomeResult, TaskOutcome

log = logging.getLogger(__name__)


EPOCH_LEAD = 100
"""How far a plan's epoch may run ahead of the ground station's last
announced one (``Traffic.epoch``) and still be adopted at once: replans in
the half second between announcements. A farther one waits for an
announcement that covers it (a forged epoch never gets one)."""
ARMING_REFUSALS = frozenset({"arm_refused", "takeoff_refused", "not_ready"})
"""Failure codes of a task that gave up on the autopilot arming (after its retries)."""


class PlanVerdict(enum.StrEnum):
    """What :meth:`Mission.offer` did with a plan."""

    ACCEPTED = "accepted"
    STALE = "stale"
    REJECTED = "rejected"
    UNANNOUNCED = "unannounced"  # too far ahead of the announced epoch: held


class Mission:
    """The queue of one UAV and the outcomes it owes the ground station."""

    def __init__(self, uav_id: str, site: Site, wall: Callable[[], float]) -> None:
        self.uav_id = uav_id
        self.site = site
        self.wall = wall
        self.epoch = 0
        self.generation: str | None = None  # the ground station's run, as announced
        self.announced = 0  # the newest epoch that ground station has announced
        self._unannounced: Plan | None = None  # ahead of every announcement: held
        self.arming_refused = False  # a task gave up on arming; the agent clears it when ready
        self.tasks: collections.deque[Task] = collections.deque()
        self.outbox: list[TaskOutcome] = []
        self._sent: collections.deque[TaskOutcome] = collections.deque(maxlen=16)
        self._waypoints_done: dict[str, list[int]] = {}
        self._monitored_s: dict[str, float] = {}
        self._failures: dict[str, int] = {}
        self._tools: dict[str, str] = {}  # the tool a pick grabbed / a drop released, per task
        self._started: set[str] = set()
        self.left_slot: MonitorTask | None = None  # the last task ended, if monitoring

    # -- plans --------------------------------------------------------------------

    def offer(self, plan: Plan) -> PlanVerdict:
        """Adopt ``plan`` if it is for this UAV and newer than the one in force."""
        if plan.uav_id != self.uav_id:
            log.warning("rejected a plan for %s", plan.uav_id, extra={"uav_id": self.uav_id})
            for task in plan.tasks:
                reason = f"plan for {plan.uav_id} sent to {self.uav_id}"
                self._report(task, OutcomeResult.FAILED, reason, plan.epoch, code="wrong_uav")
            return PlanVerdict.REJECTED
        if plan.epoch <= self.epoch:
            log.info("ignored plan epoch %d (holding %d)", plan.epoch, self.epoch)
            return PlanVerdict.STALE
        if plan.epoch > self.announced + EPOCH_LEAD:
            log.warning(
                "held plan epoch %d: the ground station announced %d",
                plan.epoch,
                self.announced,
                extra={"uav_id": self.uav_id},
            )
            self._unannounced = plan
            return PlanVerdict.UNANNOUNCED
        kept = {t.task_id for t in plan.tasks}
        head = self.head
        if head is not None and head.task_id in self._started and head.task_id not in kept:
            reason = f"replaced by plan epoch {plan.epoch}"
            self._report(head, OutcomeResult.ABORTED, reason, code="replaced")
        self.epoch = plan.epoch
        self.tasks.clear()
        for task in plan.tasks:
            problem = task_problem(task, self.site)
            if problem is None:
                self.tasks.append(task)
            else:
                reason = f"rejected: {problem}"
                self._report(task, OutcomeResult.FAILED, reason, code="invalid_task")
        log.info("plan epoch %d: %d tasks", plan.epoch, len(self.tasks))
        return PlanVerdict.ACCEPTED

    def announce(self, generation: str | None, epoch: int) -> PlanVerdict | None:
        """The ground station ``generation`` says it has issued epochs up to
        ``epoch`` (a new generation starts over); a held plan it now covers
        is offered again (its verdict; None if none was held)."""
        if generation != self.generation:
            self.generation, self.announced = generation, epoch
        else:
            self.announced = max(self.announced, epoch)
        held = self._unannounced
        if held is None or held.epoch > self.announced + EPOCH_LEAD:
            return None
        self._unannounced = None
        return self.offer(held)

    @property
    def head(self) -> Task | None:
        """The task to perform now."""
        return self.tasks[0] if self.tasks else None

    def start(self, task: Task) -> None:
        """Note that work on ``task`` began (it is then reported if replaced)."""
        self._started.add(task.task_id)

    # -- progress -------------------------------------------------------------------

    def waypoints_done(self, task_id: str) -> list[int]:
        return list(self._waypoints_done.get(task_id, []))

    def mark_waypoint(self, task: InspectTask, index: int) -> None:
        done = self._waypoints_done.setdefault(task.task_id, [])
        if index not in done:
            done.append(index)

    def next_waypoint(self, task: InspectTask) -> Waypoint | None:
        """The first waypoint of ``task`` not visited yet."""
        done = set(self._waypoints_done.get(task.task_id, []))
        return next((w for w in task.waypoints if w.index not in done), None)

    def monitored_s(self, task_id: str) -> float:
        return self._monitored_s.get(task_id, 0.0)

    def add_monitored(self, task_id: str, seconds: float) -> None:
        self._monitored_s[task_id] = self.monitored_s(task_id) + max(0.0, seconds)

    def progress(self, task: Task | None) -> float:
        """Fraction of ``task`` done (0..1)."""
        match task:
            case InspectTask(waypoints=waypoints) if waypoints:
                done = set(self._waypoints_done.get(task.task_id, []))
                return len([w for w in waypoints if w.index in done]) / len(waypoints)
            case MonitorTask(duration_s=duration):
                return min(1.0, self.monitored_s(task.task_id) / duration)
        return 0.0

    def note_tool(self, task: Task, tool: str | None) -> None:
        """The gripper grabbed (pick) or released (drop) ``tool`` for ``task``."""
        if tool is not None:
            self._tools[task.task_id] = tool

    def note_failure(self, task: Task) -> int:
        """Count a failed attempt at ``task``; returns the attempts so far."""
        self._failures[task.task_id] = self._failures.get(task.task_id, 0) + 1
        return self._failures[task.task_id]

    # -- endings --------------------------------------------------------------------

    def complete(self, task: Task) -> None:
        """``task`` (the head) succeeded: report it and move on."""
        self._pop(task)
        self._report(task, OutcomeResult.COMPLETED, "", progress=1.0)

    def fail(
        self, task: Task, reason: str, *, code: str = "task_failed", retryable: bool = False
    ) -> None:
        """``task`` (the head) failed: report it and move on. ``retryable``:
        for a passing reason (it may succeed later or on another UAV)."""
        self._pop(task)
        self.arming_refused |= code in ARMING_REFUSALS
        self._report(task, OutcomeResult.FAILED, reason, code=code, retryable=retryable)

    def abandon(self, reason: str) -> int:
        """Empty the queue (emergency protocol): every task fails with
        ``reason``; retryable, as another UAV (or this one later) can do it."""
        count = len(self.tasks)
        while self.tasks:
            self.fail(self.tasks[0], reason, code="abandoned", retryable=True)
        return count

    def take_outcomes(self) -> list[TaskOutcome]:
        """The outcomes not yet delivered; the outbox is emptied."""
        outcomes, self.outbox = self.outbox, []
        self._sent.extend(outcomes)
        return outcomes

    def redeliver(self) -> None:
        """Queue the recently sent outcomes again: after the ground station's
        token returns, some may have been published into a session the router
        had already dropped. The ground station records duplicates as stale."""
        pending = {o.task_id for o in self.outbox}
        self.outbox[:0] = [o for o in self._sent if o.task_id not in pending]
        self._sent.clear()

    def _pop(self, task: Task) -> None:
        if self.tasks and self.tasks[0].task_id == task.task_id:
            self.tasks.popleft()
            self.left_slot = task if isinstance(task, MonitorTask) else None

    def _report(
        self,
        task: Task,
        result: OutcomeResult,
        reason: str,
        epoch: int | None = None,
        progress: float | None = None,
        *,
        code: str = "",
        retryable: bool = False,
    ) -> None:
        outcome = TaskOutcome(
            uav_id=self.uav_id,
            task_id=task.task_id,
            action_id=task.action_id,
            epoch=self.epoch if epoch is None else epoch,
            result=result,
            reason=reason,
            progress=self.progress(task) if progress is None else progress,
            waypoints_done=self.waypoints_done(task.task_id),
            stamp_s=self.wall(),
            flown_s=self.monitored_s(task.task_id),
            tool=self._tools.get(task.task_id),
            retryable=retryable,
            reason_code=code,
        )
        log.info(
            "task %s %s %s%s",
            task.task_id,
            result,
            reason,
            " (retryable)" if retryable else "",
            extra={"uav_id": self.uav_id},
        )
        self.outbox.append(outcome)
