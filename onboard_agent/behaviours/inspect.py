"""Action "Inspection": hold each waypoint for its service time."""

from __future__ import annotations

from onboard_agent.behaviours.base import AgentBehaviour, Status
from onboard_agent.context import Context
from proto.plan import InspectTask


class Inspect(AgentBehaviour):
    """At the next waypoint (the tree brought us there): hold ``service_s``,
    mark it done (progress a split inspection can resume from), then RUNNING
    while waypoints remain (the tree flies to the next) and SUCCESS after the
    last one."""

    def __init__(self, ctx: Context, name: str = "Inspection") -> None:
        super().__init__(name, ctx)
        self._index: int | None = None
        self._since = 0.0

    def initialise(self) -> None:
        self._index = None

    def update(self) -> Status:
        mission = self.ctx.mission
        task = mission.head
        if not isinstance(task, InspectTask):
            self.feedback_message = "no inspection task"
            return Status.FAILURE
        mission.start(task)
        wp = mission.next_waypoint(task)
        if wp is None:
            self.feedback_message = "all waypoints inspected"
            return Status.SUCCESS
        now = self.ctx.clock()
        if self._index != wp.index:
            self._index, self._since = wp.index, now
        if now - self._since < wp.service_s:
            self.feedback_message = f"inspecting waypoint {wp.index}"
            return Status.RUNNING
        mission.mark_waypoint(task, wp.index)
        self._index = None
        if mission.next_waypoint(task) is None:
            self.feedback_message = "all waypoints inspected"
            return Status.SUCCESS
        self.feedback_message = f"waypoint {wp.index} done"
        return Status.RUNNING
