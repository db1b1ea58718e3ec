"""Pages of a list reply: at most the limit, never over the byte budget,
continued after the cursor, the last without one."""

from __future__ import annotations

import pytest

from ground_station.paging import PAGE_BYTES, page
from proto.errors import RequestError


def test_pages_follow_the_cursor_and_respect_limit_and_bytes():
    items = [f"item-{i:04d}" + "x" * 1000 for i in range(1200)]  # ~1.2 MB in all
    key = lambda s: s[:9]  # noqa: E731
    pages, cursor = [], None
    while True:
        got, cursor = page(items, key, cursor, None)
        assert sum(len(i) for i in got) <= PAGE_BYTES
        pages.append(got)
        if cursor is None:
            break
        assert cursor == key(got[-1])
    assert len(pages) == 3 and [i for p in pages for i in p] == items
    five, after = page(items, key, None, 5)
    assert five == items[:5] and after == key(items[4])
    with pytest.raises(RequestError) as bad:
        page(items, key, "nope", 5)
    assert bad.value.field == "cursor"


def test_one_item_over_the_budget_still_makes_a_page():
    [big], cursor = page(["b" * (PAGE_BYTES + 10)], lambda s: "b", None, None)
    assert len(big) > PAGE_BYTES and cursor is None
