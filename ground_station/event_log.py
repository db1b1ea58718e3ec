"""The ground station's event log: numbered, stored, then published."""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Callable, Iterator

from ground_station.store import Store, StoreUnavailable
from proto.events import EventKind, GsEvent

log = logging.getLogger(__name__)


class EventLog:
    """Emits :class:`GsEvent` with consecutive ``seq`` (continuing after a
    restart), stores each one, and hands it to ``publish``.

    An event the store cannot take is still published and kept in order
    until :meth:`flush` (each emit, and the watchdog) stores it: what
    happened is never lost to a full disk, nor does it stop what follows.
    Events emitted in a :meth:`batch` are stored in one transaction and
    published at its end (one disk sync, not one per event)."""

    def __init__(
        self, store: Store, publish: Callable[[GsEvent], None], clock: Callable[[], float]
    ) -> None:
        self._store = store
        self._publish = publish
        self._clock = clock
        self._seq = store.last_event_seq()
        self._unstored: list[GsEvent] = []
        self._said = False  # the store's failure was logged
        self._batch: list[GsEvent] | None = None  # emitted in the open batch, to publish

    @property
    def unstored(self) -> int:
        """Events published but not yet in the store."""
        return len(self._unstored)

    @property
    def last_seq(self) -> int:
        """The newest event's ``seq`` (0 before the first)."""
        return self._seq

    def after(self, after_seq: int, limit: int) -> list[GsEvent]:
        """At most ``limit`` events with ``seq > after_seq``, oldest first: the
        stored ones, then those still waiting for the store (all newer)."""
        waiting = [e for e in self._unstored if e.seq > after_seq]
        return (self._store.events(after_seq, limit) + waiting)[:limit]

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
        self._unstored.append(event)
        if self._batch is not None:
            self._batch.append(event)
            return event
        self.flush()
        self._publish(event)
        return event

    @contextlib.contextmanager
    def batch(self) -> Iterator[None]:
        """Emit several events, stored together and published at the end."""
        if self._batch is not None:  # already in one
            yield
            return
        self._batch = []
        try:
            yield
        finally:
            emitted, self._batch = self._batch, None
            self.flush()
            for event in emitted:
                self._publish(event)

    def flush(self) -> None:
        """Store the events not stored yet, in one transaction, if the store takes them."""
        if not self._unstored:
            return
        try:
            self._store.append_events(self._unstored)
        except StoreUnavailable as exc:
            if not self._said:
                log.error("events wait for the store: %s", exc)
            self._said = True
            return
        self._unstored.clear()
        self._said = False
