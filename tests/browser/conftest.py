"""Browser fixtures: Debian's chromium driven by Playwright for Python.

Playwright's own browser download is not used (``executable_path`` points at
the system chromium); the tests skip, saying why, only when
``/usr/bin/chromium`` is absent (``apt-get install -y chromium``)."""

from __future__ import annotations

import os
import pathlib
from collections.abc import Callable, Iterator

import pytest

CHROMIUM = pathlib.Path(os.environ.get("LINECREW_CHROMIUM", "/usr/bin/chromium"))
VIEWPORT = {"width": 1500, "height": 1300}


@pytest.fixture(scope="module")
def browser() -> Iterator[object]:
    """One chromium per test module. Not per session: the sync Playwright API
    keeps an asyncio loop running on this thread while it is open, and later
    tests that call ``asyncio.run`` would fail."""
    if not CHROMIUM.exists():
        pytest.skip(f"{CHROMIUM} is absent: install it with `apt-get install -y chromium`")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        # --no-sandbox: chromium refuses to start as root with its sandbox
        browser = playwright.chromium.launch(
            executable_path=str(CHROMIUM), args=["--no-sandbox", "--disable-dev-shm-usage"]
        )
        yield browser
        browser.close()


class PageLog:
    """What a page did: console errors, uncaught errors, requests."""

    def __init__(self, page) -> None:
        self.errors: list[str] = []
        self.requests: list = []
        page.on("pageerror", lambda exc: self.errors.append(f"pageerror: {exc}"))
        page.on(
            "console",
            lambda m: self.errors.append(f"console: {m.text}") if m.type == "error" else None,
        )
        page.on("request", lambda request: self.requests.append(request))


@pytest.fixture
def new_page(browser) -> Iterator[Callable[[], tuple[object, PageLog]]]:
    """new_page() -> (page, log): a fresh context each (own sessionStorage)."""
    contexts = []

    def make():
        context = browser.new_context(viewport=VIEWPORT)
        contexts.append(context)
        page = context.new_page()
        page.set_default_timeout(15_000)
        return page, PageLog(page)

    yield make
    for context in contexts:
        context.close()


@pytest.fixture
def artefacts(tmp_path) -> pathlib.Path:
    """Where a test leaves its screenshots."""
    path = tmp_path / "artefacts"
    path.mkdir()
    return path
