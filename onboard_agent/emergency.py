"""The emergency protocol (system design section 6).

Triggers: the ground station's liveliness token has been gone longer than
``agent_link_timeout_s`` (a shorter drop-out changes nothing), or the energy
left no longer covers reaching the nearest station with the reserve. Then
the queue is emptied (every task reported failed, delivered when the link
returns) and, with no task left, the Main Tree flies to the nearest station
and lands. The emergency clears when the cause does (the token is back); a
new plan is then needed to fly again.
"""

from __future__ import annotations

import logging

from onboard_agent import budget
from onboard_agent.context import Context

log = logging.getLogger(__name__)

LINK_LOST = "ground station unreachable"
LOW_ENERGY = "energy too low to go on"


class Emergency:
    """Watches the ground-station link and the energy; call :meth:`check`
    before each tick."""

    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self._gs_alive: set[str] = set()
        self._lost_since: float | None = None
        self._ever_seen = False

    @property
    def link_up(self) -> bool:
        """Whether some ground station's token is alive now."""
        return bool(self._gs_alive)

    def ground_station(self, key: str, alive: bool) -> None:
        """A ground-station token appeared (``alive``) or vanished."""
        if alive:
            self._gs_alive.add(key)
            self._ever_seen = True
            self._lost_since = None
        else:
            self._gs_alive.discard(key)
            if not self._gs_alive and self._lost_since is None:
                self._lost_since = self.ctx.link_clock()

    def check(self) -> str:
        """Trigger or clear the protocol; returns the active reason ("" if none)."""
        ctx = self.ctx
        link_lost = (
            self._ever_seen
            and self._lost_since is not None
            and ctx.link_clock() - self._lost_since > ctx.config.agent_link_timeout_s
        )
        reason = LINK_LOST if link_lost else ""
        if not reason and ctx.mission.head is not None and not budget.can_reach_station(ctx):
            reason = LOW_ENERGY
        if not reason and ctx.emergency == LOW_ENERGY and not ctx.vehicle.landed:
            reason = LOW_ENERGY  # stays on until landed on the station
        if reason and reason != ctx.emergency:
            count = ctx.mission.abandon(f"emergency: {reason}")
            log.warning(
                "emergency: %s; %d tasks abandoned", reason, count, extra={"uav_id": ctx.uav_id}
            )
        elif reason and ctx.mission.head is not None:
            ctx.mission.abandon(f"emergency: {reason}")  # a plan that slipped in meanwhile
        if ctx.emergency and not reason:
            log.info("emergency over (%s)", ctx.emergency, extra={"uav_id": ctx.uav_id})
        ctx.emergency = reason
        return reason
