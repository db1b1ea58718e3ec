"""Shapes of the gateway's JSON request bodies (beyond the proto messages)."""

from __future__ import annotations

from typing import Annotated

import msgspec

from proto.base import Id
from proto.geo import Point
from proto.mission import Action
from proto.rpc import Command

Positive = Annotated[float, msgspec.Meta(gt=0)]


class SubmitEnvelope(msgspec.Struct, frozen=True, kw_only=True):
    """Optional fields beside the action in ``POST /v1/actions``."""

    request_id: Annotated[str, msgspec.Meta(min_length=1, max_length=128)] | None = None
    action_id: Id | None = None


class ModifyBody(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``PATCH /v1/actions/{id}``: a new priority and/or new parameters."""

    priority: Positive | None = None
    action: Action | None = None
    request_id: str | None = None


class ControlBody(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``POST /v1/uavs/{id}/control`` and ``POST /v1/fleet/control``."""

    command: Command


class GestureBody(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=True):
    """``POST /v1/gestures``: a recognised gesture and what it points at."""

    gesture: str
    target: Id
    request_id: str | None = None


class FaultBody(msgspec.Struct, frozen=True, kw_only=True):
    """Documentation shape of ``POST /v1/sim/faults`` (a proto ``SimFault``)."""

    type: str
    uav_id: Id | None = None
    worker_id: Id | None = None
    position: Point | None = None
