"""What the behaviour tree needs from an autopilot: the seam between the
tree and MAVLink (the real :class:`~onboard_agent.autopilot.link.MavlinkLink`,
or a fake in tests).

Commands never block: each returns a :class:`Pending` (an ``asyncio`` task
or a ``concurrent.futures`` future) that completes when the autopilot
acknowledged it, or with an :class:`~onboard_agent.autopilot.errors.AutopilotError`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any, Protocol

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

    def add_done_callback(self, fn: Callable[[Any], object], /) -> None: ...


EKF_NEEDED = 0x1 | 0x2 | 0x10 | 0x20  # EKF_STATUS_REPORT: attitude, horiz velocity, abs position
EKF_CONST_POS_MODE = 0x80  # no absolute position: the EKF holds a constant position


@dataclasses.dataclass(frozen=True, kw_only=True)
class VehicleState:
    """The autopilot's latest report, in the site's local frame (z: height
    above the site origin, whatever the autopilot's home; see
    :mod:`linecrew.site_frame`).

    Readiness (can it arm?) comes from what ArduCopter reports before arming:
    GPS_RAW_INT's fix, EKF_STATUS_REPORT's flags, HOME_POSITION and the
    pre-arm bit of SYS_STATUS. A report never received counts as no
    objection (-1 / None), except home, position and battery, which must
    have been seen. ``known`` is False while the autopilot has no position
    (no 3-D fix, or lat = lon = 0, as ArduCopter sends before its EKF has an
    origin); ``battery_known`` until the first battery report.
    """

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
    known: bool = False  # a real position has been received (a fix, not lat = lon = 0)
    gripper_text: str = ""  # the autopilot's last "Gripper: ..." text since a gripper command
    battery_known: bool = False  # a battery report has been received
    gps_fix_type: int = -1  # GPS_RAW_INT fix_type (-1: never reported)
    ekf_flags: int = -1  # EKF_STATUS_REPORT flags (-1: never reported)
    home: GeoPoint | None = None  # HOME_POSITION (None: not set yet)
    prearm_ok: bool | None = None  # SYS_STATUS pre-arm check bit (None: not reported)
    arm_text: str = ""  # the autopilot's last "PreArm: ..." / "Arm: ..." text

    @property
    def not_ready_reason(self) -> str:
        """Why the autopilot cannot arm now ("" when it can, as far as it says)."""
        if not self.link_ok:
            return "no autopilot heartbeat"
        if 0 <= self.gps_fix_type < 3:
            return "GPS: no 3-D fix"
        if self.ekf_flags >= 0 and (
            self.ekf_flags & EKF_NEEDED != EKF_NEEDED or self.ekf_flags & EKF_CONST_POS_MODE
        ):
            return "EKF: no absolute position"
        if not self.known:
            return "position unknown"
        if self.home is None:
            return "home not set"
        if not self.battery_known:
            return "battery unknown"
        if self.prearm_ok is False:
            return "pre-arm checks failing" + (f" ({self.arm_text})" if self.arm_text else "")
        return ""

    @property
    def ready(self) -> bool:
        """The autopilot reports nothing that stops it arming."""
        return not self.not_ready_reason

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

    def takeoff(self, z_m: float) -> Pending:
        """Climb straight up to the site height ``z_m``."""
        ...

    def goto(self, target: Point) -> Pending: ...

    def land(self) -> Pending: ...

    def grab(self) -> Pending: ...

    def release(self) -> Pending: ...

    def change_speed(self, speed_mps: float) -> Pending: ...
