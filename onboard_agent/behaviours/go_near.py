"""Action "Go near X": take off if landed, then fly to the target in GUIDED."""

from __future__ import annotations

import logging

from onboard_agent import route
from onboard_agent.autopilot.errors import CommandDenied, CommandTimeout
from onboard_agent.autopilot.protocol import GUIDED
from onboard_agent.behaviours.base import AgentBehaviour, CommandSlot, Status
from onboard_agent.context import Context
from onboard_agent.targets import Target
from proto.geo import Point
from proto.telemetry import FlightState

log = logging.getLogger(__name__)

LIFTOFF_TIMEOUT_S = 10.0  # still on the ground this long after takeoff: start over


class GoNear(AgentBehaviour):
    """SUCCESS once the target is reached; RUNNING while taking off and
    flying; FAILURE when the target is unknown or the autopilot refuses.

    On the ground: wait until the autopilot reports it can arm (GPS fix, EKF,
    home, pre-arm checks; at most ``ready_timeout_s``), then GUIDED, arm,
    take off ``takeoff_alt_m`` above the pad it stands on (a roof pad too),
    each command acknowledged before the next.
    In the air: GUIDED if needed, then the position target (or, where the
    straight line passes near a person, the next leg round them: see
    :mod:`onboard_agent.route`), re-sent every ``goto_resend_s`` and
    whenever it moved more than ``follow_threshold_m`` (a walking worker).
    While the traffic report has another airborne UAV within
    ``keep_clear_m`` of the target point, it holds where it is instead (at
    most ``yield_max_s``): a point is flown to once it is free (not for
    targets that keep UAVs apart otherwise: see ``Target.keep_clear``).

    A refused or unanswered mode change, arm or takeoff is retried after a
    backoff (``retry_backoff_s``, doubling up to ``retry_backoff_max_s``), up
    to ``arm_attempts`` times, with the autopilot's reason as feedback; then,
    like a readiness time-out, the behaviour fails *retryable* (the task may
    succeed later or on another UAV)."""

    def __init__(self, target: Target, ctx: Context, name: str | None = None) -> None:
        super().__init__(name or f"Go near {target.label}", ctx)
        self.target = target
        self.command = CommandSlot()
        self._done: set[str] = set()
        self._sent: Point | None = None
        self._sent_at = 0.0
        self._takeoff_at = 0.0
        self._climb_to: float | None = None  # site z of the last takeoff
        self._refusals = 0
        self._retry_at = -1e18
        self._refused = ""
        self._waiting_since: float | None = None
        self._yield_since: float | None = None

    def initialise(self) -> None:
        self.command.cancel()
        self._done.clear()
        self._sent = None
        self._refusals, self._retry_at, self._refused = 0, -1e18, ""
        self._waiting_since = None
        self._yield_since = None
        self.failure_code, self.retryable = "", False

    def update(self) -> Status:
        status = self.command.check()
        if status is Status.RUNNING:
            self.feedback_message = f"waiting for {self.command.label}"
            return status
        if status is Status.FAILURE:
            return self._refusal()
        if self.ctx.clock() < self._retry_at:
            wait = self._retry_at - self.ctx.clock()
            self.feedback_message = f"{self._refused}; retrying in {wait:.0f} s"
            return Status.RUNNING
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

    def _refusal(self) -> Status:
        """A command failed: transient reasons are retried after a backoff."""
        exc, config = self.command.failed, self.ctx.config
        self._refused = self.command.error
        if not isinstance(exc, CommandDenied | CommandTimeout):
            self.feedback_message = self.command.error
            return Status.FAILURE
        self._refusals += 1
        code = "command_timeout" if isinstance(exc, CommandTimeout) else "arm_refused"
        if self.command.failed_label in ("mode", "guided"):
            code = "mode_refused" if code == "arm_refused" else code
        elif self.command.failed_label == "takeoff" and code == "arm_refused":
            code = "takeoff_refused"
        if self._refusals >= config.arm_attempts:
            self.feedback_message = f"{self.command.error} ({self._refusals} tries)"
            self.failure_code, self.retryable = code, True
            return Status.FAILURE
        backoff = config.retry_backoff_s * 2 ** (self._refusals - 1)
        self._retry_at = self.ctx.clock() + min(backoff, config.retry_backoff_max_s)
        self.feedback_message = f"{self.command.error}; retrying in {backoff:.0f} s"
        return Status.RUNNING

    def _take_off(self) -> Status:
        ctx, vehicle = self.ctx, self.ctx.vehicle
        autopilot = ctx.autopilot
        if "takeoff" not in self._done and not vehicle.armed:
            why = vehicle.not_ready_reason
            if why:
                now = ctx.clock()
                if self._waiting_since is None:
                    self._waiting_since = now
                if now - self._waiting_since > ctx.config.ready_timeout_s:
                    self.feedback_message = f"autopilot not ready: {why}"
                    self.failure_code, self.retryable = "not_ready", True
                    return Status.FAILURE
                self.feedback_message = f"waiting for the autopilot: {why}"
                return Status.RUNNING
            self._waiting_since = None
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
            self._climb_to = vehicle.position.z_m + ctx.config.takeoff_alt_m
            self.command.issue("takeoff", autopilot.takeoff(self._climb_to))
            ctx.heading_to = None  # straight up from where it stands
            self._takeoff_at = ctx.clock()
            self.feedback_message = "taking off"
        return Status.RUNNING

    def _fly(self, point: Point) -> Status:
        ctx, vehicle = self.ctx, self.ctx.vehicle
        config = ctx.config
        climb_to = self._climb_to if vehicle.flight_state is FlightState.TAKING_OFF else None
        if climb_to is not None and vehicle.position.z_m < climb_to - 0.1 * config.takeoff_alt_m:
            self.feedback_message = "climbing"
            return Status.RUNNING
        if vehicle.mode != GUIDED and "guided" not in self._done:
            self.command.issue("guided", ctx.autopilot.set_mode(GUIDED))
            self.feedback_message = "setting GUIDED"
            return Status.RUNNING
        now = ctx.clock()
        held = self._yielding(point, now)
        if held is not None:
            return held
        clear_m = ctx.surroundings.site.safety.people_clearance_m + config.route_margin_m
        track = (vehicle.position, point)
        traffic = ctx.traffic.obstacles(ctx.link_clock(), track)
        obstacles = (
            ctx.surroundings.people() + ctx.spots.raised_spots(ctx.surroundings.site) + traffic
        )
        columns = ctx.spots.busy_columns(ctx.surroundings.site, config.approach_alt_m)
        cruise_z = self.target.cruise_z(ctx)
        layer = ctx.spots.layer
        ahead = ctx.traffic.ahead(ctx.link_clock(), track)
        verticals = ctx.traffic.verticals(ctx.link_clock())
        movers = ctx.traffic.movers(ctx.link_clock())
        leg = route.next_leg(
            vehicle.position,
            point,
            obstacles,
            clear_m,
            cruise_z,
            columns,
            layer,
            traffic,
            ahead,
            verticals,
            movers,
        )
        moved = self._sent is None or self._sent.distance_to(leg) > config.follow_threshold_m
        if moved or now - self._sent_at >= config.goto_resend_s:
            ctx.goto(leg)
            self._sent, self._sent_at = leg, now
        distance = self.target.distance(ctx, point)
        self.feedback_message = f"flying to {self.target.label}, {distance:.1f} m"
        return Status.RUNNING

    def _yielding(self, point: Point, now: float) -> Status | None:
        """RUNNING (holding where the UAV is) while another airborne UAV is
        at ``point`` (from the traffic report): as long as it is heard there
        (flying on would fly into it; chaos seed 16: a relief came down onto
        the UAV it relieved, still watching from the slot). One only thought
        to be there (unheard: a hung agent, whose autopilot hovers on at its
        last target) is waited for ``yield_max_s``; then the behaviour fails,
        retryable (``point_occupied``: the ground station replans, and moves
        a lost UAV's slot), never flying into it (chaos seed 12: a UAV sent
        to a waypoint where one with a killed agent hovered met it 0.95 m
        apart). In an emergency the UAV flies on after ``yield_max_s`` (its
        battery decides: two UAVs low on energy holding for each other at a
        station must not both fall, seed 12). None: not holding."""
        ctx, config = self.ctx, self.ctx.config
        radius = max(config.keep_clear_m, ctx.surroundings.site.safety.separation_m)
        here = ctx.vehicle.position
        other = None
        if here.distance_to(point) >= radius and self.target.keep_clear(ctx):
            other = ctx.traffic.holder(point, radius, ctx.link_clock(), here)
        if other is None:
            self._yield_since = ctx.holding_for = None
            return None
        if self._yield_since is None:
            self._yield_since = now
            self._sent = None
            log.info(
                "holding off: %s is at the %s",
                other.uav_id,
                self.target.label,
                extra={"uav_id": ctx.uav_id},
            )
        if (other.unheard or ctx.emergency) and now - self._yield_since > config.yield_max_s:
            ctx.holding_for = None
            if ctx.emergency:
                return None  # no time left: fly on
            self.feedback_message = f"{other.uav_id}, unheard, still at the {self.target.label}"
            self.failure_code, self.retryable = "point_occupied", True
            return Status.FAILURE
        ctx.holding_for = other.uav_id
        if self._sent is None or now - self._sent_at >= config.goto_resend_s:
            self._sent = self._sent or here
            ctx.goto(self._sent)
            self._sent_at = now
        self.feedback_message = f"holding off: {other.uav_id} is at the {self.target.label}"
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        self.ctx.holding_for = None
        if new_status is Status.INVALID:
            self.command.cancel()
