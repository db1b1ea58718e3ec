"""The gateway's action routes: submit, list, read, change and cancel an
action, and turn a crew gesture into one."""

from __future__ import annotations

import uuid

from fastapi import FastAPI, Path, Query, Request, Response

from ground_station.gateway import openapi
from ground_station.gateway.bodies import GestureBody, ModifyBody, SubmitEnvelope
from ground_station.gateway.errors import decode_body
from ground_station.gateway.exchange import json_reply, read_body
from ground_station.gateway.gestures import Vocabulary
from ground_station.gateway.rpc import GsClient, to_json
from proto.base import ID_PATTERN, MAX_REQUEST_ID
from proto.errors import InvalidRequest, RequestTimeout
from proto.mission import Action, ActionState
from proto.rpc import (
    ActionList,
    ActionReply,
    CancelAction,
    GetAction,
    ListActions,
    ModifyAction,
    SubmitAction,
)
from proto.site import Site

MAX_PAGE = 1000  # actions per page
ACTION_ID = Path(pattern=ID_PATTERN, description="an action id, e.g. act-00001")


def add_collection_routes(app: FastAPI, client: GsClient, max_body_bytes: int) -> None:
    """``/v1/actions``: submit an action, list them."""

    @app.post(
        "/v1/actions",
        status_code=201,
        summary="Submit an inspect, monitor or deliver action",
        openapi_extra=openapi.body_schema(Action),
    )
    async def post_action(request: Request) -> Response:
        raw = await read_body(request, max_body_bytes)
        action = decode_body(raw, Action)
        envelope = decode_body(raw, SubmitEnvelope)
        request_id = envelope.request_id or request.headers.get("idempotency-key")
        if request_id is not None and not 0 < len(request_id) <= MAX_REQUEST_ID:
            raise InvalidRequest(
                f"a request id has 1 to {MAX_REQUEST_ID} characters",
                field="Idempotency-Key",
            )
        return await submit(client, action, request_id, envelope.action_id)

    @app.get("/v1/actions", summary="List actions, optionally by state, whole or by page")
    async def list_actions(
        state: str | None = Query(None, description="comma-separated action states"),
        limit: int | None = Query(None, ge=1, le=MAX_PAGE),
        cursor: str | None = Query(None, pattern=ID_PATTERN),
    ) -> Response:
        """Every action (pages fetched in turn), or with ``limit`` / ``cursor``
        one page; the ``Next-Cursor`` header then continues it."""
        states = _states(state)
        if limit is not None or cursor is not None:
            request = ListActions(states=states, limit=limit, cursor=cursor)
            reply = await client.call(request, ActionList)
            headers = {"Next-Cursor": reply.next_cursor} if reply.next_cursor else {}
            return Response(to_json(reply.records), media_type="application/json", headers=headers)
        records, cursor = [], None
        while True:
            reply = await client.call(ListActions(states=states, cursor=cursor), ActionList)
            records += reply.records
            if reply.next_cursor is None:
                return json_reply(records)
            cursor = reply.next_cursor


def add_item_routes(app: FastAPI, client: GsClient, max_body_bytes: int) -> None:
    """``/v1/actions/{action_id}``: read, change or cancel one action."""

    @app.get("/v1/actions/{action_id}", summary="One action")
    async def get_action(action_id: str = ACTION_ID) -> Response:
        return json_reply((await client.call(GetAction(action_id=action_id), ActionReply)).record)

    @app.patch(
        "/v1/actions/{action_id}",
        summary="Change an action's priority or parameters",
        openapi_extra=openapi.body_schema(ModifyBody),
    )
    async def patch_action(request: Request, action_id: str = ACTION_ID) -> Response:
        change = decode_body(await read_body(request, max_body_bytes), ModifyBody)
        modify = ModifyAction(
            request_id=change.request_id or str(uuid.uuid4()),
            action_id=action_id,
            priority=change.priority,
            action=change.action,
        )
        return json_reply((await client.call(modify, ActionReply)).record)

    @app.delete("/v1/actions/{action_id}", summary="Cancel an action")
    async def delete_action(action_id: str = ACTION_ID) -> Response:
        cancel = CancelAction(request_id=f"cancel-{action_id}", action_id=action_id)
        return json_reply((await client.call(cancel, ActionReply)).record)


def add_gesture_route(
    app: FastAPI, client: GsClient, site: Site, vocabulary: Vocabulary, max_body_bytes: int
) -> None:
    """``/v1/gestures``: a crew gesture on ``site``, read through ``vocabulary``,
    submitted as an action."""

    @app.post(
        "/v1/gestures",
        status_code=201,
        summary="Turn a crew gesture into an action",
        openapi_extra=openapi.body_schema(GestureBody),
    )
    async def post_gesture(request: Request) -> Response:
        gesture = decode_body(await read_body(request, max_body_bytes), GestureBody)
        action = vocabulary.action(gesture.gesture, gesture.target, site)
        return await submit(client, action, gesture.request_id, None)


async def submit(
    client: GsClient, action: Action, request_id: str | None, action_id: str | None
) -> Response:
    """Submit ``action`` (a fresh request id if none); a timeout says which
    request id to send again, as the action may have been accepted."""
    request = SubmitAction(
        request_id=request_id or str(uuid.uuid4()), action=action, action_id=action_id
    )
    try:
        reply = await client.call(request, ActionReply)
    except RequestTimeout as exc:  # it may have been accepted: say how to find out
        raise RequestTimeout(
            f"{exc.message}; the action may have been accepted: send the same request "
            "again with this request_id (it is never accepted twice)",
            request_id=request.request_id,
        ) from exc
    return json_reply(reply.record, 201)


def _states(text: str | None) -> list[ActionState]:
    """``?state=a,b`` as action states; an unknown one is a 422 naming them."""
    states = []
    for name in text.split(",") if text else []:
        try:
            states.append(ActionState(name))
        except ValueError:
            known = ", ".join(ActionState)
            raise InvalidRequest(
                f"unknown state {name!r} (one of {known})", field="state"
            ) from None
    return states
