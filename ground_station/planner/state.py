"""The planner's internal job and state records (see ``simulate``).

Records built by the ten thousand in the planning loops (steps, bookings,
candidates) are msgspec Structs, frozen, with ``gc=False`` when they hold no
containers: a NamedTuple's constructor is a Python function, about eight
times the cost of building a tuple; a Struct's is about one and a half.
Sort keys sorted by the thousand stay tuples (``list.sort`` compares exact
tuples fastest); each says so where it is defined.
"""

from __future__ import annotations

from typing import NamedTuple

import msgspec

from ground_station.planner.model import Vec3
from ground_station.planner.result import Step, StepKind


class Visit:
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
        kind: StepKind,
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

    def _with(self, service_s: float, release_s: float) -> Visit:
        return Visit(
            self.kind,
            self.action_id,
            self.index,
            self.pos,
            service_s,
            release_s,
            self.anchor_s,
            self.tool,
        )

    def copy_topup(self) -> Visit:
        """This task, recharging before it if at all possible."""
        t = self._with(self.service_s, self.release_s)
        t.topup, t.full_s = True, self.full_s
        return t

    def released(self, release_s: float) -> Visit:
        """This task, not to be started before ``release_s``."""
        t = self._with(self.service_s, release_s)
        t.topup, t.full_s = self.topup, self.full_s
        return t

    def resumed(self) -> Visit:
        """This running task redone in full (after a recharge or interruption)."""
        return self if self.full_s is None else self._with(self.full_s, self.release_s)

    def __repr__(self) -> str:
        return f"Visit({self.kind},{self.action_id},{self.index},{self.anchor_s})"


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


def wait_step(start_s: float, end_s: float, energy_wh: float, pos: Vec3) -> Step:
    """A wait where the UAV is (landed, or hovering).

    Every step the planner builds gives ``distance_m``, 0 too: msgspec omits
    a default field only if it holds the default object itself, and plans
    have always carried it."""
    return Step(
        kind="wait",
        start_s=start_s,
        arrive_s=start_s,
        end_s=end_s,
        energy_after_wh=energy_wh,
        position_m=pos,
        distance_m=0.0,
    )


class Booking(msgspec.Struct, frozen=True, gc=False):
    """A reservation of a shared resource (a charging station's pads, or a
    hold point) from ``start_s`` to ``end_s``; see ``pads.Pads``."""

    resource: int
    start_s: float
    end_s: float


class Sim(NamedTuple):
    """Simulated tasks: steps, per-task first-step index, states, reservations."""

    steps: list[Step]
    marks: list[int]
    states: list[State]
    res: list[Booking]
    old_next: int = -1  # converged: the old route from this task on is unchanged
