"""What every route of the gateway reads and writes: a request body read
whole up to the configured limit, and a wire message as the JSON reply."""

from __future__ import annotations

from typing import Any

from fastapi import Request, Response

from ground_station.gateway.rpc import to_json
from proto.errors import BodyTooLarge


def json_reply(message: Any, status: int = 200) -> Response:
    """``message`` as a JSON reply with ``status``."""
    return Response(to_json(message), status_code=status, media_type="application/json")


async def read_body(request: Request, max_bytes: int) -> bytes:
    """The request's body; :class:`BodyTooLarge` once it passes ``max_bytes``."""
    data = b""
    async for chunk in request.stream():
        data += chunk
        if len(data) > max_bytes:
            raise BodyTooLarge("request body too large")
    return data
