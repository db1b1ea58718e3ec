"""The fleet watchdog: who is present, who is lost, what each UAV is doing.

Presence comes from each agent's liveliness token plus the freshness of its
telemetry. A UAV silent (token gone, or no telemetry) for less than
``link_timeout_s`` is still present: brief drop-outs move no work. Longer,
it is *lost* and its work goes to others; when token and telemetry return it
is *back*. A UAV whose telemetry says it crashed, or whose agent says it
failed, is reported at once, without the grace, and takes no work until it
reports otherwise (then it is *back*). UAVs never heard since start-up begin
as lost (without an event).
A present UAV silent for ``SILENT_AFTER_S`` or more is *silent*: shown with
how long and since when (mission time), its planned tasks unknown (never
failed), until it is *heard* again or declared lost; :meth:`FleetMonitor.check`
reports the start and the end of each such spell once.
Time is injected: :meth:`FleetMonitor.check` and the ``on_*`` feeds get the
watchdog's (monotonic) now; the mission clock, read as reports arrive, only
dates the silences.
"""

from __future__ import annotations

import dataclasses
import enum
import time
from collections.abc import Callable, Mapping

import msgspec

from proto.plan import Plan
from proto.rpc import UavOpState, UavState
from proto.telemetry import (
    AgentState,
    AgentStatus,
    FlightState,
    Telemetry,
    Traffic,
    TrafficEntry,
)

_FROM_AGENT = {
    AgentState.IDLE: UavOpState.IDLE,
    AgentState.BUSY: UavOpState.BUSY,
    AgentState.RECHARGING: UavOpState.RECHARGING,
    AgentState.EMERGENCY: UavOpState.EMERGENCY,
    AgentState.FAILED: UavOpState.FAILED,
    AgentState.NOT_READY: UavOpState.NOT_READY,
}


TRAFFIC_MAX_AGE_S = 60.0
"""UAVs last heard airborne longer ago than this are left out of the
traffic (a hung UAV may hover on where it was for that long)."""
AIRBORNE = frozenset({FlightState.TAKING_OFF, FlightState.FLYING, FlightState.LANDING})
FALLEN = frozenset({UavOpState.FAILED, UavOpState.LOST})
"""States in which a UAV's last word of holding off for another is shown no more."""
SILENT_AFTER_S = 2.0
"""Silence (s) after which a present UAV is silent: ten telemetry periods, and
two status periods (an agent with no position yet is heard once a second)."""


class Change(enum.StrEnum):
    """A presence change reported by :meth:`FleetMonitor.check`."""

    LOST = "lost"
    BACK = "back"
    CRASHED = "crashed"  # telemetry says crashed (or disarmed in the air): lost at once
    FAILED = "failed"  # the agent reports itself failed (e.g. no autopilot): lost at once
    NOT_READY = "not_ready"  # on its pad, the autopilot cannot arm yet: work goes elsewhere
    SILENT = "silent"  # present, unheard for SILENT_AFTER_S: its tasks are unknown, nothing moves
    HEARD = "heard"  # a silent UAV heard again before the link timeout


@dataclasses.dataclass
class _Uav:
    token: bool = False
    token_lost_s: float | None = None
    token_lost_at: float | None = None  # ``token_lost_s`` on the mission clock
    heard_s: float | None = None  # last telemetry (or status)
    heard_at: float | None = None  # ``heard_s`` on the mission clock
    silent_since: float | None = None  # mission time a silent spell began (None: not silent)
    telemetry_s: float | None = None  # when ``telemetry`` arrived
    lost: bool = True
    lost_s: float | None = None
    telemetry: Telemetry | None = None
    status: AgentStatus | None = None
    down: Change | None = None  # CRASHED / FAILED already reported for the current spell
    handled: tuple[str | None, float] | None = None  # (tool, agent stamp) of its last pick / drop


def _down(uav: _Uav) -> Change | None:
    """Whether the UAV's own reports say it cannot fly (any more, or for now)."""
    if uav.telemetry is not None and uav.telemetry.flight_state == FlightState.CRASHED:
        return Change.CRASHED
    if uav.status is not None and uav.status.state == AgentState.FAILED:
        return Change.FAILED
    if uav.status is not None and uav.status.state == AgentState.NOT_READY:
        return Change.NOT_READY
    return None


