"""Settings of the gateway process, built once in ``main``."""

from __future__ import annotations

import dataclasses
import os
import pathlib
import secrets


@dataclasses.dataclass(frozen=True, kw_only=True)
class GatewaySettings:
    """Gateway settings (flags override ``LINECREW_GATEWAY_*`` / ``LINECREW_TOKEN``)."""

    host: str = "127.0.0.1"  # HTTP bind address
    port: int = 8080  # HTTP port (0: any free port)
    token: str = ""  # bearer token operators must send
    site: str = "default"  # key space of the ground station
    scenario: str = "paper"  # site used to resolve gesture targets
    rpc_timeout_s: float = 2.0  # ground station silent this long -> 503
    max_body_bytes: int = 64 * 1024  # larger request bodies -> 413
    gestures: str | None = None  # a YAML gesture vocabulary (default: the shipped one)


def resolve_token(token: str | None, token_file: str | None) -> str:
    """The bearer token: given, else read from ``token_file``, else
    ``LINECREW_TOKEN``, else a new random one (written to ``token_file`` if set)."""
    if token:
        return token
    if token_file and pathlib.Path(token_file).is_file():
        return pathlib.Path(token_file).read_text().strip()
    if env := os.environ.get("LINECREW_TOKEN"):
        return env
    fresh = secrets.token_urlsafe(24)
    if token_file:
        path = pathlib.Path(token_file)
        path.write_text(fresh + "\n")
        path.chmod(0o600)
    return fresh
