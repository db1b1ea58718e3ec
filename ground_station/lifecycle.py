"""The lifecycle of an action, as an enum of events and a transition table.

::

    accepted -> planned -> in_progress -> completed
        \\           \\           \\-> failed (no UAV can finish it)
         \\-----------\\-----------\\-> cancelled (operator)

A planned or in-progress action goes back to ``accepted`` when a replan
leaves it unplaced (e.g. its UAV was lost and nobody else can take it yet).
"""

from __future__ import annotations

import enum

from proto.errors import InvalidTransition
from proto.mission import ActionState as S


class ActionEvent(enum.StrEnum):
    """What can happen to an action."""

    PLACED = "placed"  # a plan covers it
    UNPLACED = "unplaced"  # the newest plan does not cover it
    STARTED = "started"  # an agent began one of its tasks
    FINISHED = "finished"  # every part is done
    IMPOSSIBLE = "impossible"  # the planner says no UAV can ever do it
    CANCEL = "cancel"  # the operator cancelled it


TERMINAL = frozenset({S.COMPLETED, S.FAILED, S.CANCELLED})

TRANSITIONS: dict[tuple[S, ActionEvent], S] = {
    (S.ACCEPTED, ActionEvent.PLACED): S.PLANNED,
    (S.ACCEPTED, ActionEvent.UNPLACED): S.ACCEPTED,
    (S.ACCEPTED, ActionEvent.IMPOSSIBLE): S.FAILED,
    (S.ACCEPTED, ActionEvent.CANCEL): S.CANCELLED,
    (S.ACCEPTED, ActionEvent.STARTED): S.IN_PROGRESS,
    (S.ACCEPTED, ActionEvent.FINISHED): S.COMPLETED,
    (S.PLANNED, ActionEvent.PLACED): S.PLANNED,
    (S.PLANNED, ActionEvent.UNPLACED): S.ACCEPTED,
    (S.PLANNED, ActionEvent.STARTED): S.IN_PROGRESS,
    (S.PLANNED, ActionEvent.FINISHED): S.COMPLETED,
    (S.PLANNED, ActionEvent.IMPOSSIBLE): S.FAILED,
    (S.PLANNED, ActionEvent.CANCEL): S.CANCELLED,
    (S.IN_PROGRESS, ActionEvent.PLACED): S.IN_PROGRESS,
    (S.IN_PROGRESS, ActionEvent.UNPLACED): S.IN_PROGRESS,
    (S.IN_PROGRESS, ActionEvent.STARTED): S.IN_PROGRESS,
    (S.IN_PROGRESS, ActionEvent.FINISHED): S.COMPLETED,
    (S.IN_PROGRESS, ActionEvent.IMPOSSIBLE): S.FAILED,
    (S.IN_PROGRESS, ActionEvent.CANCEL): S.CANCELLED,
}


def next_state(state: S, event: ActionEvent) -> S:
    """The state after ``event``; raises :class:`InvalidTransition`."""
    try:
        return TRANSITIONS[(state, event)]
    except KeyError:
        raise InvalidTransition(f"cannot {event} an action that is {state}") from None
