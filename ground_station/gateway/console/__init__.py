"""The operator console: a static page (hand-written HTML, CSS and ES
modules in ``static/``, shipped as package data) served by the gateway at
``/``, its assets under ``/console/``.

The page and its assets are public (they hold no data); every data call the
page makes goes to the ``/v1`` API with the operator's bearer token, which
the page reads from the URL fragment (``/#token=...``, never sent to the
server) or asks for. Nothing is loaded from elsewhere: the page's
Content-Security-Policy allows only this origin.
"""

from __future__ import annotations

from importlib import resources

from fastapi import FastAPI, Response
from starlette.staticfiles import StaticFiles

PAGE_PATH = "/"
STATIC_PREFIX = "/console/"
CSP = (
    "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
    "connect-src 'self'; object-src 'none'; base-uri 'none'; frame-ancestors 'none'"
)


def is_public(path: str) -> bool:
    """Whether ``path`` is the console page or one of its static assets
    (exactly ``/``, or under ``/console/``): the only paths it adds that
    need no token."""
    return path == PAGE_PATH or path.startswith(STATIC_PREFIX)


def static_files() -> list[str]:
    """Names of the shipped static files."""
    root = resources.files(__name__) / "static"
    return sorted(f.name for f in root.iterdir() if f.is_file())


def mount(app: FastAPI) -> None:
    """Serve the page at ``/`` and its assets at ``/console/``."""
    page = (resources.files(__name__) / "static" / "index.html").read_bytes()
    headers = {
        "Content-Security-Policy": CSP,
        "Cache-Control": "no-cache",
        "X-Content-Type-Options": "nosniff",
        "Referrer-Policy": "no-referrer",
    }

    @app.get(PAGE_PATH, include_in_schema=False)
    async def console_page() -> Response:
        return Response(page, media_type="text/html; charset=utf-8", headers=headers)

    app.mount(
        STATIC_PREFIX.rstrip("/"),
        StaticFiles(packages=[(__name__, "static")]),
        name="console",
    )
