"""Chaos fixtures: ``netns`` skips the test, with the reason, where this
machine does not allow network namespaces (``ip netns add``, nft)."""

from __future__ import annotations

import pytest

from linecrew.chaos.netns import NetnsError, check_available


@pytest.fixture
def netns() -> None:
    """Skip unless real cuts (network namespaces) are possible here."""
    try:
        check_available()
    except NetnsError as exc:
        pytest.skip(str(exc))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """``chaos_long`` tests run only when the marker is selected (``-m chaos_long``)."""
    if "chaos_long" in (config.getoption("markexpr") or ""):
        return
    skip = pytest.mark.skip(reason="long chaos run: select it with -m chaos_long")
    for item in items:
        if item.get_closest_marker("chaos_long"):
            item.add_marker(skip)
