"""``linecrew export RUN_DIR --format jsonl``: a run's actions and events as
JSON lines that any tool reads (``jq``, pandas) without linecrew's code.

Each line is one JSON object with a ``record`` field saying what it is:

- ``{"record": "action", "action_id", "action": {...}, "state", "progress",
  "reason", "created_s", "updated_s", ..., "transitions": [{"from", "to",
  "stamp_s", "reason"}]}``, one per action, in submission order;
- ``{"record": "event", "seq", "stamp_s", "kind", "action_id", "uav_id",
  "epoch", "detail"}``, one per ground-station event, in order;
- ``{"record": "outcome", "uav_id", "task_id", "action_id", "result",
  "reason", "stamp_s", ...}``, every task outcome of the flight log, in order.

Times are mission seconds (UNIX seconds times the run's speed-up).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import msgspec

from linecrew.report.data import Run


def _plain(message: msgspec.Struct) -> dict[str, Any]:
    data = msgspec.to_builtins(message)
    data.pop("schema_version", None)
    return data


def records(run: Run) -> Iterator[dict[str, Any]]:
    """The export's objects, actions first, then events, then outcomes."""
    for record in run.actions:
        transitions = [
            {"from": t.from_state, "to": t.to_state, "stamp_s": t.stamp_s, "reason": t.reason}
            for t in run.transitions.get(record.action_id, [])
        ]
        yield {"record": "action", **_plain(record), "transitions": transitions}
    for event in run.events:
        yield {"record": "event", **_plain(event)}
    for line in run.flight:
        if line.get("kind") == "outcome":
            yield {"record": "outcome", **{k: v for k, v in line.items() if k not in ("kind", "t")}}


def jsonl(run: Run) -> Iterator[str]:
    """One JSON text per record."""
    encoder = msgspec.json.Encoder()
    for item in records(run):
        yield encoder.encode(item).decode()
