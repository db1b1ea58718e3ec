"""Everything the behaviours share: one object handed to each of them.

The tree runs on one thread (the asyncio loop, or a test), so plain
attributes are enough; ``tool`` and ``recharging`` are the agent's beliefs
that no autopilot message carries.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

from onboard_agent.autopilot.protocol import Autopilot, Pending, VehicleState
from onboard_agent.config import AgentConfig
from onboard_agent.energy import EnergyModel
from onboard_agent.mission import Mission
from onboard_agent.spots import Spots
from onboard_agent.surroundings import Surroundings
from onboard_agent.traffic import Traffic
from proto.geo import Point


@dataclasses.dataclass(kw_only=True, eq=False)
class Context:
    """Shared state of one agent's behaviour tree."""

    uav_id: str
    config: AgentConfig
    autopilot: Autopilot
    mission: Mission
    surroundings: Surroundings
    spots: Spots
    traffic: Traffic
    energy: EnergyModel
    clock: Callable[[], float]  # monotonic mission seconds: task durations (scaled by speed-up)
    wall: Callable[[], float]  # mission seconds: plan times (WaitTask.until_s)
    tool: str | None = None  # the tool we believe the gripper holds
    tool_station_id: str | None = None  # where that tool was picked
    recharging: bool = False  # a battery-low recharge runs until the battery is full
    emergency: str = ""  # why the emergency protocol is active ("" when not)
    holding_for: str | None = None  # the UAV at our next point: we hold until it leaves
    heading_to: Point | None = None  # the last position target sent (None: since a take-off)
    link_clock: Callable[[], float] = time.monotonic  # real seconds: link timeouts

    @property
    def vehicle(self) -> VehicleState:
        return self.autopilot.state

    def goto(self, target: Point) -> Pending:
        """Send the autopilot a position target, remembered in
        ``heading_to``: telemetry reports it, since a UAV whose agent hangs
        flies on to it while the ground station hears no more of it."""
        self.heading_to = target
        return self.autopilot.goto(target)
