"""The action records as the ground station keeps them: read (404 if
unknown), change state through the lifecycle (with the events it implies),
save with the clock's stamp. Shared by requests and agents' reports."""

from __future__ import annotations

from collections.abc import Callable

import msgspec

from ground_station.event_log import EventLog
from ground_station.lifecycle import TERMINAL, ActionEvent, next_state
from ground_station.store import Store
from proto.errors import InvalidTransition, NotFound
from proto.events import EventKind
from proto.mission import ActionRecord, ActionState


class ActionBook:
    """Reads and writes action records in the store."""

    def __init__(self, store: Store, events: EventLog, clock: Callable[[], float]) -> None:
        self.store = store
        self.events = events
        self.clock = clock

    def record(self, action_id: str) -> ActionRecord:
        """The record of ``action_id``; :class:`NotFound` if there is none."""
        record = self.store.action(action_id)
        if record is None:
            raise NotFound(f"no action {action_id!r}", field="action_id")
        return record

    def live_record(self, action_id: str) -> ActionRecord:
        """The record of an action that has not ended (else invalid_transition)."""
        record = self.record(action_id)
        if record.state in TERMINAL:
            raise InvalidTransition(f"action {action_id} is {record.state}", field="action_id")
        return record

    def transition(self, record: ActionRecord, event: ActionEvent, reason: str) -> None:
        """Apply a lifecycle event; a change of state is saved and announced."""
        self.update(record, record, event, reason)

    def update(
        self,
        before: ActionRecord,
        after: ActionRecord,
        event: ActionEvent | None,
        reason: str,
    ) -> None:
        """Save ``after`` over ``before`` in one write, in the state ``event``
        leads to (if any); a change of state is announced once saved. An
        event that keeps the state still leaves its reason on the record
        (why an accepted action waits: ``no_capable_uav`` when the only UAVs
        able to do it crashed)."""
        state = after.state if event is None else next_state(before.state, event)
        changed = state != before.state
        if changed or (event is not None and reason != before.reason):
            after = msgspec.structs.replace(after, state=state, reason=reason)
        if not changed and after == before:
            return
        self.save(after, before.state, reason)
        if changed:
            self.events.emit(
                EventKind.ACTION_STATE,
                action_id=before.action_id,
                detail=f"{before.state}->{state}: {reason}",
            )
            if state == ActionState.FAILED:
                self.events.emit(EventKind.ACTION_FAILED, action_id=before.action_id, detail=reason)

    def save(self, record: ActionRecord, previous: ActionState, reason: str) -> None:
        """Store ``record`` (stamped now) over its ``previous`` state."""
        now = self.clock()
        record = msgspec.structs.replace(record, updated_s=now)
        self.store.update_action(record, previous, now)

    def in_force(self, record: ActionRecord | None) -> bool:
        """Whether ``record`` exists and has not ended."""
        return record is not None and record.state not in TERMINAL
