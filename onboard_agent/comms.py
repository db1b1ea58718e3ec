"""The agent on the bus: plan in (epoch-fenced by the mission), human poses
and the stations' spot feeds in, ground-station liveliness in, telemetry /
status / outcomes and spot claims out, and its own liveliness token.

After every (re)appearance of a ground-station token the current plan is
queried (``GetPlans`` on the plan key), because samples published during an
outage are lost. Outcomes wait in the mission's outbox while no ground
station is alive and go out when one is.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable

from linecrew_runtime.bus import Bus
from onboard_agent.agent import Agent
from onboard_agent.mission import PlanVerdict
from proto.errors import LinecrewError
from proto.keys import KeySpace, Role, UavTopic
from proto.plan import Plan
from proto.rpc import GetPlans, PlansReply
from proto.spots import StationSpots
from proto.telemetry import HumanPose
from proto.telemetry import Traffic as TrafficReport

log = logging.getLogger(__name__)


class Comms:
    """Binds one :class:`Agent` to the bus; all callbacks run on the loop."""

    def __init__(
        self, bus: Bus, keys: KeySpace, agent: Agent, on_plan: Callable[[], None] = lambda: None
    ) -> None:
        self.bus = bus
        self.on_plan = on_plan  # after every plan offered (the runtime then ticks at once)
        self.keys = keys
        self.agent = agent
        self.uav_id = agent.ctx.uav_id
        self.config = agent.ctx.config
        self._last_status_at = -1e9
        self._resyncs: set[asyncio.Task[None]] = set()
        self.refused = 0  # samples dropped: their payload names another owner than their key

    def _trusted(self, key: str, kind: str, ident: str) -> bool:
        """Whether a sample on ``key`` may speak for ``kind`` ``ident``; counts refusals."""
        if self.keys.owns(key, kind, ident):
            return True
        self.refused += 1
        log.warning("refused a sample: %s does not belong to %s %s", key, kind, ident)
        return False

    async def run(self) -> None:
        """Declare the token and serve until cancelled."""
        keys = self.keys
        with self.bus.declare_token(keys.alive(Role.AGENT, self.uav_id)):
            async with asyncio.TaskGroup() as group:
                group.create_task(self._plans())
                group.create_task(self._poses())
                group.create_task(self._spots())
                group.create_task(self._traffic())
                group.create_task(self._ground_stations())
                group.create_task(self._telemetry())

    async def _plans(self) -> None:
        async with self.bus.subscribe_async(self.keys.plan(self.uav_id), Plan) as sub:
            async for _key, plan in sub:
                self._offer(plan)

    def _offer(self, plan: Plan) -> None:
        """Hand ``plan`` to the agent, then wake its tick loop."""
        self.agent.offer_plan(plan)
        self.on_plan()

    async def _poses(self) -> None:
        async with self.bus.subscribe_async(self.keys.all_human_poses(), HumanPose) as sub:
            async for key, pose in sub:
                if self._trusted(key, "human", pose.worker_id):
                    self.agent.human_pose(pose)

    async def _spots(self) -> None:
        async with self.bus.subscribe_async(self.keys.all_station_spots(), StationSpots) as sub:
            async for key, feed in sub:
                if self._trusted(key, "station", feed.station_id):
                    self.agent.ctx.spots.update(feed)

    async def _traffic(self) -> None:
        async with self.bus.subscribe_async(self.keys.traffic(), TrafficReport) as sub:
            async for _key, report in sub:
                self.agent.ctx.traffic.update(report, self.agent.ctx.link_clock())
                if self.agent.announce(report.generation, report.epoch) is PlanVerdict.ACCEPTED:
                    self.on_plan()  # a held plan now covered: act on it at once

    async def _ground_stations(self) -> None:
        key = self.keys.all_alive(Role.GROUND_STATION)
        async with self.bus.watch_liveliness_async(key) as sub:
            async for token, alive in sub:
                log.info("ground station %s %s", token, "up" if alive else "gone")
                self.agent.ground_station(token, alive)
                if alive:
                    self.agent.mission.redeliver()
                    task = asyncio.create_task(self.resync())
                    self._resyncs.add(task)
                    task.add_done_callback(self._resyncs.discard)

    async def resync(self) -> None:
        """Ask the ground station for our current plan."""
        request = GetPlans(uav_id=self.uav_id)
        try:
            reply: PlansReply = await self.bus.query_async(
                self.keys.plan(self.uav_id), request, PlansReply, self.config.plan_query_timeout_s
            )
        except LinecrewError as exc:
            log.info("plan resync failed: %s", exc, extra={"uav_id": self.uav_id})
            return
        for plan in reply.plans:
            if plan.uav_id == self.uav_id:
                self._offer(plan)

    async def _telemetry(self) -> None:
        period = 1.0 / self.config.telemetry_hz
        while True:
            vehicle = self.agent.ctx.vehicle
            if vehicle.known and vehicle.battery_known:  # never 0 N 0 E, never a 0 % guess
                self.bus.publish(self.keys.telemetry(self.uav_id), self.agent.telemetry())
            await asyncio.sleep(period)

    def after_tick(self, now: float) -> None:
        """Publish the status (1 Hz and on change) and deliverable outcomes."""
        status = self.agent.status()
        changed = self.agent.status_changed(status)
        if changed or now - self._last_status_at >= self.config.status_period_s:
            self.bus.publish(self.keys.status(self.uav_id), status)
            self._last_status_at = now
        claim = self.agent.ctx.spots.claim_due(self.agent.ctx.clock())
        if claim is not None:
            self.bus.publish(self.keys.uav(self.uav_id, UavTopic.SPOT), claim)
        if self.agent.emergency.link_up:
            for outcome in self.agent.mission.take_outcomes():
                self.bus.publish(self.keys.outcome(self.uav_id), outcome)
