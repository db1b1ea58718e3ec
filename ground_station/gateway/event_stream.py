"""``GET /v1/events``: ground-station events as Server-Sent Events.

With ``?after_seq=N`` the stream first replays stored events after ``N``
(from the ground station's history), then follows live ones; every event's
``id:`` is its ``seq`` so a client can resume. A comment line every 15 s
keeps proxies from closing an idle stream.
"""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator

from fastapi import Request

from ground_station.gateway.rpc import GsClient, to_json
from proto.events import GsEvent
from proto.rpc import GetHistory, HistoryReply

KEEPALIVE_S = 15.0


def _frame(event: GsEvent) -> bytes:
    return b"id: %d\nevent: %s\ndata: %s\n\n" % (
        event.seq,
        str(event.kind).encode(),
        to_json(event),
    )


async def event_stream(
    client: GsClient, request: Request, after_seq: int | None
) -> AsyncIterator[bytes]:
    """Yield SSE frames until the client goes away."""
    async with client.bus.subscribe_async(client.keys.events(), GsEvent) as live:
        last = -1
        if after_seq is not None:
            history = await client.call(GetHistory(after_seq=after_seq, limit=1000), HistoryReply)
            for event in history.events:
                last = event.seq
                yield _frame(event)
        yield b": connected\n\n"
        while not await request.is_disconnected():
            try:
                _key, event = await asyncio.wait_for(live.get(), KEEPALIVE_S)
            except TimeoutError:
                yield b": keep-alive\n\n"
                continue
            if event.seq > last:
                last = event.seq
                yield _frame(event)
