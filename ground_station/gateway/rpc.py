"""The gateway's only way to the ground station and simulator: typed Zenoh
queries, run off the event loop, with a short timeout (silence -> 503)."""

from __future__ import annotations

from typing import Any

import msgspec

from linecrew_runtime.bus import Bus
from proto.keys import KeySpace, Role
from proto.rpc import Reply, Request
from proto.sim import FaultApplied, SimFault


class GsClient:
    """Sends requests to ``gs/rpc/{op}`` and faults to ``sim/fault``."""

    def __init__(self, bus: Bus, site: str, timeout_s: float) -> None:
        self.bus = bus
        self.keys = KeySpace(site)
        self.timeout_s = timeout_s

    async def call(self, request: Request, reply_type: type[Any] | Any = Reply) -> Any:
        """The ground station's reply (raises ``RequestError`` / ``RequestTimeout``)."""
        key = self.keys.rpc(request.op)
        return await self.bus.query_async(key, request, reply_type, self.timeout_s)

    async def fault(self, fault: SimFault) -> FaultApplied:
        """Forward a fault to the simulator."""
        return await self.bus.query_async(
            self.keys.sim("fault"), fault, FaultApplied, self.timeout_s
        )

    def ground_station_up(self) -> bool:
        """Whether a ground station's liveliness token is visible."""
        return bool(self.bus.alive(self.keys.all_alive(Role.GROUND_STATION), timeout_s=0.5))


def to_json(message: msgspec.Struct | Any) -> bytes:
    """JSON bytes of a wire message (enums as strings)."""
    return msgspec.json.encode(message)
