"""A fake autopilot and a hand-driven clock for behaviour-tree tests.

The fake acknowledges commands at once (or refuses / leaves them pending on
request) and applies them to its state the way ArduCopter would, but
without time: ``arrive()`` puts the vehicle at its position target.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses

from onboard_agent.autopilot import GUIDED, LAND, CommandDenied, VehicleState
from proto.geo import GeoPoint, Point
from proto.telemetry import FlightState


class FakeClock:
    """A monotonic clock advanced by hand."""

    def __init__(self, start: float = 1000.0) -> None:
        self.now = start

    def __call__(self) -> float:
        return self.now

    def advance(self, seconds: float) -> None:
        self.now += seconds


class FakeAutopilot:
    """Implements :class:`onboard_agent.autopilot.Autopilot` without a vehicle."""

    def __init__(self, position: Point, battery: float = 1.0) -> None:
        self.state = VehicleState(
            position=position,
            battery_fraction=battery,
            mode="STABILIZE",
            flight_state=FlightState.LANDED,
            link_ok=True,
            known=True,
            battery_known=True,
            home=GeoPoint(),  # a ready autopilot: home set, nothing against arming
        )
        self.calls: list[tuple[str, object]] = []
        self.target: Point | None = None
        self.deny: dict[str, str] = {}  # command -> reason to refuse it with
        self.hold: set[str] = set()  # commands left unacknowledged
        self.grabbed = 0
        self.released = 0
        self.gripper_says = ""  # the "Gripper: ..." text a grab answers with

    def update(self, **changes: object) -> None:
        self.state = dataclasses.replace(self.state, **changes)

    def arrive(self) -> None:
        """Put the vehicle at its position target, hovering."""
        if self.target is not None and not self.state.landed:
            self.update(position=self.target)

    def _answer(self, name: str, arg: object = None) -> concurrent.futures.Future[None]:
        self.calls.append((name, arg))
        future: concurrent.futures.Future[None] = concurrent.futures.Future()
        if name in self.hold:
            return future
        if name in self.deny:
            future.set_exception(CommandDenied(name, "DENIED", self.deny[name]))
            return future
        future.set_result(None)
        return future

    def names(self) -> list[str]:
        return [name for name, _ in self.calls]

    def set_mode(self, mode: str):
        future = self._answer("mode", mode)
        if not future.done() or future.exception() is None:
            self.update(mode=mode)
            if mode == LAND and not self.state.landed:
                self.land_now()
        return future

    def arm(self):
        future = self._answer("arm")
        if future.done() and future.exception() is None:
            self.update(armed=True)
        return future

    def takeoff(self, z_m: float):
        future = self._answer("takeoff", z_m)
        if future.done() and future.exception() is None and self.state.armed:
            p = self.state.position
            self.update(
                flight_state=FlightState.FLYING, position=Point(x_m=p.x_m, y_m=p.y_m, z_m=z_m)
            )
        return future

    def goto(self, target: Point):
        self.target = target
        return self._answer("goto", target)

    def land(self):
        future = self._answer("land")
        if future.done() and future.exception() is None:
            self.land_now()
        return future

    def land_now(self) -> None:
        p = self.state.position
        self.update(
            mode=LAND,
            armed=False,
            flight_state=FlightState.LANDED,
            position=Point(x_m=p.x_m, y_m=p.y_m, z_m=0.0),
        )

    def grab(self):
        future = self._answer("grab", self.state.position)
        self.grabbed += 1
        self.update(gripper_text=self.gripper_says)
        return future

    def release(self):
        future = self._answer("release", self.state.position)
        self.released += 1
        return future

    def change_speed(self, speed_mps: float):
        return self._answer("speed", speed_mps)


__all__ = ["GUIDED", "FakeAutopilot", "FakeClock"]
