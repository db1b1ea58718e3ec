"""The allocation cost of the paper: w1*J1 + w2*J2 + w3*J3.

complete mode: J2 is the time (s, from ``now_s``) at which the part is
finished, so travel, queueing and recharge detours all count, plus the delay
pushed onto the UAV's later tasks. paper mode: J2 is the distance (m) from
the end of the UAV's last task to the part's start, as in the released code.
"""

from __future__ import annotations

from math import dist

from ground_station.planner.model import CostWeights, RunningTask, Vec3
from ground_station.planner.simulate import State


def j1(caps: dict[str, float], kind: str) -> float:
    """Type suitability: 0 ideal .. 1 barely acceptable (inf if incapable)."""
    return caps.get(kind, float("inf"))


def j3(running: RunningTask | None, action_id: str) -> float:
    """Interruption term: -1 for continuing the action the UAV is running."""
    return -1.0 if running is not None and running.action_id == action_id else 0.0


def j3_interrupt(running_weight: float, new_weight: float) -> float:
    """Interruption term for displacing a running task: 1 plus the running
    action's weight relative to the new one (higher priority costs more)."""
    return 1.0 + running_weight / new_weight


def complete_cost(
    w: CostWeights, suit: float, finish_s: float, now_s: float, delay_s: float, j3_value: float
) -> float:
    return (
        w.suitability_s * suit
        + w.travel * (finish_s - now_s + delay_s)
        + w.interruption_s * j3_value
    )


def paper_cost(w: CostWeights, suit: float, tail: State, start: Vec3, j3_value: float) -> float:
    return w.suitability_s * suit + w.travel * dist(tail.pos, start) + w.interruption_s * j3_value
