"""Action "Land": settle over the spot, land, wait until landed and disarmed."""

from __future__ import annotations

from onboard_agent.behaviours.base import AgentBehaviour, CommandSlot, Status
from onboard_agent.context import Context
from proto.geo import Point
from proto.telemetry import FlightState


class Land(AgentBehaviour):
    """SUCCESS once on the ground and disarmed (a pad only charges a disarmed
    UAV); FAILURE if the autopilot refuses to land."""

    def __init__(self, ctx: Context, name: str = "Land") -> None:
        super().__init__(name, ctx)
        self.command = CommandSlot()
        self._sent = False

    def initialise(self) -> None:
        self.command.cancel()
        self._sent = False

    def update(self) -> Status:
        status = self.command.check()
        if status is not Status.SUCCESS:
            self.feedback_message = self.command.error or "waiting for land"
            return status
        vehicle = self.ctx.vehicle
        if vehicle.flight_state is FlightState.UNKNOWN or not vehicle.link_ok:
            self.feedback_message = "waiting for the autopilot"
            return Status.RUNNING
        if vehicle.landed:
            if not vehicle.armed:
                self.feedback_message = "landed"
                return Status.SUCCESS
            if not self._sent:  # on the ground but armed (not landed by us): disarm by LAND
                self.command.issue("land", self.ctx.autopilot.land())
                self._sent = True
            self.feedback_message = "waiting for disarm"
            return Status.RUNNING
        if not self._sent:
            if vehicle.speed_mps > self.ctx.config.settle_speed_mps:
                self.feedback_message = "settling before landing"
                return Status.RUNNING
            self.command.issue("land", self.ctx.autopilot.land())
            self._sent = True
            here = vehicle.position  # telemetry says where it comes down: others keep out
            self.ctx.heading_to = Point(x_m=here.x_m, y_m=here.y_m, z_m=0.0)
        self.feedback_message = f"landing, {vehicle.position.z_m:.1f} m"
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status is Status.INVALID:
            self.command.cancel()
