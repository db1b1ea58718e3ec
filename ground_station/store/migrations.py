"""Versioned schema of the ground station's SQLite store.

Each entry of :data:`MIGRATIONS` upgrades the schema by one version
(``PRAGMA user_version``); entries are only ever appended, never edited.
Message bodies are stored as MessagePack blobs (the wire codec), so the
store evolves with the wire schema.
"""

from __future__ import annotations

import sqlite3

MIGRATIONS: tuple[str, ...] = (
    # 1: actions, their transitions, plans by epoch, events, counters.
    """
    CREATE TABLE actions (
        action_id   TEXT PRIMARY KEY,
        request_id  TEXT UNIQUE,
        record      BLOB NOT NULL,
        state       TEXT NOT NULL,
        created_s   REAL NOT NULL
    );
    CREATE TABLE transitions (
        id          INTEGER PRIMARY KEY AUTOINCREMENT,
        action_id   TEXT NOT NULL REFERENCES actions(action_id),
        from_state  TEXT,
        to_state    TEXT NOT NULL,
        stamp_s     REAL NOT NULL,
        reason      TEXT NOT NULL DEFAULT ''
    );
    CREATE INDEX transitions_by_action ON transitions(action_id);
    CREATE TABLE plans (
        uav_id      TEXT NOT NULL,
        epoch       INTEGER NOT NULL,
        plan        BLOB NOT NULL,
        PRIMARY KEY (uav_id, epoch)
    );
    CREATE TABLE events (
        seq         INTEGER PRIMARY KEY,
        event       BLOB NOT NULL
    );
    CREATE TABLE counters (
        name        TEXT PRIMARY KEY,
        value       INTEGER NOT NULL
    );
    """,
)


def migrate(conn: sqlite3.Connection) -> int:
    """Bring ``conn`` to the newest schema; returns the version reached.

    Raises ``RuntimeError`` if the file comes from a newer linecrew."""
    version = conn.execute("PRAGMA user_version").fetchone()[0]
    if version > len(MIGRATIONS):
        raise RuntimeError(
            f"store schema version {version} is newer than this build ({len(MIGRATIONS)})"
        )
    for number, script in enumerate(MIGRATIONS[version:], start=version + 1):
        conn.executescript(f"BEGIN;\n{script}\nPRAGMA user_version = {number};\nCOMMIT;")
    return len(MIGRATIONS)
