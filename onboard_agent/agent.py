"""One UAV's Agent Behavior Manager, without I/O: the tree, the mission,
the emergency protocol, and the messages that describe them.

:class:`Agent` is driven from outside: :meth:`tick` at ``tick_hz``, plans and
poses handed in, telemetry / status / outcomes taken out. The comms layer
(:mod:`onboard_agent.comms`) does the driving in the real process; tests
drive it by hand with a fake autopilot and fake clocks.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

import py_trees

from onboard_agent import idioms
from onboard_agent.autopilot.protocol import Autopilot
from onboard_agent.config import AgentConfig
from onboard_agent.context import Context
from onboard_agent.emergency import Emergency
from onboard_agent.energy import EnergyModel
from onboard_agent.mission import Mission, PlanVerdict
from onboard_agent.spots import Spots
from onboard_agent.surroundings import Surroundings
from onboard_agent.traffic import Traffic
from proto.errors import LinecrewError
from proto.plan import Plan
from proto.scenario import Scenario
from proto.telemetry import AgentState, AgentStatus, FlightState, HumanPose, Telemetry

log = logging.getLogger(__name__)


class UnknownUav(LinecrewError):
    """The scenario has no UAV (or no type) with this id: fix the command line."""

    code = "unknown_uav"


class Agent:
    """The behaviour tree of one UAV and everything it reads and reports."""

    def __init__(
        self,
        uav_id: str,
        scenario: Scenario,
        autopilot: Autopilot,
        config: AgentConfig | None = None,
        *,
        clock: Callable[[], float] = time.monotonic,
        wall: Callable[[], float] = time.time,
        link_clock: Callable[[], float] = time.monotonic,
    ) -> None:
        uav_type = scenario.fleet.type_of(uav_id)
        if uav_type is None:
            raise UnknownUav(f"no UAV {uav_id!r} in scenario {scenario.name!r}")
        config = config or AgentConfig()
        energy = EnergyModel(uav_type, scenario.fleet.reserve_fraction, config.energy_margin)
        self.ctx = Context(
            uav_id=uav_id,
            config=config,
            autopilot=autopilot,
            mission=Mission(uav_id, scenario.site, wall),
            surroundings=Surroundings(scenario.site, wall),
            spots=Spots(uav_id, scenario, link_clock),
            traffic=Traffic(uav_id),
            energy=energy,
            clock=clock,
            wall=wall,
            link_clock=link_clock,
        )
        self.root = idioms.main_tree(self.ctx)
        self.tree = py_trees.trees.BehaviourTree(self.root)
        self.emergency = Emergency(self.ctx)
        self._autopilot_seen = False  # a heartbeat has been heard since the start
        self._ready_once = False  # the autopilot could arm at least once since the start
        self._last_status: tuple[object, ...] = ()

    @property
    def mission(self) -> Mission:
        return self.ctx.mission

    # -- inputs ---------------------------------------------------------------------

    def offer_plan(self, plan: Plan) -> PlanVerdict:
        """A plan from the ground station (epoch-fenced)."""
        verdict = self.mission.offer(plan)
        self._adopted(verdict)
        return verdict

    def announce(self, generation: str | None, epoch: int) -> PlanVerdict | None:
        """The ground station's generation and newest epoch (its traffic
        report); the verdict on a held plan it now covers, if any."""
        verdict = self.mission.announce(generation, epoch)
        self._adopted(verdict)
        return verdict

    def _adopted(self, verdict: PlanVerdict | None) -> None:
        if verdict is PlanVerdict.ACCEPTED and self.ctx.emergency:
            self.emergency.check()  # an emergency re-reads the queue it now has

    def human_pose(self, pose: HumanPose) -> None:
        self.ctx.surroundings.update_pose(pose)

    def ground_station(self, key: str, alive: bool) -> None:
        self.emergency.ground_station(key, alive)

    # -- ticking --------------------------------------------------------------------

    def tick(self) -> None:
        """One tick: emergency protocol first, then the tree (its root ticked
        directly: ``BehaviourTree.tick`` also walks every node for visitors,
        which the agent has none of, a quarter of an idle agent's CPU)."""
        self.emergency.check()
        self.root.tick_once()

    def active_path(self) -> list[str]:
        """Names from the root to the deepest node that ran this tick."""
        node = self.root.tip()
        path: list[str] = []
        while node is not None:
            path.append(node.name)
            node = node.parent
        return path[::-1]

    # -- reports --------------------------------------------------------------------

    def state(self) -> tuple[AgentState, str]:
        """The agent's state as operators see it, and why."""
        ctx = self.ctx
        self._autopilot_seen |= ctx.vehicle.link_ok
        if not ctx.vehicle.link_ok:
            if not self._autopilot_seen and ctx.config.not_ready_state:
                return AgentState.NOT_READY, "not ready: waiting for the autopilot's heartbeat"
            return AgentState.FAILED, "no autopilot heartbeat"
        if ctx.emergency:
            return AgentState.EMERGENCY, ctx.emergency
        if ctx.recharging or (self.root.tip() is not None and "Recharge" in self.active_path()):
            return AgentState.RECHARGING, ""
        why = self.not_ready()
        self._ready_once |= not why
        if not why:
            self.mission.arming_refused = False
        if why:
            # not ready to fly at all until first ready (the autopilot's start-up), or
            # once a task gave up on arming (motors failed on the pad): its work goes
            # to others until the autopilot can arm again; a refusal short of that (a
            # low battery on the pad, which a recharge cures) is a passing one: the
            # state stays and ``ready`` says it, as arming retries and outcomes do
            state = AgentState.IDLE if self.mission.head is None else AgentState.BUSY
            refusing = not self._ready_once or self.mission.arming_refused
            not_ready = ctx.config.not_ready_state and refusing
            return (AgentState.NOT_READY if not_ready else state), why
        if self.mission.head is None:
            return AgentState.IDLE, ""
        return AgentState.BUSY, ""

    def not_ready(self) -> str:
        """Why the UAV, on the ground and disarmed, could not take off now ("" if it could)."""
        vehicle = self.ctx.vehicle
        if vehicle.armed or not (vehicle.landed or vehicle.flight_state is FlightState.UNKNOWN):
            return ""
        why = vehicle.not_ready_reason
        return f"not ready: {why}" if why else ""

    def status(self) -> AgentStatus:
        state, reason = self.state()
        head = self.mission.head
        return AgentStatus(
            uav_id=self.ctx.uav_id,
            stamp_s=self.ctx.wall(),
            state=state,
            epoch=self.mission.epoch,
            task_id=head.task_id if head is not None else None,
            progress=self.mission.progress(head),
            active_path=self.active_path(),
            queue_length=len(self.mission.tasks),
            reason=reason,
            ready=not self.not_ready() and state is not AgentState.FAILED,
            holding_for=self.ctx.holding_for,
        )

    def status_changed(self, status: AgentStatus) -> bool:
        """Whether ``status`` differs from the last one this was asked about
        (time and progress aside): the 'on change' rule."""
        key = (
            status.state,
            status.epoch,
            status.task_id,
            status.queue_length,
            status.reason,
            status.ready,
            status.holding_for,
            tuple(status.active_path),
        )
        changed = key != self._last_status
        self._last_status = key
        return changed

    def telemetry(self) -> Telemetry:
        ctx, vehicle = self.ctx, self.ctx.vehicle
        return Telemetry(
            uav_id=ctx.uav_id,
            stamp_s=ctx.wall(),
            position=vehicle.position,
            geo=vehicle.geo,
            velocity=vehicle.velocity,
            heading_deg=vehicle.heading_deg,
            battery_wh=ctx.energy.energy_wh(vehicle.battery_fraction),
            battery_fraction=min(1.0, max(0.0, vehicle.battery_fraction)),
            flight_state=vehicle.flight_state,
            armed=vehicle.armed,
            mode=vehicle.mode,
            tool=ctx.tool,
            target=None if vehicle.landed else ctx.heading_to,
        )
