"""Actions "Pick Tool", "Deliver Tool" and "Drop Tool": one gripper command
once hovering, plus the agent's belief about what it holds."""

from __future__ import annotations

from onboard_agent.behaviours.base import AgentBehaviour, CommandSlot, Status
from onboard_agent.context import Context
from proto.plan import DeliverTask, PickTask


class _GripperAction(AgentBehaviour):
    verb = ""

    def __init__(self, ctx: Context, name: str) -> None:
        super().__init__(name, ctx)
        self.command = CommandSlot()
        self._sent_at: float | None = None

    def initialise(self) -> None:
        self.command.cancel()
        self._sent_at = None

    def hold_s(self) -> float:
        """Service time after the gripper acted (pick_s / drop_s)."""
        return 0.0

    def send(self) -> None:
        raise NotImplementedError

    def done(self) -> str | None:
        """Update the beliefs once the gripper acted; why it failed, if it did."""
        raise NotImplementedError

    def update(self) -> Status:
        status = self.command.check()
        if status is Status.FAILURE:
            self.feedback_message = self.command.error
            return status
        if status is Status.RUNNING:
            self.feedback_message = f"waiting for gripper {self.verb}"
            return status
        ctx = self.ctx
        if self._sent_at is None:
            if ctx.vehicle.speed_mps > ctx.config.settle_speed_mps:
                self.feedback_message = "settling"
                return Status.RUNNING
            self.send()
            self._sent_at = ctx.clock()
            self.feedback_message = f"gripper {self.verb}"
            return Status.RUNNING
        if ctx.clock() - self._sent_at < self.hold_s():
            self.feedback_message = f"gripper {self.verb}: holding"
            return Status.RUNNING
        problem = self.done()
        if problem is not None:
            self.feedback_message = problem
            return Status.FAILURE
        self.feedback_message = f"gripper {self.verb} done"
        return Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        if new_status is Status.INVALID:
            self.command.cancel()


class PickTool(_GripperAction):
    """Grab the head task's tool at its tool station."""

    verb = "grab"

    def __init__(self, ctx: Context, name: str = "Pick Tool") -> None:
        super().__init__(ctx, name)

    def hold_s(self) -> float:
        task = self.ctx.mission.head
        return task.pick_s if isinstance(task, PickTask) else 0.0

    def send(self) -> None:
        self.command.issue("grab", self.ctx.autopilot.grab())

    def done(self) -> str | None:
        """Believe the gripper holds the task's tool, unless the gripper said
        it grabbed nothing or another tool (then that one is held and the
        "Drop Tool" branch takes it back)."""
        task = self.ctx.mission.head
        if not isinstance(task, PickTask | DeliverTask):
            return None
        if isinstance(task, PickTask):
            station_id: str | None = task.tool_station_id
        else:
            station = self.ctx.surroundings.tool_station_for(task.tool)
            station_id = station.id if station is not None else None
        held = grabbed(self.ctx.vehicle.gripper_text, task.tool)
        if held is None:
            return f"grabbed nothing at {station_id} (no {task.tool} left?)"
        self.ctx.tool, self.ctx.tool_station_id = held, station_id
        self.ctx.mission.note_tool(task, held)
        if held != task.tool:
            return f"grabbed {held} instead of {task.tool} at {station_id}"
        return None


def grabbed(text: str, expected: str) -> str | None:
    """The tool a gripper report says it holds (``expected`` when the
    autopilot says nothing, as a plain gripper does); None if it grabbed nothing."""
    if not text.startswith("Gripper: grabbed "):
        return expected
    rest = text.removeprefix("Gripper: grabbed ")
    if rest == "nothing":
        return None
    return rest.split(" at ", 1)[0]


class ReleaseTool(_GripperAction):
    """Open the gripper: "Deliver Tool" at the worker, "Drop Tool" at a station."""

    verb = "release"

    def __init__(self, ctx: Context, name: str = "Deliver Tool") -> None:
        super().__init__(ctx, name)

    def hold_s(self) -> float:
        task = self.ctx.mission.head
        return task.drop_s if isinstance(task, DeliverTask) else 0.0

    def send(self) -> None:
        self.command.issue("release", self.ctx.autopilot.release())

    def done(self) -> str | None:
        task = self.ctx.mission.head
        if isinstance(task, DeliverTask):
            self.ctx.mission.note_tool(task, self.ctx.tool)
        self.ctx.tool = None
        self.ctx.tool_station_id = None
        return None
