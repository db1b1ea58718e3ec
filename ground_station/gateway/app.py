"""The operator REST API (FastAPI). It talks to the ground station only over
Zenoh RPC (:class:`GsClient`); bodies are decoded with msgspec into the
proto types, so the wire contract is the API contract."""

from __future__ import annotations

import secrets
import uuid
from collections.abc import Awaitable, Callable
from typing import Any

from fastapi import Depends, FastAPI, Path, Query, Request, Response
from fastapi.exceptions import RequestValidationError
from fastapi.responses import PlainTextResponse, StreamingResponse
from fastapi_offline import FastAPIOffline
from starlette.exceptions import HTTPException

from ground_station.gateway import console, openapi
from ground_station.gateway.bodies import (
    ControlBody,
    GestureBody,
    Health,
    ModifyBody,
    PlanQuality,
    SubmitEnvelope,
)
from ground_station.gateway.errors import (
    decode_body,
    error_response,
    http_error_handler,
    known_query_only,
    linecrew_error_handler,
    validation_error_handler,
)
from ground_station.gateway.event_stream import event_stream, first_history
from ground_station.gateway.gestures import Vocabulary
from ground_station.gateway.metrics import GatewayCounters, prometheus_text
from ground_station.gateway.rpc import GsClient, to_json
from ground_station.gateway.settings import GatewaySettings
from ground_station.gateway.workers import WorkerPoses
from proto.base import ID_PATTERN, MAX_INT, MAX_REQUEST_ID
from proto.errors import BodyTooLarge, InvalidRequest, LinecrewError, RequestTimeout
from proto.mission import Action, ActionState
from proto.rpc import (
    ActionList,
    ActionReply,
    CancelAction,
    ControlUav,
    FleetReply,
    GetAction,
    GetFleet,
    GetMetrics,
    GetPlans,
    ListActions,
    MetricsReply,
    ModifyAction,
    PlansReply,
    SubmitAction,
)
from proto.sim import SimFault
from proto.site import Site

PUBLIC_PATHS = ("/healthz", "/docs", "/openapi.json", "/static-offline-docs/")
"""Prefixes served without the token. The console's page (exactly ``/``) and
its assets (``/console/...``) are public too, see :func:`console.is_public`;
``/`` is not a prefix here, or every path would be public."""


MAX_PAGE = 1000  # actions per page
ACTION_ID = Path(pattern=ID_PATTERN, description="an action id, e.g. act-00001")
UAV_ID = Path(pattern=ID_PATTERN, description="a UAV id, e.g. uav-1")


def is_public(path: str) -> bool:
    """Whether ``path`` needs no bearer token."""
    return path.startswith(PUBLIC_PATHS) or console.is_public(path)


