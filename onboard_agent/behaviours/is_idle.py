"""Condition "Idle?"."""

from onboard_agent.behaviours.base import Condition


class IsIdle(Condition):
    """Nothing to perform now (no head task). Guards "Perform Task"; in the
    Main Tree "Mission Over?" catches the empty queue first."""

    def holds(self) -> bool:
        return self.ctx.mission.head is None
