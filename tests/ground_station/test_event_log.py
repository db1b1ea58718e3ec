"""The event log's batches: one transaction for many events, published in
order once stored."""

from __future__ import annotations

from ground_station.event_log import EventLog
from ground_station.store import Store
from proto.events import EventKind


class CountingStore(Store):
    """A real store that counts the transactions events are written in."""

    writes = 0

    def append_events(self, events):
        self.writes += 1
        super().append_events(events)


def test_events_of_a_batch_are_stored_together_then_published_in_order(tmp_path):
    store = CountingStore(str(tmp_path / "gs.db"))
    published = []
    log = EventLog(store, published.append, lambda: 5.0)
    with log.batch():
        for uav in ("uav-1", "uav-2", "uav-3"):
            log.emit(EventKind.PLAN_CHANGED, uav_id=uav, epoch=4)
        assert published == [] and store.events() == []  # nothing said before it is kept
        with log.batch():  # a batch inside a batch is part of it
            log.emit(EventKind.REPLAN, epoch=4)
        assert published == []
    assert store.writes == 1
    assert [e.seq for e in published] == [1, 2, 3, 4]
    assert [e.seq for e in store.events()] == [1, 2, 3, 4]
    log.emit(EventKind.FAULT, detail="alone")
    assert store.writes == 2 and published[-1].seq == 5
