"""The SQLite store: schema migrations, durability across reopen, queries."""

from __future__ import annotations

import sqlite3

import pytest

from ground_station.store import MIGRATIONS, Store
from proto import (
    ActionRecord,
    ActionState,
    EventKind,
    GsEvent,
    InspectAction,
    Plan,
    Point,
    WaitTask,
    WaypointSpec,
)


def record(action_id: str, state: ActionState = ActionState.ACCEPTED, **kw) -> ActionRecord:
    action = InspectAction(waypoints=[WaypointSpec(position=Point(x_m=1, y_m=2))])
    return ActionRecord(action_id=action_id, action=action, state=state, created_s=1.0, **kw)


@pytest.fixture
def path(tmp_path):
    return str(tmp_path / "gs.db")


def test_new_file_is_migrated_to_the_newest_schema_in_wal_mode(path):
    store = Store(path)
    assert store.schema_version == len(MIGRATIONS)
    store.close()
    conn = sqlite3.connect(path)
    assert conn.execute("PRAGMA user_version").fetchone()[0] == len(MIGRATIONS)
    assert conn.execute("PRAGMA journal_mode").fetchone()[0] == "wal"


def test_a_file_from_a_newer_build_is_refused(path):
    Store(path).close()
    conn = sqlite3.connect(path)
    conn.execute(f"PRAGMA user_version = {len(MIGRATIONS) + 1}")
    conn.close()
    with pytest.raises(RuntimeError, match="newer than this build"):
        Store(path)


def test_actions_and_transitions_survive_reopening(path):
    store = Store(path)
    store.insert_action(record("a1", request_id="r1"), 1.0)
    planned = record("a1", ActionState.PLANNED, request_id="r1")
    store.update_action(planned, ActionState.ACCEPTED, 2.0)
    store.close()
    store = Store(path)
    assert store.action("a1") == planned
    assert store.action_by_request("r1") == planned
    assert store.transitions("a1") == [
        (None, "accepted", 1.0, ""),
        ("accepted", "planned", 2.0, ""),
    ]
    assert store.actions([ActionState.PLANNED]) == [planned]
    assert store.actions([ActionState.COMPLETED]) == []
    store.insert_action(record("a2"), 3.0)
    store.insert_action(record("a3"), 3.0)
    assert store.action_counts() == {"planned": 1, "accepted": 2}


def test_request_ids_are_unique(path):
    store = Store(path)
    store.insert_action(record("a1", request_id="r1"), 1.0)
    with pytest.raises(sqlite3.IntegrityError):
        store.insert_action(record("a2", request_id="r1"), 1.0)
    assert store.action("a2") is None


def test_latest_plan_per_uav_and_counters(path):
    store = Store(path)
    wait = WaitTask(task_id="w", until_s=3.0)
    store.save_plans([Plan(uav_id="u1", epoch=1), Plan(uav_id="u2", epoch=1)])
    store.save_plans([Plan(uav_id="u1", epoch=2, tasks=[wait])])
    assert {u: p.epoch for u, p in store.latest_plans().items()} == {"u1": 2, "u2": 1}
    assert [store.next_counter("epoch") for _ in range(3)] == [1, 2, 3]
    store.close()
    assert Store(path).counter("epoch") == 3


def test_events_are_paged_by_sequence(path):
    store = Store(path)
    for seq in range(1, 6):
        store.append_events([GsEvent(seq=seq, stamp_s=seq, kind=EventKind.REPLAN)])
    assert [e.seq for e in store.events(after_seq=2, limit=2)] == [3, 4]
    assert store.last_event_seq() == 5
