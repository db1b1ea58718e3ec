"""A store that cannot write, on a small disk of its own (a real full or
read-only file system): nothing half-kept, new actions refused with 503's
code, what happened meanwhile (a UAV lost) replanned once the disk is freed,
and a clear error, not a traceback, when the store is unusable at start."""

from __future__ import annotations

import os
import subprocess
import time

import pytest

from ground_station.event_log import EventLog
from ground_station.store import Store, StoreUnavailable
from linecrew.bench.light_agent import LightAgent
from linecrew_runtime.bus import Bus
from proto import ActionState, EventKind, GetMetrics, MetricsReply, RequestError
from tests.ground_station.test_service import (
    KEYS,
    SCENARIO,
    UAVS,
    gs_alive,
    gs_args,
    history,
    owner_of,
    settled,
    submit,
    waypoints_of,
)
from tests.ground_station.test_store import record
from tests.support.disk import small_disk
from tests.support.processes import running, start, wait_until


@pytest.fixture
def disk(tmp_path):
    with small_disk(tmp_path / "disk", size_kib=16 * 1024) as d:
        yield d


def test_a_write_to_a_full_disk_keeps_nothing_and_the_store_writes_once_freed(disk):
    store = Store(str(disk.root / "gs.db"))
    disk.fill()
    with pytest.raises(StoreUnavailable) as full:
        store.insert_action(record("a-1"), 1.0)
    assert full.value.code == "store_unavailable" and "full" in str(full.value)
    assert "full" in (store.failing or "")
    assert store.action("a-1") is None and store.actions() == []
    disk.free()
    store.insert_action(record("a-1"), 1.0)
    assert store.failing is None and store.action("a-1") is not None


def test_events_the_store_cannot_take_are_published_and_stored_in_order_later(disk):
    store = Store(str(disk.root / "gs.db"))
    published = []
    log = EventLog(store, published.append, lambda: 5.0)
    log.emit(EventKind.FAULT, detail="before")
    disk.fill()
    log.emit(EventKind.UAV_LOST, uav_id="uav-1")
    log.emit(EventKind.FAULT, detail="during")
    assert [e.seq for e in published] == [1, 2, 3]  # said at once
    assert [e.seq for e in store.events()] == [1] and log.unstored == 2
    assert [e.seq for e in log.after(0, 10)] == [1, 2, 3] and log.last_seq == 3  # all readable
    assert [e.seq for e in log.after(1, 1)] == [2]
    log.flush()  # still full: nothing lost, nothing reordered
    assert log.unstored == 2
    disk.free()
    log.flush()
    assert [e.seq for e in store.events()] == [1, 2, 3] and log.unstored == 0


@pytest.mark.parametrize("how", ["read-only", "full"])
def test_an_unusable_store_at_start_is_a_clear_error(disk, router, how):
    path = disk.root / "gs.db"
    Store(str(path)).close()
    if how == "read-only":
        disk.read_only()
    else:
        disk.fill()
    with pytest.raises(StoreUnavailable, match="cannot be used"):
        Store(str(path))
    env = {**os.environ, "LINECREW_GS_STORE_WAIT_S": "2"}
    begun = time.monotonic()
    done = subprocess.run(
        gs_args(router, str(path)), capture_output=True, text=True, timeout=60, env=env
    )
    assert done.returncode == 1
    assert time.monotonic() - begun >= 2.0  # it tried again before giving up
    assert done.stderr.count("cannot write yet") >= 1, done.stderr
    assert "cannot start" in done.stderr and "Traceback" not in done.stderr, done.stderr
    if how == "read-only":
        disk.read_only(False)


def test_a_ground_station_started_on_a_read_only_store_starts_once_it_writes(
    disk, router, bus_config
):
    path = disk.root / "gs.db"
    Store(str(path)).close()
    disk.read_only()
    gs = start(gs_args(router, str(path)), "gs")
    try:
        wait_until(lambda: "cannot write yet" in gs.output(), 20, "the gs waiting for its store")
        assert gs.alive()
        disk.read_only(False)
        with Bus.open(bus_config) as client:
            wait_until(lambda: gs_alive(client), 20, "the gs up once the store writes")
            assert submit(client, "inspect-loop").record.state == ActionState.ACCEPTED
        assert "cannot start" not in gs.output()
    finally:
        disk.read_only(False)
        gs.stop()


def metric(client: Bus, name: str) -> float | None:
    return client.query(KEYS.rpc("metrics"), GetMetrics(), MetricsReply, 5.0).values.get(name)


def test_a_uav_lost_while_the_disk_is_full_has_its_work_replanned_once_freed(
    router, bus_config, disk
):
    db = str(disk.root / "gs.db")
    with (
        Bus.open(bus_config) as client,
        running(gs_args(router, db), "gs", lambda: gs_alive(client)) as gs,
    ):
        fleet = {u: LightAgent(bus_config, SCENARIO, u) for u in UAVS}
        try:
            wait_until(lambda: all(a.plans for a in fleet.values()), 15, "a first plan each")
            submit(client, "inspect-loop")
            wait_until(lambda: owner_of(fleet, "inspect-loop"), 10, "inspection planned")
            wait_until(lambda: settled(client), 30, "the background improvement done")
            victim = owner_of(fleet, "inspect-loop")
            assert victim is not None
            share = waypoints_of([victim], "inspect-loop")
            others = [a for a in fleet.values() if a is not victim]

            disk.fill()
            with pytest.raises(RequestError) as refused:
                submit(client, "deliver-wrench")
            assert refused.value.code == "store_unavailable"
            victim.go_silent()
            wait_until(lambda: metric(client, "store_failing") == 1.0, 15, "store said failing")
            assert not share <= waypoints_of(others, "inspect-loop")  # never sent unstored

            disk.free()
            wait_until(lambda: share <= waypoints_of(others, "inspect-loop"), 20, "work moved")
            events = history(client).events
            assert [e.seq for e in events] == list(range(1, len(events) + 1))  # none lost
            kinds = [(e.kind, e.uav_id) for e in events]
            assert (EventKind.UAV_LOST, victim.uav_id) in kinds
            faults = [e.detail for e in events if e.kind == EventKind.FAULT]
            assert any("cannot write" in f for f in faults)
            assert any("writes again" in f for f in faults)
            assert submit(client, "deliver-wrench").record.state == ActionState.ACCEPTED
            assert metric(client, "store_failing") == 0.0
        finally:
            for agent in fleet.values():
                agent.close()
        assert gs.stop() == 0, gs.output()
