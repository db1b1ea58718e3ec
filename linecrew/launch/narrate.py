"""Plain-language text for ``linecrew demo``: what runs, what the scenario
asks, one line per meaningful ground-station event, and action outcomes.

Everything here is pure (no I/O): :class:`Narrator` turns events, with the
gateway's plans, into lines; the demo prints them.
"""

from __future__ import annotations

import queue
import re
from typing import Any

from proto.events import EventKind, GsEvent
from proto.mission import Action, DeliverAction, InspectAction, MonitorAction
from proto.scenario import Scenario

HANDOVER = re.compile(r"slot \d+ of (?P<worker>\S+): (?P<old>\S+) -> (?P<new>\S+)")
"""The ``detail`` of a ``handover`` event."""
NUMBER = re.compile(r"\d+(\.\d+)?")


def plural(n: int, word: str) -> str:
    """``1 point``, ``3 points``."""
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def action_text(action: Action) -> str:
    """What an action asks, in plain words."""
    match action:
        case DeliverAction():
            return (
                f"deliver the {action.tool} from {action.tool_station_id} "
                f"to worker {action.worker_id}"
            )
        case MonitorAction():
            return (
                f"watch worker {action.worker_id} with {plural(action.uavs, 'UAV')}, "
                f"{action.standoff_m:g} m away, for {action.duration_s:.0f} s"
            )
        case InspectAction():
            holds = sorted({w.service_s for w in action.waypoints})
            hold = f"{holds[0]:g}" if len(holds) == 1 else f"{holds[0]:g}-{holds[-1]:g}"
            return f"inspect {plural(len(action.waypoints), 'point')} ({hold} s at each)"


def intro(scenario: Scenario, speedup: float) -> str:
    """What runs, what the scenario asks, and what the speed-up means."""
    fleet = scenario.fleet
    uavs = []
    for uav in fleet.uavs:
        kind = fleet.type_of(uav.id)
        gripper = ", with gripper" if kind is not None and kind.gripper else ""
        uavs.append(f"{uav.id} ({uav.type}{gripper}) at {uav.home_station}")
    asks = [
        f"  at {a.at_s:>4.0f} s  {a.id}: {action_text(a.action)}"
        for a in sorted(scenario.actions, key=lambda a: a.at_s)
    ]
    return "\n".join(
        [
            "What runs, each a separate process: a Zenoh message router, the ground "
            "station (plans and replans the fleet), the REST gateway (this demo talks "
            f"to it), a simulator of the {plural(len(fleet.uavs), 'UAV')}, and one agent "
            "per UAV (flies that UAV's plan).",
            f"Fleet: {', '.join(uavs)}.",
            f"The scenario {scenario.name!r} submits these actions:",
            *asks,
            f"x{speedup:g}: {speedup:g} mission seconds pass per real second; "
            "the times below are mission seconds.",
        ]
    )


def task_text(uav_id: str, tasks: list[dict[str, Any]], origin_s: float) -> str:
    """What ``uav_id`` does now: its first task (with the drop that follows
    a pick). ``tasks`` as ``GET /v1/plan`` gives them."""
    if not tasks:
        return f"{uav_id} has nothing left to do"
    task, after = tasks[0], tasks[1] if len(tasks) > 1 else {}
    for_action = f" ({task['action_id']})" if task.get("action_id") else ""
    match task["type"]:
        case "pick":
            drop = after.get("type") == "deliver"
            then = f", then brings it to {after['worker_id']}" if drop else ""
            return (
                f"{uav_id} heads to {task['tool_station_id']} to pick the {task['tool']}"
                f"{then}{for_action}"
            )
        case "deliver":
            return f"{uav_id} brings the {task['tool']} to {task['worker_id']}{for_action}"
        case "inspect":
            points = plural(len(task["waypoints"]), "point")
            return f"{uav_id} inspects {points}{for_action}"
        case "monitor":
            slot = f" (slot {task['slot'] + 1} of {task['slots']})" if task["slots"] > 1 else ""
            return (
                f"{uav_id} watches {task['worker_id']}{slot} "
                f"for {task['duration_s']:.0f} s{for_action}"
            )
        case "recharge":
            return f"{uav_id} recharges at {task['station_id']}"
        case "wait":
            return f"{uav_id} waits until t={task['until_s'] - origin_s:.0f} s"
        case "home":
            return f"{uav_id} flies home to {task['station_id']}"
    return f"{uav_id} does {task['type']} {task['task_id']}"