class FleetMonitor:
    """Tracks every UAV of the fleet; feed it tokens, telemetry and status."""

    def __init__(
        self,
        uav_ids: list[str],
        link_timeout_s: float,
        mission_clock: Callable[[], float] = time.time,
    ) -> None:
        self.link_timeout_s = link_timeout_s
        self.mission_clock = mission_clock
        self._uavs = {uav_id: _Uav() for uav_id in uav_ids}
        self._checked_s: float | None = None  # the clock at the last check

    def known(self, uav_id: str) -> bool:
        """Whether ``uav_id`` belongs to the fleet."""
        return uav_id in self._uavs

    def on_token(self, uav_id: str, alive: bool, now_s: float) -> None:
        """The agent's liveliness token appeared or vanished."""
        uav = self._uavs.get(uav_id)
        if uav is None:
            return
        uav.token = alive
        uav.token_lost_s = None if alive else now_s
        uav.token_lost_at = None if alive else self.mission_clock()

    def on_telemetry(self, telemetry: Telemetry, now_s: float) -> None:
        """A telemetry sample arrived (stamped with the receiver's clock)."""
        uav = self._uavs.get(telemetry.uav_id)
        if uav is not None:
            uav.telemetry = telemetry
            uav.heard_s = uav.telemetry_s = now_s
            uav.heard_at = self.mission_clock()

    def on_status(self, status: AgentStatus, now_s: float | None = None) -> None:
        """An agent status arrived (at ``now_s`` of the receiver's clock: the
        agent is heard, even while it has no position to send telemetry of)."""
        uav = self._uavs.get(status.uav_id)
        if uav is not None:
            uav.status = status
            if now_s is not None:
                uav.heard_s, uav.heard_at = now_s, self.mission_clock()

    def silence_s(self, uav_id: str, now_s: float) -> float:
        """How long ``uav_id`` has been silent (``inf`` if never heard)."""
        uav = self._uavs[uav_id]
        if uav.heard_s is None:
            return float("inf")
        token_silence = 0.0 if uav.token else now_s - (uav.token_lost_s or now_s)
        return max(token_silence, now_s - uav.heard_s)

    def silent_since(self, uav_id: str) -> float | None:
        """Mission time the silent spell of ``uav_id`` began (None: not silent)."""
        return self._uavs[uav_id].silent_since

    def check(self, now_s: float) -> list[tuple[str, Change]]:
        """Apply the timeout; return the UAVs that became lost or came back,
        and those that fell silent or were heard again meanwhile."""
        self._checked_s = now_s
        changes: list[tuple[str, Change]] = []
        for uav_id, uav in self._uavs.items():
            down = _down(uav)
            if down is not None and uav.down is None and not uav.lost:
                changes.append((uav_id, down))
            elif down is None and uav.down is not None and not uav.lost:
                # its reports are healthy again (e.g. a restarted agent that
                # reported failed until its autopilot answered): back, so that
                # it gets a fresh plan instead of flying the one it resynced
                changes.append((uav_id, Change.BACK))
            # a lost UAV's state is said once it is back (the next check)
            uav.down = None if uav.lost else down
            silence = self.silence_s(uav_id, now_s)
            if silence >= self.link_timeout_s and not uav.lost:
                uav.lost, uav.lost_s, uav.silent_since = True, now_s, None
                changes.append((uav_id, Change.LOST))
            elif uav.lost and uav.token and silence < self.link_timeout_s:
                uav.lost, uav.lost_s = False, None
                changes.append((uav_id, Change.BACK))
            elif not uav.lost:
                changes += _spell(uav_id, uav, silence)
        return changes

    def available(self, uav_id: str) -> bool:
        """Present and neither failed nor in emergency: can take work."""
        return self.state(uav_id) in {UavOpState.IDLE, UavOpState.BUSY, UavOpState.RECHARGING}

    def state(self, uav_id: str) -> UavOpState:
        """The state operators see."""
        uav = self._uavs[uav_id]
        if uav.lost:
            return UavOpState.LOST
        if uav.telemetry is not None and uav.telemetry.flight_state == FlightState.CRASHED:
            return UavOpState.FAILED
        if uav.status is None:
            return UavOpState.IDLE
        return _FROM_AGENT[uav.status.state]

    def telemetry(self, uav_id: str) -> Telemetry | None:
        """The latest telemetry of ``uav_id``."""
        return self._uavs[uav_id].telemetry

    def on_handled_tool(self, uav_id: str, tool: str | None, stamp_s: float) -> None:
        """``uav_id`` reported a completed pick of ``tool`` (or a drop: None)
        at ``stamp_s`` of its clock, which telemetry may not show yet."""
        uav = self._uavs.get(uav_id)
        if uav is not None:
            uav.handled = (tool, stamp_s)

    def tool(self, uav_id: str) -> str | None:
        """The tool ``uav_id`` holds: its latest telemetry's, unless a pick or
        drop it reported later says otherwise (a plan made between the two
        would pick the tool again)."""
        uav = self._uavs[uav_id]
        seen = uav.telemetry
        if uav.handled is not None and (seen is None or uav.handled[1] > seen.stamp_s):
            return uav.handled[0]
        return seen.tool if seen is not None else None

    def status(self, uav_id: str) -> AgentStatus | None:
        """The latest status of ``uav_id``."""
        return self._uavs[uav_id].status

    def traffic(self, now_s: float) -> Traffic:
        """Every UAV last heard airborne (within ``TRAFFIC_MAX_AGE_S``),
        lost ones included: where they were is where they may still hover."""
        entries = []
        for uav_id, uav in self._uavs.items():
            t, seen = uav.telemetry, uav.telemetry_s
            if t is None or seen is None or now_s - seen > TRAFFIC_MAX_AGE_S:
                continue
            airborne = t.flight_state in AIRBORNE
            entries.append(
                TrafficEntry(
                    uav_id=uav_id,
                    position=t.position,
                    airborne=airborne,
                    age_s=now_s - seen,
                    target=t.target,
                )
            )
        return Traffic(uavs=entries)

    def snapshot(self, plans: Mapping[str, Plan]) -> list[UavState]:
        """Every UAV's state for a :class:`proto.rpc.FleetReply`; a silent
        one's tasks in ``plans`` (each UAV's current plan) are unknown."""
        out = []
        checked_s = self._checked_s
        for uav_id, uav in self._uavs.items():
            silence = (
                self.silence_s(uav_id, checked_s)
                if uav.silent_since is not None and checked_s is not None
                else None
            )
            silent = silence is not None
            plan = plans.get(uav_id)
            state = self.state(uav_id)
            status = uav.status
            if status is not None and status.holding_for and state in FALLEN:
                status = msgspec.structs.replace(status, holding_for=None)
            out.append(
                UavState(
                    uav_id=uav_id,
                    state=state,
                    telemetry=uav.telemetry,
                    status=status,
                    silent_s=round(silence, 1) if silence is not None else None,
                    silent_since_s=uav.silent_since if silent else None,
                    unknown_tasks=unknown_tasks(plan, uav.status) if silent and plan else [],
                )
            )
        return out


