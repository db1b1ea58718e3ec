"""Ground-station events, published on ``gs/events`` and kept in history."""

from __future__ import annotations

import enum

from proto.base import Count, Finite, Id, Message, Text


class EventKind(enum.StrEnum):
    """What happened."""

    ACTION_ACCEPTED = "action_accepted"
    ACTION_CHANGED = "action_changed"
    ACTION_CANCELLED = "action_cancelled"
    ACTION_STATE = "action_state"
    PLAN_CHANGED = "plan_changed"
    REPLAN = "replan"
    ACTION_FAILED = "action_failed"
    HANDOVER = "handover"
    UAV_SILENT = "uav_silent"  # present, unheard past SILENT_AFTER_S: its tasks are unknown
    UAV_HEARD = "uav_heard"  # a silent UAV heard again within the link timeout
    UAV_LOST = "uav_lost"
    UAV_BACK = "uav_back"
    UAV_CRASHED = "uav_crashed"
    UAV_STATE = "uav_state"
    UAV_CONTROL = "uav_control"
    FAULT = "fault"


class GsEvent(Message, frozen=True, kw_only=True):
    """One event. ``seq`` increases by one per event of a ground station."""

    seq: Count
    stamp_s: Finite
    kind: EventKind
    action_id: Id | None = None
    uav_id: Id | None = None
    epoch: Count | None = None
    detail: Text = ""
