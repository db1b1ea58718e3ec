"""What an adopted plan means for each action in force: placed (wholly or
partly), unplaced until the fleet's state changes, or impossible (why it is
unplaced no change of fleet state can cure: the action fails)."""

from __future__ import annotations

from ground_station import planner as pl
from ground_station.lifecycle import ActionEvent
from proto.mission import ActionRecord

IMPOSSIBLE = frozenset({"unreachable_with_full_battery", "unknown_tool"})
"""Unplaced reasons that no change of fleet state can cure: the action fails."""


def placement_events(
    records: list[ActionRecord], tasks: dict[str, list], result: pl.Solution
) -> dict[str, tuple[ActionEvent, str]]:
    """What the adopted plan means for each of ``records`` (its ``tasks`` per
    UAV, planned as ``result``): placed (wholly or partly), unplaced for now,
    or impossible; with the words for its event."""
    placed = {t.action_id for plan_tasks in tasks.values() for t in plan_tasks if t.action_id}
    unplaced: dict[str, list[pl.Unplaced]] = {}
    for item in result.unplaced:
        unplaced.setdefault(item.action_id, []).append(item)
    events: dict[str, tuple[ActionEvent, str]] = {}
    for record in records:
        missing = unplaced.get(record.action_id, [])
        reasons = ", ".join(sorted({m.reason for m in missing}))
        if record.action_id in placed:
            events[record.action_id] = (
                ActionEvent.PLACED,
                f"partly unplaced: {reasons}" if missing else "planned",
            )
        elif any(m.reason in IMPOSSIBLE for m in missing):
            events[record.action_id] = (ActionEvent.IMPOSSIBLE, reasons)
        else:
            events[record.action_id] = (ActionEvent.UNPLACED, reasons or "not planned")
    return events
