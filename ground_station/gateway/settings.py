"""Settings of the gateway process, built once in ``main``."""

from __future__ import annotations

import dataclasses
import os
import pathlib
import secrets

from linecrew_runtime.settings import NOT_FROM_ENV, EnvSettings
from proto.errors import LinecrewError


@dataclasses.dataclass(frozen=True, kw_only=True)
class GatewaySettings(EnvSettings):
    """Gateway settings (flags override ``LINECREW_GATEWAY_*`` variables)."""

    ENV_PREFIX = "LINECREW_GATEWAY_"

    host: str = "127.0.0.1"  # HTTP bind address
    port: int = 8080  # HTTP port (0: any free port)
    scenario: str = "paper"  # its site names gesture targets; its id is the key space
    rpc_timeout_s: float = 2.0  # ground station silent this long -> 503
    max_body_bytes: int = 64 * 1024  # larger request bodies -> 413
    gestures: str | None = None  # a YAML gesture vocabulary (default: the shipped one)
    token: str = dataclasses.field(default="", metadata=NOT_FROM_ENV)  # see resolve_token
    site: str = dataclasses.field(default="default", metadata=NOT_FROM_ENV)  # the scenario's


DEV_TOKEN = "linecrew-dev-token"
"""The token docker-compose.yml falls back to: public, so refused unless
``LINECREW_ALLOW_DEV_TOKEN=1`` says this is a development run."""


class DevTokenRefused(LinecrewError, ValueError):
    """The gateway was given the public development token without the flag."""

    code = "dev_token_refused"


def check_token(token: str) -> str:
    """``token``, unless it is :data:`DEV_TOKEN` and ``LINECREW_ALLOW_DEV_TOKEN``
    is not 1 (then :class:`DevTokenRefused` says what to do)."""
    if token == DEV_TOKEN and os.environ.get("LINECREW_ALLOW_DEV_TOKEN") != "1":
        raise DevTokenRefused(
            f"the token {DEV_TOKEN!r} is public: set LINECREW_TOKEN to a secret "
            "(e.g. `openssl rand -hex 24`), or LINECREW_ALLOW_DEV_TOKEN=1 for a development run"
        )
    return token


def resolve_token(token: str | None, token_file: str | None) -> str:
    """The bearer token: given, else read from ``token_file``, else
    ``LINECREW_TOKEN``, else a new random one (written to ``token_file`` if set)."""
    if token:
        return token
    if token_file and pathlib.Path(token_file).is_file():
        return pathlib.Path(token_file).read_text().strip()
    if env := os.environ.get("LINECREW_TOKEN"):
        return env
    fresh = secrets.token_hex(24)  # never starts with "-" (an option to argparse)
    if token_file:
        path = pathlib.Path(token_file)
        path.write_text(fresh + "\n")
        path.chmod(0o600)
    return fresh
