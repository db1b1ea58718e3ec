"""What the behaviour tree needs from an autopilot: the seam between the
tree and MAVLink (the real :class:`~onboard_agent.autopilot.link.MavlinkLink`,
or a fake in tests).

Commands never block: each returns a :class:`Pending` (an ``asyncio`` task
or a ``concurrent.futures`` future) that completes when the autopilot
acknowledged it, or with an :class:`~onboard_agent.autopilot.errors.AutopilotError`.
"""

from __future__ import annotations

import dataclasses
from typing import Protocol

from proto.geo import GeoPoint, Point, Vector
from proto.telemetry import FlightState

GUIDED = "GUIDED"
_ORIGIN = Point(x_m=0.0, y_m=0.0, z_m=0.0)
_NOWHERE = GeoPoint()
_STILL = Vector()
LAND = "LAND"


class Pending(Protocol):
    """A command in flight (satisfied by asyncio tasks and concurrent futures)."""

    def done(self) -> bool: ...

    def cancelled(self) -> bool: ...

    def exception(self) -> BaseException | None: ...

    def cancel(self) -> bool: ...


@dataclasses.dataclass(frozen=True, kw_only=True)
class VehicleState:
    """The autopilot's latest report, in the site's local frame."""

    position: Point = _ORIGIN
    geo: GeoPoint = _NOWHERE
    velocity: Vector = _STILL
    heading_deg: float = 0.0
    battery_fraction: float = 0.0
    charging: bool = False
    armed: bool = False
    mode: str = ""
    flight_state: FlightState = FlightState.UNKNOWN
    link_ok: bool = False  # heartbeats arriving
    known: bool = False  # a position has been received
    gripper_text: str = ""  # the autopilot's last "Gripper: ..." text since a gripper command

    @property
    def landed(self) -> bool:
        return self.flight_state is FlightState.LANDED

    @property
    def speed_mps(self) -> float:
        v = self.velocity
        return float((v.east_mps**2 + v.north_mps**2 + v.up_mps**2) ** 0.5)


class Autopilot(Protocol):
    """Commands and state of one vehicle."""

    @property
    def state(self) -> VehicleState: ...

    def set_mode(self, mode: str) -> Pending: ...

    def arm(self) -> Pending: ...

    def takeoff(self, alt_m: float) -> Pending: ...

    def goto(self, target: Point) -> Pending: ...

    def land(self) -> Pending: ...

    def grab(self) -> Pending: ...

    def release(self) -> Pending: ...

    def change_speed(self, speed_mps: float) -> Pending: ...
