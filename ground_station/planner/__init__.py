"""ground_station.planner: the mission planner, a pure deterministic library.

``plan(problem)`` turns a ``Problem`` (fleet, stations, actions) into a
``Plan`` (per-UAV timed steps, unplaced parts with reasons, metrics);
``validate(problem, plan)`` checks any plan independently. No I/O, no clock.
"""

from ground_station.planner.api import plan, score
from ground_station.planner.errors import PlanningProblemError
from ground_station.planner.load import (
    check_problem,
    plan_from_json,
    problem_from_json,
    problem_from_obj,
)
from ground_station.planner.metrics import compute_metrics
from ground_station.planner.model import (
    Action,
    CostWeights,
    DeliverAction,
    InspectAction,
    MonitorAction,
    Problem,
    RunningTask,
    Station,
    ToolStation,
    Uav,
    UavType,
    Waypoint,
)
from ground_station.planner.replan import (
    ActionAdded,
    ActionCancelled,
    ActionChanged,
    BatteryLow,
    Event,
    Session,
    TaskFinished,
    UavBack,
    UavLost,
    replan_once,
)
from ground_station.planner.result import Metrics, Plan, Step, UavPlan, Unplaced, Violation
from ground_station.planner.routes import Options
from ground_station.planner.validate import validate

__all__ = [
    "Action",
    "ActionAdded",
    "ActionCancelled",
    "ActionChanged",
    "BatteryLow",
    "CostWeights",
    "DeliverAction",
    "Event",
    "InspectAction",
    "Metrics",
    "MonitorAction",
    "Options",
    "Plan",
    "PlanningProblemError",
    "Problem",
    "RunningTask",
    "Session",
    "Station",
    "Step",
    "TaskFinished",
    "ToolStation",
    "Uav",
    "UavBack",
    "UavLost",
    "UavPlan",
    "UavType",
    "Unplaced",
    "Violation",
    "Waypoint",
    "check_problem",
    "compute_metrics",
    "plan",
    "plan_from_json",
    "problem_from_json",
    "problem_from_obj",
    "replan_once",
    "score",
    "validate",
]