def _spell(uav_id: str, uav: _Uav, silence: float) -> list[tuple[str, Change]]:
    """A present UAV's silent spell begins (``SILENT``) or ends (``HEARD``), once each."""
    silent = silence >= SILENT_AFTER_S
    if silent and uav.silent_since is None:
        uav.silent_since = _began(uav)
        return [(uav_id, Change.SILENT)]
    if not silent and uav.silent_since is not None:
        uav.silent_since = None
        return [(uav_id, Change.HEARD)]
    return []


def _began(uav: _Uav) -> float:
    """Mission time the present UAV's silence began: when it was last heard,
    or when its token vanished if that was earlier."""
    assert uav.heard_s is not None and uav.heard_at is not None  # present: it was heard
    token_first = uav.token_lost_s is not None and uav.token_lost_s < uav.heard_s
    if not uav.token and token_first and uav.token_lost_at is not None:
        return uav.token_lost_at
    return uav.heard_at


def unknown_tasks(plan: Plan, status: AgentStatus | None) -> list[str]:
    """The tasks of ``plan`` a silent UAV may be flying or have yet to fly:
    from the one it last reported running on (all if it reported none of them)."""
    ids = [t.task_id for t in plan.tasks]
    running = status.task_id if status is not None else None
    return ids[ids.index(running) :] if running in ids else ids
