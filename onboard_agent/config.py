"""The agent's settings: one frozen object built once in ``main()``.

Values come from defaults, then ``LINECREW_AGENT_*`` environment variables
(the upper-cased field name, e.g. ``LINECREW_AGENT_TICK_HZ=5``), then
command-line overrides, read as every process reads its settings
(:mod:`linecrew_runtime.settings`).
"""

from __future__ import annotations

import dataclasses

from linecrew_runtime.clock import wall_period_s
from linecrew_runtime.settings import EnvSettings


@dataclasses.dataclass(frozen=True, kw_only=True)
class AgentConfig(EnvSettings):
    """Behaviour-tree, emergency and autopilot-link settings of one agent."""

    ENV_PREFIX = "LINECREW_AGENT_"

    tick_hz: float = 10.0  # behaviour-tree ticks per second
    telemetry_hz: float = 5.0  # Telemetry messages per second
    status_period_s: float = 1.0  # AgentStatus at least this often (and on change)
    agent_link_timeout_s: float = 3.0  # ground station gone this long -> emergency
    battery_full_fraction: float = 0.95  # "battery full" at or above this fraction
    energy_margin: float = 1.15  # factor on predicted energy (wind, estimation errors)
    near_waypoint_m: float = 1.0  # "near waypoint": 3-D distance
    near_human_m: float = 2.5  # "near human" when delivering: 3-D distance to the drop point
    near_slot_m: float = 1.0  # "near human" when monitoring: distance to the slot point
    near_station_m: float = 0.5  # "near station": horizontal distance
    near_tool_station_m: float = 1.0  # "near tool station": 3-D distance to the pick point
    settle_speed_mps: float = 0.3  # below this the vehicle counts as hovering
    takeoff_alt_m: float = 3.0  # takeoff height above the pad
    approach_alt_m: float = 3.0  # height above a station before landing
    pick_height_m: float = 1.0  # height above a tool station to grab / return a tool
    deliver_height_m: float = 2.0  # height above the worker to release a tool
    follow_threshold_m: float = 0.5  # re-target the slot when it moved more than this
    route_margin_m: float = 1.0  # a route passes people by their clearance plus this
    handover_hold_m: float = 3.0  # a relief holds this much farther out until its window begins
    wait_aside_m: float = 3.0  # an airborne wait after monitoring hovers this far along the ring
    keep_clear_m: float = 2.0  # never fly to a point another airborne UAV is this near (traffic)
    yield_max_s: float = 30.0  # hold off at most this long (mission s), then fly on
    relief_wait_s: float = 60.0  # past its segment's end, wait this long at most for the relief
    relief_there_m: float = 1.5  # a relief heard this near its slot (3-D) has taken it over
    goto_resend_s: float = 1.0  # repeat a position target this often (no ACK exists)
    task_attempts: int = 3  # a task whose subtree failed this often is reported failed
    arm_attempts: int = 6  # arm / mode / takeoff refusals retried (with backoff) before failing
    retry_backoff_s: float = 1.0  # first wait after a refusal (mission s); doubles each time
    retry_backoff_max_s: float = 16.0  # longest wait between two tries
    ready_timeout_s: float = 120.0  # a task waits this long for the autopilot to become ready
    not_ready_state: bool = True  # publish AgentState.NOT_READY until the autopilot can
    # first arm (the gs gives the work to others until it can); False keeps IDLE / BUSY
    # with ready=False and the reason, for a gs that does not know the state
    command_ack_timeout_s: float = 1.0  # wait this long for a COMMAND_ACK
    command_retries: int = 3  # resend an unacknowledged command this many times
    heartbeat_timeout_s: float = 3.0  # no autopilot HEARTBEAT this long -> link lost
    autopilot_system: int = 0  # the autopilot's MAVLink system id; 0: the first one heard
    autopilot_component: int = 1  # its component id (MAV_COMP_ID_AUTOPILOT1)
    plan_query_timeout_s: float = 2.0  # resync query to the ground station

    def at_speedup(self, speedup: float) -> AgentConfig:
        """These settings for a mission clock ``speedup`` times real time:
        telemetry as often in mission seconds as at x1 (:func:`wall_period_s`)."""
        hz = 1.0 / wall_period_s(1.0 / self.telemetry_hz, speedup)
        return dataclasses.replace(self, telemetry_hz=hz)

    def check(self) -> None:
        """Raise ``ValueError`` for settings that cannot work."""
        if self.tick_hz <= 0 or self.telemetry_hz <= 0:
            raise ValueError("tick_hz and telemetry_hz must be positive")
        if not 0.0 < self.battery_full_fraction <= 1.0:
            raise ValueError("battery_full_fraction must be in (0, 1]")
        if self.agent_link_timeout_s <= 0 or self.command_ack_timeout_s <= 0:
            raise ValueError("timeouts must be positive")
        if not 0 <= self.autopilot_system <= 255 or not 1 <= self.autopilot_component <= 255:
            raise ValueError("autopilot_system must be 0-255, autopilot_component 1-255")
        if self.command_retries < 0:
            raise ValueError("command_retries must be >= 0")
        if self.arm_attempts < 1 or self.retry_backoff_s <= 0 or self.ready_timeout_s <= 0:
            raise ValueError("arm_attempts, retry_backoff_s and ready_timeout_s must be positive")
