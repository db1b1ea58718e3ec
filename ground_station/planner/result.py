"""What the planner returns: a :class:`Solution`.

Step semantics (shared with the validator): a step begins at ``start_s`` at
the previous step's end position (or the UAV's position for its first
step), flies straight to ``position_m`` at cruise speed (``arrive_s``), then
serves from ``arrive_s`` to ``end_s``: hovering for inspect, monitor, pick,
deliver and airborne waits; on a pad for recharge; landed waits (after a
recharge or home, or while a UAV that starts on the ground has not yet
flown) cost nothing. A wait either stays in place or flies to a station and
waits landed there (for a free pad). Steps are contiguous in time.
"""

from __future__ import annotations

from typing import Literal

import msgspec

from ground_station.planner.model import Vec3

StepKind = Literal["inspect", "monitor", "pick", "deliver", "recharge", "wait", "home"]


class Step(msgspec.Struct, frozen=True, kw_only=True, omit_defaults=True):
    """One timed step of a UAV's plan.

    ``index`` is the waypoint index (inspect) or slot (monitor); ``station``
    the recharge or landing station; ``tool`` the tool picked or delivered.
    ``energy_after_wh`` is the battery at ``end_s``.
    """

    kind: StepKind
    start_s: float
    arrive_s: float
    end_s: float
    position_m: Vec3
    energy_after_wh: float
    distance_m: float = 0.0
    action_id: str | None = None
    index: int | None = None
    station: str | None = None
    tool: str | None = None


class UavPlan(msgspec.Struct, frozen=True, kw_only=True):
    """The ordered steps of one UAV."""

    uav_id: str
    steps: tuple[Step, ...] = ()


class Unplaced(msgspec.Struct, frozen=True, kw_only=True):
    """An action (``part`` None) or a part of it (waypoint index) not placed.

    ``reason`` is a stable code: ``no_capable_uav``, ``k_exceeds_fleet``,
    ``unreachable_with_full_battery``, ``unknown_tool``,
    ``monitor_coverage_infeasible``, ``battery_infeasible``.
    """

    action_id: str
    part: int | None = None
    reason: str


class Metrics(msgspec.Struct, frozen=True, kw_only=True):
    """Plan quality figures.

    ``makespan_s`` is from ``now_s`` to the end of the last step (all UAVs
    landed); ``weighted_completion_s`` sums weight x (completion - now_s)
    over fully placed actions and ``mean_completion_s`` divides it by the
    total weight of all actions. ``planning_time_s`` is filled by callers
    that time the planner (the library reads no clock).
    """

    makespan_s: float = 0.0
    distance_m: float = 0.0
    energy_wh: float = 0.0
    recharges: int = 0
    weighted_completion_s: float = 0.0
    unplaced_parts: int = 0
    planning_time_s: float = 0.0
    mean_completion_s: float = 0.0


class Solution(msgspec.Struct, frozen=True, kw_only=True):
    """Per-UAV step lists, what could not be placed, and metrics."""

    uavs: tuple[UavPlan, ...]
    unplaced: tuple[Unplaced, ...] = ()
    metrics: Metrics = Metrics()


class Violation(msgspec.Struct, frozen=True, kw_only=True):
    """A validator finding: stable ``code`` and a human ``detail``."""

    code: str
    detail: str
    uav_id: str | None = None
    action_id: str | None = None
