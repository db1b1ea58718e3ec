"""Plans sent from the ground station to each agent.

A :class:`Plan` holds the ordered tasks of one UAV under a monotonically
increasing ``epoch``; an agent ignores any plan older than the one it holds.
Every task carries the planner's estimates (``start_s``/``end_s`` in mission
seconds (see :mod:`proto.telemetry`), ``energy_after_wh``) so agents can judge "battery enough".
"""

from __future__ import annotations

from proto.base import (
    Count,
    Finite,
    Fraction,
    Id,
    Message,
    NonNegative,
    Positive,
    PositiveCount,
    Record,
)
from proto.geo import Point


class TaskBase(Record, frozen=True, kw_only=True):
    """Fields every task has."""

    task_id: Id
    action_id: Id | None = None
    start_s: Finite = 0.0
    end_s: Finite = 0.0
    energy_after_wh: Finite = 0.0


class Waypoint(Record, frozen=True, kw_only=True):
    """An inspection point: fly there, hold ``service_s`` seconds.
    ``index`` is its position in the action's original waypoint list."""

    index: Count
    position: Point
    service_s: NonNegative = 0.0


class InspectTask(TaskBase, frozen=True, kw_only=True, tag="inspect"):
    """Visit ``waypoints`` in order."""

    waypoints: list[Waypoint]


class MonitorTask(TaskBase, frozen=True, kw_only=True, tag="monitor"):
    """Hold slot ``slot`` of ``slots`` around the worker (``standoff_m``
    away horizontally, ``height_m`` above them, at bearing ``bearing_deg``
    + 360 * slot / slots degrees from +x), following them, for
    ``duration_s``. ``relieved_by`` names the UAV planned to take the slot
    over at ``end_s``: until it is there (at most the agent's
    ``relief_wait_s``, and only while the battery allows) this UAV keeps
    watching from beside the slot instead of leaving the worker alone."""

    worker_id: Id
    slot: Count
    slots: PositiveCount
    standoff_m: Positive
    duration_s: Positive
    height_m: NonNegative = 3.0
    bearing_deg: Finite = 0.0
    relieved_by: Id | None = None

    @property
    def window_start_s(self) -> float:
        """When its planned window begins (``end_s - duration_s``; a task
        without times has none that means anything)."""
        return self.end_s - self.duration_s


class PickTask(TaskBase, frozen=True, kw_only=True, tag="pick"):
    """Fly to a tool station and grab ``tool`` (takes ``pick_s``)."""

    tool: Id
    tool_station_id: Id
    position: Point
    pick_s: NonNegative = 0.0


class DeliverTask(TaskBase, frozen=True, kw_only=True, tag="deliver"):
    """Fly to the worker and release the held ``tool`` (takes ``drop_s``)."""

    tool: Id
    worker_id: Id
    drop_s: NonNegative = 0.0


class RechargeTask(TaskBase, frozen=True, kw_only=True, tag="recharge"):
    """Land on a pad of ``station_id`` and stay until ``until_fraction``."""

    station_id: Id
    position: Point
    until_fraction: Fraction = 0.95


class WaitTask(TaskBase, frozen=True, kw_only=True, tag="wait"):
    """Hold (on the pad if landed) until ``until_s`` (mission seconds)."""

    until_s: Finite


class GoHomeTask(TaskBase, frozen=True, kw_only=True, tag="home"):
    """Fly to ``station_id`` and land."""

    station_id: Id
    position: Point


class LandTask(TaskBase, frozen=True, kw_only=True, tag="land"):
    """Land where the UAV is (an operator's command; never planned)."""


Task = (
    InspectTask
    | MonitorTask
    | PickTask
    | DeliverTask
    | RechargeTask
    | WaitTask
    | GoHomeTask
    | LandTask
)


class Plan(Message, frozen=True, kw_only=True):
    """The task list of one UAV, on ``uav/{id}/plan``."""

    uav_id: Id
    epoch: Count
    issued_s: Finite = 0.0
    tasks: list[Task] = []
