"""The paper's trees (Calvo et al., ICUAS 2022, Figs. 3-5), one builder each.

Composites are reactive (``memory=False``, BehaviorTree.CPP's
ReactiveSequence / ReactiveFallback): conditions are re-checked every tick,
so a UAV that drifts from its waypoint flies back before inspecting again.
Each subtree's root carries ``subtree_id`` for the Groot2 export.
"""

from __future__ import annotations

import py_trees

from onboard_agent import targets
from onboard_agent.behaviours.battery_enough import IsBatteryEnough
from onboard_agent.behaviours.battery_full import IsBatteryFull
from onboard_agent.behaviours.decorators import ForceRunning, TaskGuard
from onboard_agent.behaviours.finish_task import FinishTask
from onboard_agent.behaviours.go_near import GoNear
from onboard_agent.behaviours.gripper import PickTool, ReleaseTool
from onboard_agent.behaviours.has_tool import HasTool
from onboard_agent.behaviours.inspect import Inspect
from onboard_agent.behaviours.is_idle import IsIdle
from onboard_agent.behaviours.is_near import IsNear, NoPlace
from onboard_agent.behaviours.land import Land
from onboard_agent.behaviours.mission_over import MissionOver
from onboard_agent.behaviours.monitor import Monitor
from onboard_agent.behaviours.need_to_drop_tool import NeedToDropTool
from onboard_agent.behaviours.recharge import Recharge
from onboard_agent.behaviours.task_is import TaskIs
from onboard_agent.behaviours.wait_until import WaitUntil
from onboard_agent.context import Context
from proto.plan import (
    DeliverTask,
    GoHomeTask,
    InspectTask,
    LandTask,
    MonitorTask,
    PickTask,
    RechargeTask,
    WaitTask,
)

Behaviour = py_trees.behaviour.Behaviour
Sequence = py_trees.composites.Sequence
Selector = py_trees.composites.Selector


def _subtree(node: Behaviour, subtree_id: str) -> Behaviour:
    node.subtree_id = subtree_id  # type: ignore[attr-defined]
    return node


def go_near(target: targets.Target, ctx: Context) -> Behaviour:
    """Fallback [Is Agent near X?, Go near X]."""
    return Selector(f"Near {target.label}", False, [IsNear(target, ctx), GoNear(target, ctx)])


def inspection(ctx: Context) -> Behaviour:
    """Inspection Task Tree: near the next WP, inspect it; until the last."""
    children = [go_near(targets.WAYPOINT, ctx), Inspect(ctx)]
    return _subtree(Sequence("Inspection Task", False, children), "InspectionTask")


def monitoring(ctx: Context) -> Behaviour:
    """Monitoring Task Tree: near the slot around the worker, monitor."""
    children = [go_near(targets.HUMAN_SLOT, ctx), Monitor(ctx)]
    return _subtree(Sequence("Monitoring Task", False, children), "MonitoringTask")


def delivery(ctx: Context) -> Behaviour:
    """Tool Delivery Task Tree: have the tool (else go to the station and
    pick it), then (for a deliver task) go near the worker and release it.
    A plan's pick task ends after the pick; its deliver task does the rest."""
    pick = Sequence("Pick", False, [go_near(targets.TOOL_STATION, ctx), PickTool(ctx)])
    have_tool = Selector("Tool", False, [HasTool("Has Agent the Tool?", ctx), pick])
    deliver = Sequence("Deliver", False, [go_near(targets.HUMAN_DROP, ctx), ReleaseTool(ctx)])
    only_pick = TaskIs("Is Pick Task?", ctx, PickTask)
    children = [have_tool, Selector("Handover", False, [only_pick, deliver])]
    return _subtree(Sequence("Tool Delivery Task", False, children), "ToolDeliveryTask")


def drop_tool(ctx: Context) -> Behaviour:
    """Drop Tool Tree: a tool nobody needs goes back to a tool station."""
    back = Sequence(
        "Return Tool",
        False,
        [go_near(targets.TOOL_RETURN, ctx), ReleaseTool(ctx, name="Drop Tool")],
    )
    children = [NeedToDropTool("Need to Drop the Tool?", ctx), back]
    return _subtree(Sequence("Drop Tool", False, children), "DropTool")


