"""Shapes of the gateway's JSON bodies beyond the proto messages: requests,
and the replies it builds itself."""

from __future__ import annotations

from typing import Literal

import msgspec

from proto.base import Id, Priority, RequestId
from proto.mission import Action
from proto.rpc import Command


class SubmitEnvelope(msgspec.Struct, frozen=True, kw_only=True):
    """Optional fields beside the action in ``POST /v1/actions``."""

    request_id: RequestId | None = None
    action_id: Id | None = None


class ModifyBody(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``PATCH /v1/actions/{id}``: a new priority and/or new parameters."""

    priority: Priority | None = None
    action: Action | None = None
    request_id: RequestId | None = None


class ControlBody(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``POST /v1/uavs/{id}/control`` and ``POST /v1/fleet/control``."""

    command: Command


class GestureBody(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``POST /v1/gestures``: a recognised gesture and what it points at."""

    gesture: str
    target: Id
    request_id: RequestId | None = None


class PlanQuality(msgspec.Struct, frozen=True, kw_only=True):
    """``GET /v1/plan/quality``: the live plan's objective (s), mission seconds
    since an improvement was adopted, its gap to the best plan seen for the
    state (a fraction); null where not known yet."""

    objective_s: float | None
    improved_ago_s: float | None
    gap_to_best: float | None


class Health(msgspec.Struct, frozen=True, kw_only=True):
    """``GET /healthz``: the gateway answers; whether a ground station is up."""

    status: Literal["ok"] = "ok"
    ground_station: Literal["up", "down"]
