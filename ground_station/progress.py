"""How a task outcome moves its action forward (pure functions).

Inspection: the waypoint indices an agent reports as done are merged into
the action; all done -> finished. Monitoring: a task's covered seconds
(measured on board, at most its duration) count for one of the ``k``
slots, so ``monitored_s`` grows by that share; full duration -> finished.
Each ended segment bumps its UAV's segment count, so the next segment has
a new task id.
Delivery: the pick starts the action, the drop finishes it.
"""

from __future__ import annotations

import msgspec

from ground_station.lifecycle import ActionEvent
from proto.mission import ActionRecord, InspectAction, MonitorAction
from proto.plan import DeliverTask, InspectTask, MonitorTask, PickTask, Task
from proto.telemetry import OutcomeResult, TaskOutcome

TAIL_S = 5.0
TAIL_FRACTION = 0.02
"""A monitoring action is finished once what is left is at most the larger
of these (5 s, 2 % of its duration): the seconds a UAV arriving a little
late loses. Relaunching k UAVs, after recharges, for such a tail would end
the action minutes later for no real coverage; the record keeps the true
``monitored_s`` and its progress (below 100 %) shows the shortfall."""


def waived_tail_s(duration_s: float) -> float:
    """The shortfall a monitoring action of ``duration_s`` may end with."""
    return max(TAIL_S, TAIL_FRACTION * duration_s)


def apply_outcome(
    record: ActionRecord, task: Task, outcome: TaskOutcome
) -> tuple[ActionRecord, ActionEvent | None]:
    """The record after ``outcome`` of ``task``, and the lifecycle event it implies."""
    completed = outcome.result == OutcomeResult.COMPLETED
    match (task, record.action):
        case (InspectTask(waypoints=waypoints), InspectAction(waypoints=all_waypoints)):
            planned = {w.index for w in waypoints}
            reported = set(outcome.waypoints_done) & planned
            if completed and not outcome.waypoints_done:
                reported = planned
            done = sorted(set(record.waypoints_done) | reported)
            record = msgspec.structs.replace(
                record, waypoints_done=done, progress=len(done) / len(all_waypoints)
            )
            if len(done) == len(all_waypoints):
                return record, ActionEvent.FINISHED
            return record, ActionEvent.STARTED if reported else None
        case (MonitorTask(duration_s=duration, slots=slots), MonitorAction(duration_s=total)):
            flown = outcome.flown_s or duration * (1.0 if completed else outcome.progress)
            covered = min(flown, duration) / slots
            monitored = min(total, record.monitored_s + covered)
            segments = dict(record.segments)
            if covered > 0 or completed:
                segments[outcome.uav_id] = segments.get(outcome.uav_id, 0) + 1
            record = msgspec.structs.replace(
                record, monitored_s=monitored, progress=monitored / total, segments=segments
            )
            if monitored >= total - waived_tail_s(total):
                return record, ActionEvent.FINISHED
            return record, ActionEvent.STARTED if covered > 0 else None
        case (PickTask(), _) if completed:
            return record, ActionEvent.STARTED
        case (DeliverTask(), _) if completed:
            return msgspec.structs.replace(record, progress=1.0), ActionEvent.FINISHED
    return record, None


def live_monitor_progress(record: ActionRecord, running: list[tuple[MonitorTask, float]]) -> float:
    """The action's progress counting the flown share of the segments being
    flown now (each ``(task, its progress)`` from the agents' statuses)."""
    action = record.action
    if not isinstance(action, MonitorAction):
        return record.progress
    covered = sum(task.duration_s * share / task.slots for task, share in running)
    return min(1.0, (record.monitored_s + covered) / action.duration_s)
