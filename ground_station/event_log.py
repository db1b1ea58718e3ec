"""The ground station's event log: numbered, stored, then published."""

from __future__ import annotations

from collections.abc import Callable

from ground_station.store import Store
from proto.events import EventKind, GsEvent


class EventLog:
    """Emits :class:`GsEvent` with consecutive ``seq`` (continuing after a
    restart), stores each one, and hands it to ``publish``."""

    def __init__(
        self, store: Store, publish: Callable[[GsEvent], None], clock: Callable[[], float]
    ) -> None:
        self._store = store
        self._publish = publish
        self._clock = clock
        self._seq = store.last_event_seq()

    def emit(
        self,
        kind: EventKind,
        *,
        action_id: str | None = None,
        uav_id: str | None = None,
        epoch: int | None = None,
        detail: str = "",
    ) -> GsEvent:
        """Record and publish one event."""
        self._seq += 1
        event = GsEvent(
            seq=self._seq,
            stamp_s=self._clock(),
            kind=kind,
            action_id=action_id,
            uav_id=uav_id,
            epoch=epoch,
            detail=detail,
        )
        self._store.append_event(event)
        self._publish(event)
        return event
