"""The agent process at run time: the MAVLink link, the bus, the comms and
the tick loop, started together and stopped together."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Awaitable

from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.clock import mission_clock
from onboard_agent.agent import Agent
from onboard_agent.autopilot.link import MavlinkLink
from onboard_agent.comms import Comms
from onboard_agent.config import AgentConfig
from proto.geo import SiteFrame
from proto.keys import KeySpace
from proto.scenario import Scenario

log = logging.getLogger(__name__)


class Wakeup:
    """A sleep that :meth:`set` ends early (a plan arrived: tick at once)."""

    def __init__(self) -> None:
        self._future: asyncio.Future[None] | None = None

    def set(self) -> None:
        """End the current sleep, if any."""
        if self._future is not None and not self._future.done():
            self._future.set_result(None)

    async def sleep(self, delay_s: float) -> None:
        """Sleep ``delay_s`` seconds or until :meth:`set`."""
        loop = asyncio.get_running_loop()
        self._future = loop.create_future()
        timer = loop.call_later(delay_s, self.set)
        try:
            await self._future
        finally:
            timer.cancel()
            self._future = None


async def tick_loop(agent: Agent, comms: Comms, wakeup: Wakeup) -> None:
    """Tick at ``tick_hz`` on the monotonic clock (no drift, no bursts), and
    once more at once when ``wakeup`` is set: a new plan starts (and shows
    in the status) without waiting for the next tick."""
    period = 1.0 / agent.ctx.config.tick_hz
    next_at = time.monotonic()
    while True:
        try:
            agent.tick()
        except Exception:  # a bug in one behaviour must not stop the UAV being reported
            log.exception("tick failed", extra={"uav_id": agent.ctx.uav_id})
        now = time.monotonic()
        comms.after_tick(now)
        if now >= next_at:  # a tick on the schedule, not an extra one
            next_at = max(next_at + period, now)
        await wakeup.sleep(max(0.0, next_at - time.monotonic()))


async def run_agent(
    uav_id: str,
    scenario: Scenario,
    autopilot_url: str,
    bus_config: BusConfig,
    config: AgentConfig,
    stop: Awaitable[None],
    site: str | None = None,
    speedup: float = 1.0,
    signing_key: bytes | None = None,
) -> None:
    """Fly ``uav_id`` until ``stop`` completes; then stop ticking and close
    the bus and the MAVLink link. Keys use ``site`` (default: the scenario's).
    Task durations and plan times run on the mission clock (``speedup``);
    link timeouts on real time; telemetry keeps its rate in mission time
    (:meth:`AgentConfig.at_speedup`). With ``signing_key`` the MAVLink link is signed."""
    config = config.at_speedup(speedup)
    frame = SiteFrame(scenario.site.origin)
    link = MavlinkLink(autopilot_url, frame, config, signing_key=signing_key)
    agent = Agent(
        uav_id,
        scenario,
        link,
        config,
        clock=lambda: time.monotonic() * speedup,
        wall=mission_clock(speedup),
    )
    bus = await asyncio.to_thread(Bus.open, bus_config)
    link.start()
    try:
        wakeup = Wakeup()
        comms = Comms(bus, KeySpace(site or scenario.site.id), agent, wakeup.set)
        tasks = [
            asyncio.create_task(link.run(), name="mavlink"),
            asyncio.create_task(comms.run(), name="comms"),
            asyncio.create_task(tick_loop(agent, comms, wakeup), name="ticks"),
        ]
        log.info("agent %s up, autopilot %s", uav_id, autopilot_url, extra={"uav_id": uav_id})
        stopper = asyncio.ensure_future(stop)
        await asyncio.wait([stopper, *tasks], return_when=asyncio.FIRST_COMPLETED)
        for task in [stopper, *tasks]:
            task.cancel()
        for task in tasks:
            with contextlib.suppress(asyncio.CancelledError):
                await task  # re-raises a component's crash
    finally:
        link.close()
        bus.close()
        log.info("agent %s stopped", uav_id, extra={"uav_id": uav_id})
