"""The vocabulary of a replan: its inputs (:class:`ReplanJob`, taken on the loop),
its result (:class:`Computed`, planned off the loop), what it did
(:class:`ReplanOutcome`), the counters (:class:`ReplanStats`) and the
settings of the background improvement (:class:`ImproveSettings`)."""

from __future__ import annotations

import dataclasses

from ground_station import planner as pl
from ground_station.lifecycle import ActionEvent
from ground_station.live_plan import Candidate
from ground_station.planning import UavNow
from proto.mission import ActionRecord
from proto.plan import MonitorTask, Plan, Task


@dataclasses.dataclass
class ReplanOutcome:
    """What one replan did."""

    epoch: int
    changed: list[Plan]
    action_events: dict[str, tuple[ActionEvent, str]]
    planning_time_s: float


@dataclasses.dataclass
class ReplanStats:
    """Count and latency of replans."""

    count: int = 0
    total_s: float = 0.0
    last_s: float = 0.0
    plans_sent: int = 0
    unchanged: int = 0  # replans that changed no UAV's plan (no event, no epoch)
    incremental: int = 0  # replans applied as events to the kept session
    rebuilds: int = 0  # replans that rebuilt the session from the state
    dropped: int = 0  # results dropped because the state changed meanwhile
    improvements_tried: int = 0
    improvements_adopted: int = 0
    improvements_rejected: int = 0
    improvements_interrupted: int = 0


@dataclasses.dataclass
class ReplanJob:
    """A replan's inputs, taken on the loop; planned on the worker's thread."""

    records: list[ActionRecord]
    now_s: float
    reason: str
    uavs: list[UavNow]
    starts: dict[str, float]
    version: int
    flying: dict[str, MonitorTask] = dataclasses.field(default_factory=dict)  # segments flown now
    frozen: dict[str, list[Task]] | None = None  # improvement: tasks that must stay


@dataclasses.dataclass
class Computed:
    """A replan's result, to be committed on the loop."""

    job: ReplanJob
    tasks: dict[str, list[Task]]
    result: pl.Solution | None = None  # None: the planner refused the problem
    error: str = ""
    elapsed_s: float = 0.0
    incremental: bool = False
    rebuilt_for: str = ""  # why the session was rebuilt (when it was)
    candidate: Candidate | None = None  # an improvement (then ``job.reason`` says so)

    @property
    def how(self) -> str:
        """How the plan was made: improved, incremental, or rebuilt (and why)."""
        if self.candidate is not None:
            return "improved"
        return "incremental" if self.incremental else f"rebuilt: {self.rebuilt_for}"


@dataclasses.dataclass(frozen=True)
class ImproveSettings:
    """The anytime improvement and its hysteresis."""

    enabled: bool = True
    rounds: int = 200  # local-search rounds per attempt (deterministic for state + seed)
    margin: float = 0.02  # adopt only if better by this fraction of the objective
    freeze_s: float = 30.0  # tasks starting within this many mission s never change
    attempts: int = 10  # attempts per state at most (each goes on from the last one)
    seed: int = 0