def action_state_text(action_id: str, detail: str) -> str | None:
    """An ``action_state`` event (detail ``old->new: reason``); failures and
    cancellations are told by their own events."""
    states, _, reason = detail.partition(": ")
    new = states.partition("->")[2]
    match new:
        case "planned":
            return f"{action_id} planned" + ("" if reason == "planned" else f" ({reason})")
        case "accepted":
            return f"{action_id} waits for a UAV: {reason}"
        case "in_progress":
            return f"{action_id} in progress"
        case "completed":
            return f"{action_id} completed"
    return None


def event_text(event: GsEvent) -> str | None:
    """A plain line for an event other than ``plan_changed``; ``None`` for
    those not worth telling (``replan``, ``uav_state``)."""
    uav, action, detail = event.uav_id or "", event.action_id or "", event.detail
    match event.kind:
        case EventKind.ACTION_ACCEPTED:
            return f"{action} submitted"
        case EventKind.ACTION_CHANGED:
            return f"{action} changed by the operator"
        case EventKind.ACTION_CANCELLED:
            return f"{action} cancelled"
        case EventKind.ACTION_STATE:
            return action_state_text(action, detail)
        case EventKind.ACTION_FAILED:
            return f"{action} FAILED: {detail}"
        case EventKind.HANDOVER:
            if m := HANDOVER.fullmatch(detail):
                return f"hand-over: {m['new']} relieves {m['old']} watching {m['worker']}"
            return f"hand-over: {detail}"
        case EventKind.UAV_SILENT | EventKind.UAV_HEARD:
            return f"{uav} {detail}"
        case EventKind.UAV_LOST:
            return f"{uav} LOST: {detail}"
        case EventKind.UAV_BACK:
            return f"{uav} back: {detail}"
        case EventKind.UAV_CRASHED:
            return f"{uav} CRASHED: {detail}"
        case EventKind.FAULT:
            return f"{uav} fault: {detail}" if uav else f"fault: {detail}"
    return None


def outcome_text(record: dict[str, Any]) -> str:
    """An action's outcome, with the reason when it did not complete."""
    outcome = f"{record['state']} ({100 * record['progress']:.0f} %)"
    if record["state"] != "completed" and record.get("reason"):
        outcome += f": {record['reason']}"
    return outcome


class Narrator:
    """Turns ground-station events into timed lines.

    The event subscription only puts events on :attr:`inbox`; :meth:`lines`
    reads what :meth:`drain` took, with a plan snapshot taken after it.
    Times are mission seconds since ``origin_s``. A fault that repeats one
    already told for the UAV (numbers aside) is told again only once the
    UAV's first task has changed. A UAV "back" that was never lost has just
    connected.
    """

    def __init__(self, origin_s: float) -> None:
        self.origin_s = origin_s
        self.inbox: queue.Queue[GsEvent] = queue.Queue()
        self.handovers = 0
        self._first: dict[str, str | None] = {}  # uav -> id of its first task told
        self._faults: dict[str, set[str]] = {}  # uav -> faults told since, numbers aside
        self._lost: set[str] = set()

    def drain(self) -> list[GsEvent]:
        """The events received so far, oldest first."""
        events = []
        while True:
            try:
                events.append(self.inbox.get_nowait())
            except queue.Empty:
                return events

    def lines(self, events: list[GsEvent], plans: list[dict[str, Any]]) -> list[str]:
        """One line per event worth telling; a plan change only when it
        changes the UAV's first task."""
        tasks = {p["uav_id"]: p["tasks"] for p in plans}
        out = []
        for event in events:
            if event.kind == EventKind.HANDOVER:
                self.handovers += 1
            uav = event.uav_id or ""
            if event.kind == EventKind.PLAN_CHANGED:
                text = self._plan_text(uav, tasks.get(uav, []))
            elif event.kind == EventKind.FAULT and self._repeated(uav, event.detail):
                text = None
            elif event.kind == EventKind.UAV_BACK and uav not in self._lost:
                text = f"{uav} connected (its agent is up)"
            else:
                text = event_text(event)
            if event.kind in (EventKind.UAV_LOST, EventKind.UAV_CRASHED):
                self._lost.add(uav)
            elif event.kind == EventKind.UAV_BACK:
                self._lost.discard(uav)
            if text is not None:
                out.append(f"t={event.stamp_s - self.origin_s:>5.0f} s  {text}")
        return out

    def _plan_text(self, uav_id: str, tasks: list[dict[str, Any]]) -> str | None:
        first = tasks[0]["task_id"] if tasks else None
        if self._first.get(uav_id) == first:
            return None
        self._first[uav_id] = first
        self._faults.pop(uav_id, None)
        return task_text(uav_id, tasks, self.origin_s)

    def _repeated(self, uav_id: str, detail: str) -> bool:
        told = self._faults.setdefault(uav_id, set())
        shape = NUMBER.sub("#", detail)
        if shape in told:
            return True
        told.add(shape)
        return False
