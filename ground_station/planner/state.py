"""The planner's internal job and state records (see ``simulate``)."""

from __future__ import annotations

from typing import NamedTuple

from ground_station.planner.model import Vec3


class Task:
    """One schedulable job on a UAV (see ``simulate``)."""

    __slots__ = (
        "action_id",
        "anchor_s",
        "full_s",
        "index",
        "kind",
        "pos",
        "release_s",
        "service_s",
        "tool",
        "topup",
    )

    def __init__(
        self,
        kind: str,
        action_id: str,
        index: int | None,
        pos: Vec3,
        service_s: float,
        release_s: float = 0.0,
        anchor_s: float | None = None,
        tool: str | None = None,
    ) -> None:
        self.kind = kind
        self.action_id = action_id
        self.index = index
        self.pos = pos
        self.service_s = service_s
        self.release_s = release_s
        self.anchor_s = anchor_s
        self.tool = tool
        self.topup = False  # recharge before this task if at all possible
        self.full_s: float | None = None  # a running task's full service, if resumed later

    def _with(self, service_s: float, release_s: float) -> Task:
        return Task(
            self.kind,
            self.action_id,
            self.index,
            self.pos,
            service_s,
            release_s,
            self.anchor_s,
            self.tool,
        )

    def copy_topup(self) -> Task:
        """This task, recharging before it if at all possible."""
        t = self._with(self.service_s, self.release_s)
        t.topup, t.full_s = True, self.full_s
        return t

    def released(self, release_s: float) -> Task:
        """This task, not to be started before ``release_s``."""
        t = self._with(self.service_s, release_s)
        t.topup, t.full_s = self.topup, self.full_s
        return t

    def resumed(self) -> Task:
        """This running task redone in full (after a recharge or interruption)."""
        return self if self.full_s is None else self._with(self.full_s, self.release_s)

    def __repr__(self) -> str:
        return f"Task({self.kind},{self.action_id},{self.index},{self.anchor_s})"


class Fail(str):
    """A reason code that also says which task (``task_index``) failed."""

    task_index: int = -1


class State(NamedTuple):
    """A UAV between tasks."""

    t: float
    pos: Vec3
    e: float
    landed: bool
    tool: str | None


# Internal step tuple: (kind, start, arrive, end, e_after, pos, action_id,
# index, station_id, tool, distance_m)
RawStep = tuple


class Sim(NamedTuple):
    """Simulated tasks: steps, per-task first-step index, states, reservations."""

    steps: list[RawStep]
    marks: list[int]
    states: list[State]
    res: list[tuple[int, float, float]]
    old_next: int = -1  # converged: the old route from this task on is unchanged
