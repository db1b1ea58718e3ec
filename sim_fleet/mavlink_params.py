"""The MAVLink parameter protocol, as ArduCopter answers it.

PARAM_REQUEST_LIST sends every parameter to the asker; PARAM_REQUEST_READ
one, by name (or by index when the index is not negative); PARAM_SET stores
a writable value and announces the new PARAM_VALUE to every peer, and a
read-only parameter's value goes back to the asker unchanged.

Messages are built with the endpoint's encoder, so pymavlink stays imported
by ``mavlink_endpoint`` alone.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sim_fleet import autopilot
from sim_fleet.vehicle import Vehicle

Addr = tuple[str, int]
Send = Callable[[list[Addr], Any], None]


class ParamProtocol:
    """One vehicle's parameters over MAVLink; ``peers`` gives the addresses
    that get telemetry (a changed value is announced to them)."""

    def __init__(
        self, mav: Any, send: Send, vehicle: Vehicle, peers: Callable[[], list[Addr]]
    ) -> None:
        self._mav = mav
        self._send = send
        self.vehicle = vehicle
        self._peers = peers

    def request_list(self, _msg: Any, addr: Addr) -> None:
        """PARAM_REQUEST_LIST: every parameter to the asker."""
        for param in self.vehicle.parameters.all():
            self._send([addr], self.value(param.name))

    def request_read(self, msg: Any, addr: Addr) -> None:
        """PARAM_REQUEST_READ: one parameter to the asker (none if unknown)."""
        params = self.vehicle.parameters
        name = msg.param_id if msg.param_index < 0 else None
        if name is None:
            by_index = params.by_index(msg.param_index)
            name = by_index.name if by_index is not None else None
        if name is not None and name in params:
            self._send([addr], self.value(name))

    def set(self, msg: Any, addr: Addr) -> None:
        """PARAM_SET: the stored value to the asker and every peer."""
        if autopilot.set_param(self.vehicle, msg.param_id, msg.param_value):
            peers = list(dict.fromkeys([addr, *self._peers()]))
            self._send(peers, self.value(msg.param_id))
        elif msg.param_id in self.vehicle.parameters:  # read-only: echo the value
            self._send([addr], self.value(msg.param_id))

    def value(self, name: str) -> Any:
        """The PARAM_VALUE message of ``name`` (None if there is no such parameter)."""
        params = self.vehicle.parameters
        p = params.param(name)
        if p is None:
            return None
        return self._mav.param_value_encode(
            p.name.encode("ascii"), p.value, p.type, len(params), params.index_of(name)
        )
