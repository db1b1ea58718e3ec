"""Counters of what a bus saw and dropped; read by health endpoints and benches."""

from __future__ import annotations

import collections
import dataclasses
import logging
import threading

log = logging.getLogger(__name__)


@dataclasses.dataclass
class BusStats:
    """Thread-safe counters. ``malformed`` counts undecodable samples per key."""

    received: int = 0
    published: int = 0
    overflowed: int = 0
    malformed: collections.Counter[str] = dataclasses.field(default_factory=collections.Counter)
    _lock: threading.Lock = dataclasses.field(default_factory=threading.Lock, repr=False)

    def count_received(self) -> None:
        """One sample decoded and delivered."""
        with self._lock:
            self.received += 1

    def count_published(self) -> None:
        """One message put on the wire."""
        with self._lock:
            self.published += 1

    def count_overflow(self) -> None:
        """One sample dropped because a consumer's queue was full."""
        with self._lock:
            self.overflowed += 1

    def count_malformed(self, key: str, reason: str) -> None:
        """One undecodable sample on ``key``: counted, logged once per key."""
        with self._lock:
            self.malformed[key] += 1
            first = self.malformed[key] == 1
        if first:
            log.warning("dropping malformed sample on %s: %s", key, reason, extra={"key": key})

    def snapshot(self) -> dict[str, object]:
        """A plain-dict copy for reports."""
        with self._lock:
            return {
                "received": self.received,
                "published": self.published,
                "overflowed": self.overflowed,
                "malformed": sum(self.malformed.values()),
            }
