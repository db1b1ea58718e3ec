"""The gateway's fleet routes: the UAVs' states, an operator's commands to
one UAV or to all of them, and the plan they fly with its quality."""

from __future__ import annotations

from fastapi import FastAPI, Path, Request, Response

from ground_station.gateway import openapi
from ground_station.gateway.bodies import ControlBody, PlanQuality
from ground_station.gateway.errors import decode_body
from ground_station.gateway.exchange import json_reply, read_body
from ground_station.gateway.rpc import GsClient
from proto.base import ID_PATTERN
from proto.rpc import ControlUav, FleetReply, GetFleet, GetPlans, PlansReply

UAV_ID = Path(pattern=ID_PATTERN, description="a UAV id, e.g. uav-1")


def add_fleet_routes(app: FastAPI, client: GsClient, max_body_bytes: int) -> None:
    """``/v1/fleet``, and the control of one UAV (``/v1/uavs/{uav_id}/control``)
    or of the whole fleet (``/v1/fleet/control``)."""

    @app.get("/v1/fleet", summary="UAV states, batteries, positions, current tasks")
    async def fleet() -> Response:
        return json_reply((await client.call(GetFleet(), FleetReply)).uavs)

    async def control(request: Request, uav_id: str | None) -> Response:
        command = decode_body(await read_body(request, max_body_bytes), ControlBody)
        reply = await client.call(ControlUav(uav_id=uav_id, command=command.command), FleetReply)
        return json_reply(reply.uavs)

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


def add_plan_routes(app: FastAPI, client: GsClient) -> None:
    """``/v1/plan`` (every UAV's timed steps) and ``/v1/plan/quality``."""

    @app.get("/v1/plan", summary="Every UAV's timed steps (for a Gantt chart)")
    async def plan() -> Response:
        plans = (await client.call(GetPlans(), PlansReply)).plans
        return json_reply(sorted(plans, key=lambda p: p.uav_id))

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
        return json_reply(quality)
