"""The action lifecycle table, pair by pair."""

from __future__ import annotations

import itertools

import pytest

from ground_station.lifecycle import (
    TERMINAL,
    TRANSITIONS,
    ActionEvent,
    InvalidTransition,
    next_state,
)
from proto.mission import ActionState as S

EXPECTED = {
    (S.ACCEPTED, ActionEvent.PLACED): S.PLANNED,
    (S.PLANNED, ActionEvent.UNPLACED): S.ACCEPTED,
    (S.PLANNED, ActionEvent.STARTED): S.IN_PROGRESS,
    (S.IN_PROGRESS, ActionEvent.UNPLACED): S.IN_PROGRESS,
    (S.IN_PROGRESS, ActionEvent.FINISHED): S.COMPLETED,
    (S.ACCEPTED, ActionEvent.IMPOSSIBLE): S.FAILED,
    (S.IN_PROGRESS, ActionEvent.CANCEL): S.CANCELLED,
}


@pytest.mark.parametrize(("pair", "target"), EXPECTED.items(), ids=str)
def test_documented_transitions(pair, target):
    assert next_state(*pair) == target


@pytest.mark.parametrize(
    ("state", "event"), list(itertools.product(sorted(TERMINAL), list(ActionEvent)))
)
def test_terminal_states_accept_no_event(state, event):
    with pytest.raises(InvalidTransition, match=f"cannot {event}"):
        next_state(state, event)


def test_every_live_state_can_be_cancelled_and_finished():
    for state in set(S) - TERMINAL:
        assert TRANSITIONS[(state, ActionEvent.CANCEL)] == S.CANCELLED
        assert TRANSITIONS[(state, ActionEvent.FINISHED)] == S.COMPLETED
