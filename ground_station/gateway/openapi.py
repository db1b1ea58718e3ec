"""The gateway's OpenAPI document: request and response schemas from the
msgspec types that encode them (the wire contract is the API contract), the
bearer scheme, and every error an operation can answer, in the one error
shape ``{"error", "message", "field"}``."""

from __future__ import annotations

from typing import Any

import msgspec
from fastapi import FastAPI

from ground_station.gateway.bodies import (
    ControlBody,
    GestureBody,
    Health,
    ModifyBody,
    PlanQuality,
)
from ground_station.gateway.errors import ErrorBody
from ground_station.gateway.workers import WorkersReply
from proto.mission import Action, ActionRecord
from proto.plan import Plan
from proto.rpc import UavState
from proto.sim import FaultApplied, SimFault
from proto.site import Site

BODY_TYPES: tuple[Any, ...] = (Action, ModifyBody, GestureBody, ControlBody, SimFault)
REPLY_TYPES: tuple[Any, ...] = (
    ActionRecord,
    list[ActionRecord],
    list[UavState],
    list[Plan],
    PlanQuality,
    FaultApplied,
    Site,
    WorkersReply,
    Health,
    ErrorBody,
)
_SCHEMAS, _COMPONENTS = msgspec.json.schema_components(
    BODY_TYPES + REPLY_TYPES, ref_template="#/components/schemas/{name}"
)
_SCHEMA = dict(zip(BODY_TYPES + REPLY_TYPES, _SCHEMAS, strict=True))

# (method, path) -> the success reply's type
REPLIES: dict[tuple[str, str], Any] = {
    ("post", "/v1/actions"): ActionRecord,
    ("get", "/v1/actions"): list[ActionRecord],
    ("get", "/v1/actions/{action_id}"): ActionRecord,
    ("patch", "/v1/actions/{action_id}"): ActionRecord,
    ("delete", "/v1/actions/{action_id}"): ActionRecord,
    ("post", "/v1/gestures"): ActionRecord,
    ("get", "/v1/fleet"): list[UavState],
    ("post", "/v1/uavs/{uav_id}/control"): list[UavState],
    ("post", "/v1/fleet/control"): list[UavState],
    ("get", "/v1/plan"): list[Plan],
    ("get", "/v1/plan/quality"): PlanQuality,
    ("post", "/v1/sim/faults"): FaultApplied,
    ("get", "/v1/site"): Site,
    ("get", "/v1/workers"): WorkersReply,
    ("get", "/healthz"): Health,
}
LOCAL_ONLY = {"/v1/site", "/v1/workers", "/healthz", "/metrics"}  # answered without the gs
NAMES_ONE = {("post", "/v1/sim/faults")}  # names a UAV or worker in its body: 404 if unknown
CONFLICTS = {("patch", "/v1/actions/{action_id}"), ("delete", "/v1/actions/{action_id}")}
WHY = {
    401: "missing or wrong bearer token",
    404: "no such action, UAV or worker",
    409: "the action's state does not allow it",
    413: "request body too large",
    422: "invalid body, path or query parameter (field names it)",
    503: "the ground station (or simulator) is unreachable, busy or its store failing",
}


def body_schema(body_type: Any) -> dict[str, Any]:
    """``openapi_extra`` for a route whose body msgspec decodes as ``body_type``."""
    content = {"application/json": {"schema": _SCHEMA[body_type]}}
    return {"requestBody": {"required": True, "content": content}}


def _errors(method: str, path: str, public: bool) -> list[int]:
    statuses = [422]
    if not public:
        statuses.append(401)
    if "{" in path or (method, path) in NAMES_ONE:
        statuses.append(404)
    if (method, path) in CONFLICTS:
        statuses.append(409)
    if method in ("post", "patch"):
        statuses.append(413)
    if path not in LOCAL_ONLY:
        statuses.append(503)
    return sorted(statuses)


def _document(spec: dict[str, Any], is_public: Any) -> dict[str, Any]:
    components = spec.setdefault("components", {})
    schemas = components.setdefault("schemas", {})
    for unused in ("HTTPValidationError", "ValidationError"):
        schemas.pop(unused, None)
    schemas.update(_COMPONENTS)
    components["securitySchemes"] = {"bearer": {"type": "http", "scheme": "bearer"}}
    spec["security"] = [{"bearer": []}]
    error = {"application/json": {"schema": _SCHEMA[ErrorBody]}}
    for path, operations in spec.get("paths", {}).items():
        for method, operation in operations.items():
            public = is_public(path)
            if public:
                operation["security"] = []
            responses = operation.setdefault("responses", {})
            success = next((code for code in responses if code.startswith("2")), "200")
            reply = REPLIES.get((method, path))
            if reply is not None:
                responses[success] = {
                    "description": responses.get(success, {}).get("description", "OK"),
                    "content": {"application/json": {"schema": _SCHEMA[reply]}},
                }
            for status in _errors(method, path, public):
                responses[str(status)] = {"description": WHY[status], "content": error}
    return spec


def install(app: FastAPI, is_public: Any) -> None:
    """Make ``app.openapi()`` return the documented schema (built once)."""
    generate = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None:
            app.openapi_schema = _document(generate(), is_public)
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
