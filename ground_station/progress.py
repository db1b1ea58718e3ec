"""How a task outcome moves its action forward (pure functions).

Inspection: the waypoint indices an agent reports as done are merged into
the action; all done -> finished. Monitoring: a task's covered seconds
(its duration times its reported progress) count for one of the ``k``
slots, so ``monitored_s`` grows by that share; full duration -> finished.
Delivery: the pick starts the action, the drop finishes it.
"""

from __future__ import annotations

import msgspec

from ground_station.lifecycle import ActionEvent
from proto.mission import ActionRecord, InspectAction, MonitorAction
from proto.plan import DeliverTask, InspectTask, MonitorTask, PickTask, Task
from proto.telemetry import OutcomeResult, TaskOutcome

_EPS_S = 1e-3


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
            covered = duration * (1.0 if completed else outcome.progress) / slots
            monitored = min(total, record.monitored_s + covered)
            record = msgspec.structs.replace(
                record, monitored_s=monitored, progress=monitored / total
            )
            if monitored >= total - _EPS_S:
                return record, ActionEvent.FINISHED
            return record, ActionEvent.STARTED if covered > 0 else None
        case (PickTask(), _) if completed:
            return record, ActionEvent.STARTED
        case (DeliverTask(), _) if completed:
            return msgspec.structs.replace(record, progress=1.0), ActionEvent.FINISHED
    return record, None
