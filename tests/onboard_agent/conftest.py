"""Integration fixtures: a sim_fleet vehicle over real MAVLink (and a link
flying it in-process), the agent as a real process, and a test-owned
"ground station" on the real router."""

from __future__ import annotations

import asyncio
import sys
import threading
import time

import msgspec
import pytest

from linecrew_runtime.bus import Bus
from linecrew_runtime.scenarios import load
from onboard_agent import Agent, AgentConfig
from onboard_agent.autopilot.link import MavlinkLink
from proto.geo import SiteFrame
from proto.keys import KeySpace, Role
from proto.plan import Plan
from proto.scenario import Scenario
from proto.site import BatterySwap
from proto.telemetry import AgentStatus, FlightState, TaskOutcome
from sim_fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.params import AutopilotParams
from tests.support.processes import running, wait_until

SPEEDUP = 10.0
KEYS = KeySpace("default")
LINK_CONFIG = AgentConfig(command_ack_timeout_s=0.3, command_retries=1, heartbeat_timeout_s=0.5)


def fast_scenario():
    """The paper's world; C1 (uav-1's home pad) swaps batteries in 20 s so
    that recharges stay short."""
    scenario = load("paper")
    stations = [
        msgspec.structs.replace(s, recharge=BatterySwap(swap_s=20.0)) if s.id == "C1" else s
        for s in scenario.site.stations
    ]
    site = msgspec.structs.replace(scenario.site, stations=stations)
    return msgspec.structs.replace(scenario, site=site)


def start_fleet(scenario: Scenario | None = None, **config) -> FleetThread:
    """``scenario`` (the fast paper one by default) in sim_fleet at SPEEDUP,
    every vehicle on a free port; ``config``: FleetConfig fields."""
    scenario = scenario or fast_scenario()
    config = {"params": AutopilotParams(auto_disarm_s=30.0)} | config
    return FleetThread(
        Fleet(scenario, FleetConfig(speedup=SPEEDUP, rate_hz=50.0, base_port=0, **config))
    ).start()


def sped_up_agent(link: MavlinkLink, config: AgentConfig, scenario: Scenario) -> Agent:
    """uav-1's agent on ``link``, its clocks ``SPEEDUP`` times real time (as the sim's)."""
    return Agent(
        "uav-1",
        scenario,
        link,
        config,
        clock=lambda: time.monotonic() * SPEEDUP,
        wall=lambda: time.time() * SPEEDUP,
    )


async def until(predicate, timeout_s: float = 10.0, what: str = "") -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what or predicate}")
        await asyncio.sleep(0.01)


def fly(fleet, uav_id: str, scenario, *, site=None, url: str | None = None, **options) -> None:
    """Run ``scenario(link)`` with a link to ``uav_id`` of the fleet once its
    telemetry flows (``site``: whose origin, the fast paper site by default;
    ``url``: another connection string; ``options``: the link's keyword arguments)."""
    origin = (site or fast_scenario().site).origin

    async def main() -> None:
        where = url or f"udpout:127.0.0.1:{fleet.fleet.ports[uav_id]}"
        config = options.pop("config", LINK_CONFIG)
        link = MavlinkLink(where, SiteFrame(origin), config, **options)
        link.start()
        heartbeat = asyncio.create_task(link.run())
        try:
            await until(
                lambda: (
                    link.state.link_ok
                    and link.state.known
                    and link.state.battery_fraction > 0
                    and link.state.flight_state is not FlightState.UNKNOWN
                ),
                what="telemetry",
            )
            await scenario(link)
        finally:
            heartbeat.cancel()
            link.close()

    asyncio.run(main())


class GroundStation:
    """What the test sees of the system: a liveliness token it can drop,
    plans it publishes, statuses and outcomes it collects."""

    def __init__(self, bus: Bus, uav_id: str) -> None:
        self.bus, self.uav_id = bus, uav_id
        self.token = None
        self.lock = threading.Lock()
        self.statuses: list[AgentStatus] = []
        self.outcomes: list[TaskOutcome] = []
        bus.subscribe(KEYS.status(uav_id), AgentStatus, lambda _k, m: self._add(self.statuses, m))
        bus.subscribe(KEYS.outcome(uav_id), TaskOutcome, lambda _k, m: self._add(self.outcomes, m))
        self.up()

    def _add(self, into: list, item) -> None:
        with self.lock:
            into.append(item)

    def up(self) -> None:
        self.token = self.bus.declare_token(KEYS.alive(Role.GROUND_STATION, "gs"))

    def down(self) -> None:
        self.token.close()

    @property
    def status(self) -> AgentStatus | None:
        with self.lock:
            return self.statuses[-1] if self.statuses else None

    def send(self, plan: Plan, timeout_s: float = 10.0) -> None:
        """Publish until the agent holds the plan's epoch (samples sent before
        its subscriber exists are lost)."""

        def held() -> bool:
            status = self.status
            if status is not None and status.epoch >= plan.epoch:
                return True
            self.bus.publish(KEYS.plan(self.uav_id), plan)
            return False

        wait_until(held, timeout_s, f"agent holding epoch {plan.epoch}")

    def outcome(self, task_id: str) -> TaskOutcome | None:
        with self.lock:
            return next((o for o in self.outcomes if o.task_id == task_id), None)


@pytest.fixture
def fleet():
    """The paper's fleet in sim_fleet at SPEEDUP, every vehicle on a free port."""
    runner = start_fleet()
    try:
        yield runner
    finally:
        runner.stop()


@pytest.fixture
def gs(bus_config):
    with Bus.open(bus_config) as bus:
        yield GroundStation(bus, "uav-1")


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_makereport(item, call):
    report = yield
    if report.when == "call":
        item.call_failed = report.failed
    return report


@pytest.fixture
def agent(request, router, fleet, gs, tmp_path):
    """``python -m onboard_agent`` flying uav-1 of the fleet."""
    path = tmp_path / "scenario.json"
    path.write_bytes(msgspec.json.encode(fast_scenario()))
    args = [
        sys.executable,
        "-m",
        "onboard_agent",
        "--uav",
        "uav-1",
        "--autopilot",
        f"udpout:127.0.0.1:{fleet.fleet.ports['uav-1']}",
        "--scenario",
        path,
        "--connect",
        router,
        "--tick-hz",
        "20",
        "--link-timeout",
        "1.5",
        "--log-level",
        "info",
    ]
    alive = KEYS.alive(Role.AGENT, "uav-1")
    with running(args, "agent", lambda: gs.bus.alive(alive)) as proc:
        yield proc
        if getattr(request.node, "call_failed", False):
            sys.stderr.write(f"--- agent log ---\n{proc.output()[-20000:]}\n")
            sys.stderr.write(f"--- last status ---\n{gs.status}\n")
