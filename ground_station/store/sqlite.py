"""The ground station's durable store: one SQLite file in WAL mode.

Every accepted action and every state transition is committed (fsync'd,
``synchronous=FULL``) before the caller replies, so a ``kill -9`` at any
moment loses nothing that was acknowledged. All methods run on the caller's
thread; the ground station uses it from its event loop only.

A write that fails (disk full, file made read-only, I/O error) is rolled
back whole and raises :class:`StoreUnavailable`: the caller's state must be
left as it was and the write tried again later. A store that cannot be
opened, migrated or written at start raises it too, with the cause.
"""

from __future__ import annotations

import sqlite3
from collections.abc import Iterable
from typing import Any

from ground_station.store.migrations import migrate
from proto import codec
from proto.errors import StoreUnavailable
from proto.events import GsEvent
from proto.mission import ActionRecord, ActionState
from proto.plan import Plan


class Store:
    """Actions, transitions, plans by epoch, events and counters in one file.

    ``failing`` holds the cause of the last failed write until a write
    succeeds again (None while writes succeed)."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.failing: str | None = None
        try:
            self._conn = sqlite3.connect(path, isolation_level=None)
        except sqlite3.Error as exc:
            raise StoreUnavailable(f"the store {path} cannot be used: {exc}") from exc
        try:
            self._conn.execute("PRAGMA journal_mode=WAL")
            self._conn.execute("PRAGMA synchronous=FULL")
            self._conn.execute("PRAGMA foreign_keys=ON")
            self.schema_version = migrate(self._conn)
            self.next_counter("starts")  # proves the file takes writes now
        except (sqlite3.Error, StoreUnavailable) as exc:
            self._conn.close()  # a caller may try again: no handle left open
            raise StoreUnavailable(f"the store {path} cannot be used: {exc}") from exc

    def close(self) -> None:
        """Close the file (a checkpoint folds the WAL back in)."""
        self._conn.close()

    # -- actions -----------------------------------------------------------------

    def insert_action(self, record: ActionRecord, stamp_s: float) -> None:
        """Store a newly accepted action and its first transition, atomically."""
        with self._transaction():
            self._conn.execute(
                "INSERT INTO actions (action_id, request_id, record, state, created_s)"
                " VALUES (?, ?, ?, ?, ?)",
                (
                    record.action_id,
                    record.request_id,
                    codec.encode(record),
                    record.state,
                    record.created_s,
                ),
            )
            self._log_transition(record.action_id, None, record.state, stamp_s, record.reason)

    def update_action(self, record: ActionRecord, previous: ActionState, stamp_s: float) -> None:
        """Replace an action's record; log a transition if its state changed."""
        with self._transaction():
            self._conn.execute(
                "UPDATE actions SET record = ?, state = ? WHERE action_id = ?",
                (codec.encode(record), record.state, record.action_id),
            )
            if record.state != previous:
                self._log_transition(
                    record.action_id, previous, record.state, stamp_s, record.reason
                )

    def action(self, action_id: str) -> ActionRecord | None:
        """One action, or ``None``."""
        row = self._conn.execute(
            "SELECT record FROM actions WHERE action_id = ?", (action_id,)
        ).fetchone()
        return codec.decode(row[0], ActionRecord) if row else None

    def action_by_request(self, request_id: str) -> ActionRecord | None:
        """The action a client request id created, or ``None``."""
        row = self._conn.execute(
            "SELECT record FROM actions WHERE request_id = ?", (request_id,)
        ).fetchone()
        return codec.decode(row[0], ActionRecord) if row else None

    def actions(self, states: Iterable[ActionState] = ()) -> list[ActionRecord]:
        """Actions in creation order, optionally only those in ``states``."""
        wanted = [str(s) for s in states]
        query = "SELECT record FROM actions"
        if wanted:
            query += f" WHERE state IN ({', '.join('?' * len(wanted))})"
        rows = self._conn.execute(query + " ORDER BY created_s, rowid", wanted).fetchall()
        return [codec.decode(row[0], ActionRecord) for row in rows]

    def transitions(self, action_id: str) -> list[tuple[str | None, str, float, str]]:
        """``(from, to, stamp_s, reason)`` of an action, oldest first."""
        return self._conn.execute(
            "SELECT from_state, to_state, stamp_s, reason FROM transitions"
            " WHERE action_id = ? ORDER BY id",
            (action_id,),
        ).fetchall()

    # -- plans, events, counters -------------------------------------------------

    def save_plans(self, plans: Iterable[Plan]) -> None:
        """Store plans (keyed by UAV and epoch) atomically."""
        with self._transaction():
            self._conn.executemany(
                "INSERT OR REPLACE INTO plans (uav_id, epoch, plan) VALUES (?, ?, ?)",
                [(p.uav_id, p.epoch, codec.encode(p)) for p in plans],
            )

    def latest_plans(self) -> dict[str, Plan]:
        """The newest plan of every UAV."""
        rows = self._conn.execute(
            "SELECT plan FROM plans p WHERE epoch = "
            "(SELECT MAX(epoch) FROM plans q WHERE q.uav_id = p.uav_id)"
        ).fetchall()
        plans: list[Plan] = [codec.decode(row[0], Plan) for row in rows]
        return {plan.uav_id: plan for plan in plans}

    def plan_at(self, uav_id: str, epoch: int) -> Plan | None:
        """The plan ``uav_id`` held at ``epoch`` (its newest plan up to it)."""
        row = self._conn.execute(
            "SELECT plan FROM plans WHERE uav_id = ? AND epoch <= ? ORDER BY epoch DESC LIMIT 1",
            (uav_id, epoch),
        ).fetchone()
        return codec.decode(row[0], Plan) if row else None

    def append_events(self, events: list[GsEvent]) -> None:
        """Store events (their ``seq`` must be new) in one transaction: all or none."""
        with self._transaction():
            self._conn.executemany(
                "INSERT INTO events (seq, event) VALUES (?, ?)",
                [(event.seq, codec.encode(event)) for event in events],
            )

    def events(self, after_seq: int = 0, limit: int = 100) -> list[GsEvent]:
        """Events with ``seq > after_seq``, oldest first, at most ``limit``."""
        rows = self._conn.execute(
            "SELECT event FROM events WHERE seq > ? ORDER BY seq LIMIT ?", (after_seq, limit)
        ).fetchall()
        return [codec.decode(row[0], GsEvent) for row in rows]

    def last_event_seq(self) -> int:
        """The highest event ``seq`` stored (0 if none)."""
        return self._conn.execute("SELECT COALESCE(MAX(seq), 0) FROM events").fetchone()[0]

    def next_counter(self, name: str) -> int:
        """Increment and return a named counter (epochs, action numbers)."""
        with self._transaction():
            self._conn.execute(
                "INSERT INTO counters (name, value) VALUES (?, 1)"
                " ON CONFLICT(name) DO UPDATE SET value = value + 1",
                (name,),
            )
            return self.counter(name)

    def action_counts(self) -> dict[str, int]:
        """How many actions are in each state (without decoding them)."""
        rows = self._conn.execute("SELECT state, COUNT(*) FROM actions GROUP BY state")
        return dict(rows.fetchall())

    def counter(self, name: str) -> int:
        """A named counter's value (0 if never incremented)."""
        row = self._conn.execute("SELECT value FROM counters WHERE name = ?", (name,)).fetchone()
        return row[0] if row else 0

    # -- internals -----------------------------------------------------------------

    def _log_transition(
        self, action_id: str, old: str | None, new: str, stamp_s: float, reason: str
    ) -> None:
        self._conn.execute(
            "INSERT INTO transitions (action_id, from_state, to_state, stamp_s, reason)"
            " VALUES (?, ?, ?, ?, ?)",
            (action_id, old, new, stamp_s, reason),
        )

    def _transaction(self) -> Any:
        return _Transaction(self)


