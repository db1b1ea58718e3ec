"""List replies that always fit on the bus: cut into pages of at most
``PAGE_BYTES`` encoded (and at most the caller's ``limit`` items), each
ending with the cursor to continue after (the last item's id)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

import msgspec

from proto.errors import InvalidRequest

T = TypeVar("T")

PAGE_BYTES = 512 * 1024
"""Encoded bytes of the items of one page: half the bus's message limit."""


def page(
    items: Sequence[T], key: Callable[[T], str], cursor: str | None, limit: int | None
) -> tuple[list[T], str | None]:
    """The items after ``cursor`` that fit one page, and the cursor of the
    next page (None when this one is the last)."""
    start = 0
    if cursor is not None:
        ids = [key(item) for item in items]
        if cursor not in ids:
            raise InvalidRequest(f"unknown cursor {cursor!r}", field="cursor")
        start = ids.index(cursor) + 1
    rest = items[start:]
    out = fitting(rest, limit)
    return out, key(out[-1]) if len(out) < len(rest) else None


def fitting(items: Sequence[T], limit: int | None = None) -> list[T]:
    """The longest prefix of ``items`` (at most ``limit``, at least one item)
    whose encoding fits ``PAGE_BYTES``."""
    out: list[T] = []
    size = 0
    for item in items:
        n = len(msgspec.msgpack.encode(item))
        if out and (size + n > PAGE_BYTES or (limit is not None and len(out) >= limit)):
            break
        out.append(item)
        size += n
    return out
