"""The operator REST API (FastAPI). It talks to the ground station only over
Zenoh RPC (:class:`GsClient`); bodies are decoded with msgspec into the
proto types, so the wire contract is the API contract. The routes are
registered by group (:mod:`.action_routes`, :mod:`.fleet_routes`,
:mod:`.site_routes`); the token guard and the gateway's own health and
metrics are here."""

from __future__ import annotations

import secrets
from collections.abc import Awaitable, Callable

from fastapi import Depends, FastAPI, Request, Response
from fastapi.exceptions import RequestValidationError
from fastapi.responses import PlainTextResponse
from fastapi_offline import FastAPIOffline
from starlette.exceptions import HTTPException

from ground_station.gateway import action_routes, console, fleet_routes, openapi, site_routes
from ground_station.gateway.bodies import Health
from ground_station.gateway.errors import (
    error_response,
    http_error_handler,
    known_query_only,
    linecrew_error_handler,
    validation_error_handler,
)
from ground_station.gateway.exchange import json_reply
from ground_station.gateway.gestures import Vocabulary
from ground_station.gateway.metrics import GatewayCounters, prometheus_text
from ground_station.gateway.rpc import GsClient
from ground_station.gateway.settings import GatewaySettings
from ground_station.gateway.workers import WorkerPoses
from proto.errors import LinecrewError
from proto.rpc import GetMetrics, MetricsReply
from proto.site import Site

PUBLIC_PATHS = ("/healthz", "/docs", "/openapi.json", "/static-offline-docs/")
"""Prefixes served without the token. The console's page (exactly ``/``) and
its assets (``/console/...``) are public too, see :func:`console.is_public`;
``/`` is not a prefix here, or every path would be public."""


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
    _add_guard(app, settings, counters)
    max_body = settings.max_body_bytes
    action_routes.add_collection_routes(app, client, max_body)
    action_routes.add_item_routes(app, client, max_body)
    action_routes.add_gesture_route(app, client, site, vocabulary, max_body)
    fleet_routes.add_fleet_routes(app, client, max_body)
    fleet_routes.add_plan_routes(app, client)
    site_routes.add_event_routes(app, client, max_body)
    site_routes.add_site_routes(app, site, workers)
    _add_service_routes(app, client, counters)
    console.mount(app)
    openapi.install(app, is_public)
    return app


def _add_guard(app: FastAPI, settings: GatewaySettings, counters: GatewayCounters) -> None:
    """The middleware that refuses a request without the bearer token (401)
    or with a declared body over the limit (413), and counts every answer."""

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


def _add_service_routes(app: FastAPI, client: GsClient, counters: GatewayCounters) -> None:
    """``/healthz`` (the gateway's liveness, the ground station's state) and
    ``/metrics`` (the ground station's and the gateway's, for Prometheus)."""

    @app.get("/healthz", summary="Gateway liveness and whether the ground station is up")
    async def healthz() -> Response:
        return json_reply(Health(ground_station="up" if client.ground_station_up() else "down"))

    @app.get("/metrics", summary="Prometheus metrics", response_class=PlainTextResponse)
    async def metrics() -> PlainTextResponse:
        try:
            values = (await client.call(GetMetrics(), MetricsReply)).values
        except LinecrewError:
            values = None
        return PlainTextResponse(
            prometheus_text(values, counters), media_type="text/plain; version=0.0.4"
        )
