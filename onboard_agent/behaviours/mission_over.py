"""Condition "Mission Over?"."""

from onboard_agent.behaviours.base import Condition


class MissionOver(Condition):
    """No task left: the plan is done, the emergency protocol emptied the
    queue, or no plan arrived yet. The Main Tree then goes back to a station."""

    def holds(self) -> bool:
        return self.ctx.mission.head is None
