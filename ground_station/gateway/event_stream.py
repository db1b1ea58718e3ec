"""``GET /v1/events``: ground-station events as Server-Sent Events.

With ``?after_seq=N`` the stream first replays stored events after ``N``
(from the ground station's history, page by page), then follows live ones
(read from the history too, so only the ground station's log is sent);
every event's ``id:`` is its ``seq`` so a client can resume. The first page
is fetched before the stream starts, so a ground station that cannot answer
gets the usual JSON 503 rather than a stream that breaks off. A comment line
every 15 s keeps proxies from closing an idle stream.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator, Iterator

from fastapi import Request

from ground_station.gateway.rpc import GsClient, to_json
from proto.base import MAX_INT
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


async def first_history(client: GsClient, after_seq: int | None) -> HistoryReply:
    """The first page of stored events after ``after_seq`` (None: no event,
    only where the log ends); raises like any call."""
    after = MAX_INT if after_seq is None else after_seq
    return await client.call(GetHistory(after_seq=after, limit=PAGE), HistoryReply)


class _Cursor:
    """The last ``seq`` sent, and reading the ground station's history on from it."""

    def __init__(self, client: GsClient, last: int) -> None:
        self.client = client
        self.last = last

    def take(self, page: HistoryReply) -> Iterator[bytes]:
        """The frames of ``page``'s events after the last one sent."""
        for event in page.events:
            if event.seq > self.last:
                self.last = event.seq
                yield _frame(event)

    async def read_on(self) -> AsyncIterator[bytes]:
        """Frames of every stored event after the last one sent, page by page."""
        while True:
            try:
                page = await first_history(self.client, self.last)
            except LinecrewError as exc:
                log.warning("event history unreadable after seq %d: %s", self.last, exc)
                yield b": the ground station did not answer; events resume on the next one\n\n"
                return
            if not page.events:
                return
            for frame in self.take(page):
                yield frame


async def event_stream(
    client: GsClient, request: Request, after_seq: int | None, history: HistoryReply
) -> AsyncIterator[bytes]:
    """Yield the replay after ``after_seq`` that starts with ``history`` (the
    first page; for ``after_seq`` None, only where the log ends), then live
    SSE frames until the client goes away.

    Every frame comes from the ground station's own log: a live sample on
    the events key only says "there is more", and the events after the last
    one sent are then read from the history. So a sample from anyone else,
    whatever its ``seq``, can neither hide an event nor add one."""
    async with client.bus.subscribe_async(client.keys.events(), GsEvent) as live:
        cursor = _Cursor(client, history.last_seq if after_seq is None else after_seq)
        if after_seq is not None:  # subscribed first: nothing falls between replay and live
            for frame in cursor.take(history):
                yield frame
            async for frame in cursor.read_on():
                yield frame
        yield b": connected\n\n"
        while not await request.is_disconnected():
            try:
                await asyncio.wait_for(live.get(), KEEPALIVE_S)
            except TimeoutError:
                yield b": keep-alive\n\n"
                continue
            live.drain()  # one read of the history answers every notice waiting
            async for frame in cursor.read_on():
                yield frame
