"""Safe hand-off of items from Zenoh's callback threads to an asyncio loop.

Zenoh callbacks of one session share threads, so they must only hand items
over; :class:`AsyncQueue` does that with ``loop.call_soon_threadsafe`` into a
bounded queue that drops the oldest item when a consumer falls behind.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable
from typing import Generic, TypeVar

T = TypeVar("T")


class AsyncQueue(Generic[T]):
    """A bounded queue fed from any thread, consumed by ``async for``."""

    def __init__(
        self,
        loop: asyncio.AbstractEventLoop,
        maxsize: int = 1000,
        on_overflow: Callable[[], None] | None = None,
    ) -> None:
        self._loop = loop
        self._queue: asyncio.Queue[T] = asyncio.Queue(maxsize)
        self._on_overflow = on_overflow

    def put_threadsafe(self, item: T) -> None:
        """Hand ``item`` to the loop; never blocks, never raises."""
        with contextlib.suppress(RuntimeError):  # loop closed: the consumer is gone
            self._loop.call_soon_threadsafe(self._put, item)

    def _put(self, item: T) -> None:
        if self._queue.full():
            self._queue.get_nowait()
            if self._on_overflow:
                self._on_overflow()
        self._queue.put_nowait(item)

    async def get(self) -> T:
        """The next item, waiting for one."""
        return await self._queue.get()

    def drain(self) -> list[T]:
        """Every item waiting now (none: an empty list), without waiting."""
        items = []
        while not self._queue.empty():
            items.append(self._queue.get_nowait())
        return items

    def __aiter__(self) -> AsyncQueue[T]:
        return self

    async def __anext__(self) -> T:
        return await self._queue.get()
