"""ground_station.planner: the mission planner, a pure deterministic library.

``plan(problem)`` turns a ``Problem`` (fleet, stations, actions) into a
``Solution`` (per-UAV timed steps, unplaced parts with reasons, metrics);
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
    Airframe,
    CostWeights,
    DeliverJob,
    InspectJob,
    Job,
    MonitorJob,
    Problem,
    RunningTask,
    Station,
    ToolDepot,
    Uav,
    Viewpoint,
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
from ground_station.planner.result import Metrics, Solution, Step, UavPlan, Unplaced, Violation
from ground_station.planner.routes import Options
from ground_station.planner.validate import validate

__all__ = [
    "ActionAdded",
    "ActionCancelled",
    "ActionChanged",
    "Airframe",
    "BatteryLow",
    "CostWeights",
    "DeliverJob",
    "Event",
    "InspectJob",
    "Job",
    "Metrics",
    "MonitorJob",
    "Options",
    "PlanningProblemError",
    "Problem",
    "RunningTask",
    "Session",
    "Solution",
    "Station",
    "Step",
    "TaskFinished",
    "ToolDepot",
    "Uav",
    "UavBack",
    "UavLost",
    "UavPlan",
    "Unplaced",
    "Viewpoint",
    "Violation",
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
