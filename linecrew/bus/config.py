"""Zenoh session settings of one process, and their translation to a
``zenoh.Config``.

Defaults follow what we measured (see the design notes): multicast scouting
off, explicit endpoints, a 1 s transport lease so that a silent peer's
liveliness tokens vanish within about a second, and fast reconnect retries.
"""

from __future__ import annotations

import dataclasses
import json
import os
from typing import Literal

import zenoh

Mode = Literal["client", "peer", "router"]
DEFAULT_ROUTER = "tcp/127.0.0.1:7447"


@dataclasses.dataclass(frozen=True, kw_only=True)
class BusConfig:
    """How a process joins the Zenoh network."""

    mode: Mode = "client"
    connect: tuple[str, ...] = (DEFAULT_ROUTER,)  # endpoints to connect to
    listen: tuple[str, ...] = ()  # endpoints to listen on (router: where clients connect)
    multicast_scouting: bool = False  # discovery by multicast: off so tests never meet by accident
    lease_ms: int = 1000  # transport lease: a silent peer is dropped after this
    keep_alive: int = 4  # keep-alive messages sent per lease period
    retry_ms: int = 250  # first reconnect period (doubles up to 4x)
    connect_attempt_ms: int = 1000  # one attempt to reach a router when opening
    open_timeout_ms: int = 1000  # a transport handshake in flight; zenoh's 10 s default
    # stalls a reconnect started during a short network cut for 10 s
    config_file: str | None = None  # a zenoh json5 file applied before the settings above

    @classmethod
    def from_env(cls, **overrides: object) -> BusConfig:
        """Defaults, then ``LINECREW_ZENOH_CONNECT`` / ``_LISTEN`` (comma
        separated), ``LINECREW_ZENOH_MODE``, ``LINECREW_ZENOH_LEASE_MS``,
        ``LINECREW_ZENOH_CONFIG``, then ``overrides`` (``None`` values ignored)."""
        env: dict[str, object] = {}
        if value := os.environ.get("LINECREW_ZENOH_CONNECT"):
            env["connect"] = _split(value)
        if value := os.environ.get("LINECREW_ZENOH_LISTEN"):
            env["listen"] = _split(value)
        if value := os.environ.get("LINECREW_ZENOH_MODE"):
            env["mode"] = value
        if value := os.environ.get("LINECREW_ZENOH_LEASE_MS"):
            env["lease_ms"] = int(value)
        if value := os.environ.get("LINECREW_ZENOH_CONFIG"):
            env["config_file"] = value
        env.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**env)  # type: ignore[arg-type]

    def to_zenoh(self) -> zenoh.Config:
        """The equivalent ``zenoh.Config``."""
        config = zenoh.Config.from_file(self.config_file) if self.config_file else zenoh.Config()
        retry = {
            "period_init_ms": self.retry_ms,
            "period_max_ms": self.retry_ms * 4,
            "period_increase_factor": 2,
        }
        settings: dict[str, object] = {
            "mode": self.mode,
            "connect/endpoints": list(self.connect) if self.mode != "router" else [],
            "connect/timeout_ms": self.connect_attempt_ms,
            "connect/retry": retry,
            "listen/endpoints": list(self.listen),
            "scouting/multicast/enabled": self.multicast_scouting,
            "transport/link/tx/lease": self.lease_ms,
            "transport/link/tx/keep_alive": self.keep_alive,
            "transport/unicast/open_timeout": self.open_timeout_ms,
        }
        for key, value in settings.items():
            config.insert_json5(key, json.dumps(value))
        return config


def _split(value: str) -> tuple[str, ...]:
    return tuple(part.strip() for part in value.split(",") if part.strip())
