"""The gateway's routes about what happens on the site: the ground
station's event stream, simulator faults, the site itself and where its
workers are."""

from __future__ import annotations

from fastapi import FastAPI, Query, Request, Response
from fastapi.responses import StreamingResponse

from ground_station.gateway import openapi
from ground_station.gateway.errors import decode_body
from ground_station.gateway.event_stream import event_stream, first_history
from ground_station.gateway.exchange import json_reply, read_body
from ground_station.gateway.rpc import GsClient
from ground_station.gateway.workers import WorkerPoses
from proto.base import MAX_INT
from proto.sim import SimFault
from proto.site import Site


def add_event_routes(app: FastAPI, client: GsClient, max_body_bytes: int) -> None:
    """``/v1/events`` (Server-Sent Events) and ``/v1/sim/faults`` (injected
    into the simulator)."""

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
        fault = decode_body(await read_body(request, max_body_bytes), SimFault)
        return json_reply(await client.fault(fault))


def add_site_routes(app: FastAPI, site: Site, workers: WorkerPoses) -> None:
    """``/v1/site`` and ``/v1/workers``, answered by the gateway itself."""

    @app.get("/v1/site", summary="The site: towers, lines, stations, tool stations, workers")
    async def get_site() -> Response:
        return json_reply(site)

    @app.get(
        "/v1/workers",
        summary="Where each worker is now (tracked poses; the site's position until one arrives)",
    )
    async def get_workers() -> Response:
        return json_reply(workers.reply())