def recharge(ctx: Context) -> Behaviour:
    """Recharge Tree (battery low): nearest charging station, land, charge
    until ``battery_full_fraction``."""
    charge = Recharge(ctx, lambda c: c.config.battery_full_fraction, latch=True)
    children = [go_near(targets.NEAREST_STATION, ctx), Land(ctx), charge]
    return _subtree(Sequence("Recharge", False, children), "Recharge")


def recharge_task(ctx: Context) -> Behaviour:
    """A planned recharge: the task's station, land, charge to its fraction."""

    def until(c: Context) -> float:
        task = c.mission.head
        return task.until_fraction if isinstance(task, RechargeTask) else 1.0

    children = [go_near(targets.TASK_STATION, ctx), Land(ctx), Recharge(ctx, until)]
    return _subtree(Sequence("Recharge Task", False, children), "RechargeTask")


def wait(ctx: Context) -> Behaviour:
    """Wait: hold until the task's time (for synchronised monitoring); on the
    pad if landed; aside of the slot just left if it follows monitoring."""
    aside = Selector(
        "Aside", False, [NoPlace(targets.WAIT_ASIDE, ctx), go_near(targets.WAIT_ASIDE, ctx)]
    )
    return _subtree(Sequence("Wait Task", False, [aside, WaitUntil(ctx)]), "WaitTask")


def go_home(ctx: Context) -> Behaviour:
    """Go Home: the task's station, land."""
    children = [go_near(targets.TASK_STATION, ctx), Land(ctx)]
    return _subtree(Sequence("Go Home Task", False, children), "GoHomeTask")


def back_to_station(ctx: Context) -> Behaviour:
    """Back To Station: the nearest charging station, land."""
    children = [go_near(targets.NEAREST_STATION, ctx), Land(ctx)]
    return _subtree(Sequence("Back To Station", False, children), "BackToStation")


def land_here(ctx: Context) -> Behaviour:
    """Land Task (an operator's command): land where the UAV is."""
    return _subtree(Sequence("Land Task", False, [Land(ctx)]), "LandTask")


def perform_task(ctx: Context) -> Behaviour:
    """Perform Task Tree: the subtree for the head task's kind, guarded so a
    hopeless task is reported failed, then "Task Done"."""
    branches = [
        ("Inspect", (InspectTask,), inspection),
        ("Monitor", (MonitorTask,), monitoring),
        ("Deliver", (PickTask, DeliverTask), delivery),
        ("Recharge", (RechargeTask,), recharge_task),
        ("Wait", (WaitTask,), wait),
        ("Home", (GoHomeTask,), go_home),
        ("Land", (LandTask,), land_here),
    ]
    children: list[Behaviour] = []
    for label, kinds, build in branches:
        guard = TaskGuard(f"{label} Guard", build(ctx), ctx)
        check = TaskIs(f"Is {label} Task?", ctx, *kinds)
        children.append(Sequence(f"{label} Branch", False, [check, guard, FinishTask(ctx)]))
    return _subtree(Selector("Perform Task", False, children), "PerformTask")


def main_tree(ctx: Context) -> Behaviour:
    """Main Tree (Fig. 3): mission over -> back to station; else battery
    enough -> drop a wrong tool -> perform the task; else recharge until full."""
    mission_over = Sequence(
        "Mission Over", False, [MissionOver("Mission Over?", ctx), back_to_station(ctx)]
    )
    not_idle = py_trees.decorators.Inverter("Inverter", IsIdle("Idle?", ctx))
    task = Sequence("Task", False, [not_idle, perform_task(ctx)])
    drop = py_trees.decorators.SuccessIsFailure("Force Failure", drop_tool(ctx))
    battery_ok = Sequence(
        "Battery Enough",
        False,
        [IsBatteryEnough("Is Battery Enough?", ctx), Selector("Drop Or Task", False, [drop, task])],
    )
    wait = Selector(
        "Wait Or Recharge", False, [IsBatteryFull("Is Battery Full?", ctx), recharge(ctx)]
    )
    mission = ForceRunning("Force Running", Selector("Mission", False, [battery_ok, wait]))
    return _subtree(Selector("Main Tree", False, [mission_over, mission]), "MainTree")
