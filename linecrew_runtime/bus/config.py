"""Zenoh session settings of one process, and their translation to a
``zenoh.Config``.

Defaults follow what we measured (see the design notes): multicast scouting
off, explicit endpoints, a 1 s transport lease so that a silent peer's
liveliness tokens vanish within about a second, and fast reconnect retries.
"""

from __future__ import annotations

import dataclasses
import json
from typing import Literal

import zenoh

from linecrew_runtime.settings import EnvSettings

Mode = Literal["client", "peer", "router"]
DEFAULT_ROUTER = "tcp/127.0.0.1:7447"


@dataclasses.dataclass(frozen=True, kw_only=True)
class BusConfig(EnvSettings):
    """How a process joins the Zenoh network (flags override ``LINECREW_ZENOH_*``;
    endpoint lists comma separated, e.g. ``LINECREW_ZENOH_CONNECT=tcp/a:7447,tcp/b:7447``)."""

    ENV_PREFIX = "LINECREW_ZENOH_"

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
    config_file: str | None = dataclasses.field(  # a zenoh json5 file applied before the above
        default=None, metadata={"env": "LINECREW_ZENOH_CONFIG"}
    )

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
