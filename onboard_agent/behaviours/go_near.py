"""Action "Go near X": take off if landed, then fly to the target in GUIDED."""

from __future__ import annotations

from onboard_agent.autopilot.protocol import GUIDED
from onboard_agent.behaviours.base import AgentBehaviour, CommandSlot, Status
from onboard_agent.context import Context
from onboard_agent.targets import Target
from proto.geo import Point
from proto.telemetry import FlightState

LIFTOFF_TIMEOUT_S = 10.0  # still on the ground this long after takeoff: start over


class GoNear(AgentBehaviour):
    """SUCCESS once the target is reached; RUNNING while taking off and
    flying; FAILURE when the target is unknown or the autopilot refuses.

    On the ground: GUIDED, arm, take off to ``takeoff_alt_m``, each command
    acknowledged before the next. In the air: GUIDED if needed, then the
    position target, re-sent every ``goto_resend_s`` and whenever the target
    moved more than ``follow_threshold_m`` (a walking worker)."""

    def __init__(self, target: Target, ctx: Context, name: str | None = None) -> None:
        super().__init__(name or f"Go near {target.label}", ctx)
        self.target = target
        self.command = CommandSlot()
        self._done: set[str] = set()
        self._sent: Point | None = None
        self._sent_at = 0.0
        self._takeoff_at = 0.0

    def initialise(self) -> None:
        self.command.cancel()
        self._done.clear()
        self._sent = None

    def update(self) -> Status:
        status = self.command.check()
        if status is Status.RUNNING:
            self.feedback_message = f"waiting for {self.command.label}"
            return status
        if status is Status.FAILURE:
            self.feedback_message = self.command.error
            return status
        if self.command.label:
            self._done.add(self.command.label)
            self.command.label = ""
        point = self.target.locate(self.ctx)
        if point is None:
            self.feedback_message = f"{self.target.label}: unknown position"
            return Status.FAILURE
        if self.target.reached(self.ctx):
            self.feedback_message = f"near {self.target.label}"
            return Status.SUCCESS
        vehicle = self.ctx.vehicle
        if not vehicle.link_ok or vehicle.flight_state is FlightState.UNKNOWN:
            self.feedback_message = "waiting for the autopilot"
            return Status.RUNNING
        if vehicle.landed:
            return self._take_off()
        return self._fly(point)

    def _take_off(self) -> Status:
        ctx, vehicle = self.ctx, self.ctx.vehicle
        autopilot = ctx.autopilot
        if "takeoff" in self._done:
            if ctx.clock() - self._takeoff_at > LIFTOFF_TIMEOUT_S:
                self._done.clear()  # disarmed on the ground meanwhile: start over
            self.feedback_message = "lifting off"
        elif vehicle.mode != GUIDED and "mode" not in self._done:
            self.command.issue("mode", autopilot.set_mode(GUIDED))
            self.feedback_message = "setting GUIDED"
        elif "arm" not in self._done:
            self.command.issue("arm", autopilot.arm())
            self.feedback_message = "arming"
        else:
            self.command.issue("takeoff", autopilot.takeoff(ctx.config.takeoff_alt_m))
            self._takeoff_at = ctx.clock()
            self.feedback_message = "taking off"
        return Status.RUNNING

    def _fly(self, point: Point) -> Status:
        ctx, vehicle = self.ctx, self.ctx.vehicle
        config = ctx.config
        climbing = vehicle.flight_state is FlightState.TAKING_OFF
        if climbing and vehicle.position.z_m < 0.9 * config.takeoff_alt_m:
            self.feedback_message = "climbing"
            return Status.RUNNING
        if vehicle.mode != GUIDED and "guided" not in self._done:
            self.command.issue("guided", ctx.autopilot.set_mode(GUIDED))
            self.feedback_message = "setting GUIDED"
            return Status.RUNNING
        now = ctx.clock()
        moved = self._sent is None or self._sent.distance_to(point) > config.follow_threshold_m
        if moved or now - self._sent_at >= config.goto_resend_s:
            ctx.autopilot.goto(point)
            self._sent, self._sent_at = point, now
        distance = self.target.distance(ctx, point)
        self.feedback_message = f"flying to {self.target.label}, {distance:.1f} m"
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status is Status.INVALID:
            self.command.cancel()