class _Transaction:
    """``BEGIN IMMEDIATE`` ... ``COMMIT`` (or ``ROLLBACK`` on error); nests.
    A database error inside is rolled back and raised as StoreUnavailable."""

    def __init__(self, store: Store) -> None:
        self._store = store
        self._conn = store._conn
        self._outer = False

    def __enter__(self) -> None:
        self._outer = not self._conn.in_transaction
        if self._outer:
            self._run("BEGIN IMMEDIATE")

    def __exit__(self, exc_type: object, exc: object, _tb: object) -> None:
        if not self._outer:
            return
        if exc_type is None:
            self._run("COMMIT")
            self._store.failing = None
        elif isinstance(exc, sqlite3.OperationalError):  # the disk, not the data
            self._fail(exc)
        elif self._conn.in_transaction:
            self._conn.execute("ROLLBACK")

    def _run(self, statement: str) -> None:
        try:
            self._conn.execute(statement)
        except sqlite3.OperationalError as exc:
            self._fail(exc)

    def _fail(self, exc: sqlite3.OperationalError) -> None:
        if self._conn.in_transaction:
            self._conn.execute("ROLLBACK")
        self._store.failing = str(exc)
        raise StoreUnavailable(f"the store cannot write: {exc}; nothing was kept") from exc
