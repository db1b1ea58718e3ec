"""``GET /v1/events``: ground-station events as Server-Sent Events.

With ``?after_seq=N`` the stream first replays stored events after ``N``
(from the ground station's history, page by page), then follows live ones;
every event's ``id:`` is its ``seq`` so a client can resume. The first page
is fetched before the stream starts, so a ground station that cannot answer
gets the usual JSON 503 rather than a stream that breaks off. A comment line
every 15 s keeps proxies from closing an idle stream.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator

from fastapi import Request

from ground_station.gateway.rpc import GsClient, to_json
from proto.errors import LinecrewError
from proto.events import GsEvent
from proto.rpc import GetHistory, HistoryReply

log = logging.getLogger(__name__)

KEEPALIVE_S = 15.0
PAGE = 1000  # events asked for per history page


def _frame(event: GsEvent) -> bytes:
    return b"id: %d\nevent: %s\ndata: %s\n\n" % (
        event.seq,
        str(event.kind).encode(),
        to_json(event),
    )


async def first_history(client: GsClient, after_seq: int) -> HistoryReply:
    """The first page of stored events after ``after_seq`` (raises like any call)."""
    return await client.call(GetHistory(after_seq=after_seq, limit=PAGE), HistoryReply)


async def event_stream(
    client: GsClient, request: Request, after_seq: int | None, history: HistoryReply | None
) -> AsyncIterator[bytes]:
    """Yield the replay after ``after_seq`` that starts with ``history`` (the
    first page; None: live only), then live SSE frames until the client goes
    away."""
    async with client.bus.subscribe_async(client.keys.events(), GsEvent) as live:
        last = -1 if after_seq is None else after_seq
        while history is not None:
            for event in history.events:
                last = event.seq
                yield _frame(event)
            try:  # asked after subscribing, so nothing falls between replay and live
                history = await first_history(client, last)
            except LinecrewError as exc:
                log.warning("event replay stopped after seq %d: %s", last, exc)
                yield b": replay stopped: the ground station did not answer\n\n"
                break
            if not history.events:
                break
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