def create_app(
    settings: GatewaySettings,
    client: GsClient,
    site: Site,
    vocabulary: Vocabulary,
    workers: WorkerPoses,
) -> FastAPI:
    """The gateway application over ``client``; ``workers`` holds the
    tracked poses of the site's people."""
    app = FastAPIOffline(  # /docs with Swagger UI's assets from the package, no CDN
        title="linecrew gateway",
        version="1",
        description="Operator API of a linecrew ground station.",
        redoc_url=None,
        dependencies=[Depends(known_query_only)],
    )
    counters = GatewayCounters()
    app.add_exception_handler(LinecrewError, linecrew_error_handler)
    app.add_exception_handler(HTTPException, http_error_handler)
    app.add_exception_handler(RequestValidationError, validation_error_handler)

    @app.middleware("http")
    async def guard(request: Request, call_next: Callable[[Request], Awaitable[Response]]):
        if not is_public(request.url.path):
            sent = request.headers.get("authorization", "")
            if not secrets.compare_digest(sent.encode(), f"Bearer {settings.token}".encode()):
                counters.count(401)
                return error_response("unauthorized", "missing or wrong bearer token")
        length = request.headers.get("content-length")
        if length and length.isdigit() and int(length) > settings.max_body_bytes:
            counters.count(413)
            return error_response(
                "body_too_large", f"request body over {settings.max_body_bytes} bytes"
            )
        response = await call_next(request)
        counters.count(response.status_code)
        return response

    def json(message: Any, status: int = 200) -> Response:
        return Response(to_json(message), status_code=status, media_type="application/json")

    async def body(request: Request) -> bytes:
        data = b""
        async for chunk in request.stream():
            data += chunk
            if len(data) > settings.max_body_bytes:
                raise BodyTooLarge("request body too large")
        return data

    async def submit(action: Action, request_id: str | None, action_id: str | None) -> Response:
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
        return json(reply.record, 201)

    @app.post(
        "/v1/actions",
        status_code=201,
        summary="Submit an inspect, monitor or deliver action",
        openapi_extra=openapi.body_schema(Action),
    )
    async def post_action(request: Request) -> Response:
        raw = await body(request)
        action = decode_body(raw, Action)
        envelope = decode_body(raw, SubmitEnvelope)
        request_id = envelope.request_id or request.headers.get("idempotency-key")
        if request_id is not None and not 0 < len(request_id) <= MAX_REQUEST_ID:
            raise InvalidRequest(
                f"a request id has 1 to {MAX_REQUEST_ID} characters",
                field="Idempotency-Key",
            )
        return await submit(action, request_id, envelope.action_id)

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
                return json(records)
            cursor = reply.next_cursor

    @app.get("/v1/actions/{action_id}", summary="One action")
    async def get_action(action_id: str = ACTION_ID) -> Response:
        return json((await client.call(GetAction(action_id=action_id), ActionReply)).record)

    @app.patch(
        "/v1/actions/{action_id}",
        summary="Change an action's priority or parameters",
        openapi_extra=openapi.body_schema(ModifyBody),
    )
    async def patch_action(request: Request, action_id: str = ACTION_ID) -> Response:
        change = decode_body(await body(request), ModifyBody)
        modify = ModifyAction(
            request_id=change.request_id or str(uuid.uuid4()),
            action_id=action_id,
            priority=change.priority,
            action=change.action,
        )
        return json((await client.call(modify, ActionReply)).record)

    @app.delete("/v1/actions/{action_id}", summary="Cancel an action")
    async def delete_action(action_id: str = ACTION_ID) -> Response:
        cancel = CancelAction(request_id=f"cancel-{action_id}", action_id=action_id)
        return json((await client.call(cancel, ActionReply)).record)

    @app.post(
        "/v1/gestures",
        status_code=201,
        summary="Turn a crew gesture into an action",
        openapi_extra=openapi.body_schema(GestureBody),
    )
    async def post_gesture(request: Request) -> Response:
        gesture = decode_body(await body(request), GestureBody)
        action = vocabulary.action(gesture.gesture, gesture.target, site)
        return await submit(action, gesture.request_id, None)

    @app.get("/v1/fleet", summary="UAV states, batteries, positions, current tasks")
    async def fleet() -> Response:
        return json((await client.call(GetFleet(), FleetReply)).uavs)

    async def control(request: Request, uav_id: str | None) -> Response:
        command = decode_body(await body(request), ControlBody)
        reply = await client.call(ControlUav(uav_id=uav_id, command=command.command), FleetReply)
        return json(reply.uavs)

    @app.post(
        "/v1/uavs/{uav_id}/control",
        summary="Take a UAV out of the plan: hold, return or land; resume gives it back",
        openapi_extra=openapi.body_schema(ControlBody),
    )
    async def control_uav(request: Request, uav_id: str = UAV_ID) -> Response:
        return await control(request, uav_id)

    @app.post(
        "/v1/fleet/control",
        summary="Command every UAV at once (hold: a fleet stop; resume: back to the plan)",
        openapi_extra=openapi.body_schema(ControlBody),
    )
    async def control_fleet(request: Request) -> Response:
        return await control(request, None)

    @app.get("/v1/plan", summary="Every UAV's timed steps (for a Gantt chart)")
    async def plan() -> Response:
        plans = (await client.call(GetPlans(), PlansReply)).plans
        return json(sorted(plans, key=lambda p: p.uav_id))

    @app.get(
        "/v1/plan/quality",
        summary="The live plan's objective (s), seconds since an improvement was "
        "adopted, and its gap to the best plan seen for the state (null: not known yet)",
    )
    async def plan_quality() -> Response:
        reply = await client.call(GetPlans(), PlansReply)
        quality = PlanQuality(
            objective_s=reply.objective_s,
            improved_ago_s=reply.improved_ago_s,
            gap_to_best=reply.gap_to_best,
        )
        return json(quality)

    @app.get("/v1/events", summary="Ground-station events as Server-Sent Events")
    async def events(
        request: Request,
        after_seq: int | None = Query(None, ge=0, le=MAX_INT, description="replay after this seq"),
    ) -> StreamingResponse:
        history = await first_history(client, after_seq)
        return StreamingResponse(
            event_stream(client, request, after_seq, history), media_type="text/event-stream"
        )

    @app.post(
        "/v1/sim/faults",
        summary="Inject a fault into the simulator (simulation only)",
        openapi_extra=openapi.body_schema(SimFault),
    )
    async def post_fault(request: Request) -> Response:
        fault = decode_body(await body(request), SimFault)
        return json(await client.fault(fault))

    @app.get("/v1/site", summary="The site: towers, lines, stations, tool stations, workers")
    async def get_site() -> Response:
        return json(site)

    @app.get(
        "/v1/workers",
        summary="Where each worker is now (tracked poses; the site's position until one arrives)",
    )
    async def get_workers() -> Response:
        return json(workers.reply())

    @app.get("/healthz", summary="Gateway liveness and whether the ground station is up")
    async def healthz() -> Response:
        return json(Health(ground_station="up" if client.ground_station_up() else "down"))

    @app.get("/metrics", summary="Prometheus metrics", response_class=PlainTextResponse)
    async def metrics() -> PlainTextResponse:
        try:
            values = (await client.call(GetMetrics(), MetricsReply)).values
        except LinecrewError:
            values = None
        return PlainTextResponse(
            prometheus_text(values, counters), media_type="text/plain; version=0.0.4"
        )

    console.mount(app)
    openapi.install(app, is_public)
    return app


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
