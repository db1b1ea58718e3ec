"""Reading a run directory: what ``linecrew report`` and ``export`` show.

A run directory (``linecrew up`` / ``demo``, :class:`~linecrew.launch.local_run.LocalRun`)
holds ``scenario.json`` (the site and fleet), ``run.json`` (speed-up, start),
``gs.db`` (the ground station's store: actions with their transitions,
plans by epoch, events) and ``flight.jsonl`` (telemetry, agent status and
task outcomes as the UAVs reported them). Times below are mission seconds
since the run started (``t0``).
"""

from __future__ import annotations

import dataclasses
import json
import pathlib
import sqlite3
from typing import Any

import msgspec

from proto import codec
from proto.errors import LinecrewError
from proto.events import GsEvent
from proto.mission import ActionRecord
from proto.plan import Plan
from proto.scenario import Scenario

TERMINAL = {"completed", "failed", "cancelled"}


def tag(value: msgspec.Struct) -> str:
    """The wire tag of a task or an action (``inspect``, ``monitor``, ...)."""
    return str(type(value).__struct_config__.tag)


class RunDirError(LinecrewError, RuntimeError):
    """Not a run directory, or one whose store cannot be read; the message says what is missing."""

    code = "run_dir_invalid"


@dataclasses.dataclass(frozen=True)
class Segment:
    """One task interval of a UAV on the report's clock."""

    uav_id: str
    start_s: float
    end_s: float
    kind: str
    task_id: str
    action_id: str | None = None
    result: str = ""  # completed / failed / aborted, "" when planned or unknown
    reason: str = ""


@dataclasses.dataclass(frozen=True)
class Transition:
    """An action's change of state."""

    from_state: str | None
    to_state: str
    stamp_s: float
    reason: str


@dataclasses.dataclass
class Run:
    """Everything read from one run directory."""

    run_dir: pathlib.Path
    scenario: Scenario
    about: dict[str, Any]
    actions: list[ActionRecord]
    transitions: dict[str, list[Transition]]
    events: list[GsEvent]
    plans: list[Plan]  # every epoch of every UAV, by epoch
    flight: list[dict[str, Any]]  # flight.jsonl lines, by time
    t0: float  # mission seconds at the start of the run

    @property
    def uav_ids(self) -> list[str]:
        """Every UAV of the fleet, in scenario order."""
        return [u.id for u in self.scenario.fleet.uavs]

    @property
    def end_s(self) -> float:
        """The last moment anything was recorded (report clock)."""
        stamps = [line["t"] for line in self.flight] + [e.stamp_s for e in self.events]
        return max(stamps, default=self.t0) - self.t0

    def kinds(self) -> dict[str, str]:
        """Task id -> task kind, from every plan."""
        return {t.task_id: tag(t) for plan in self.plans for t in plan.tasks}

    def tracks(self) -> dict[str, list[tuple[float, float, float]]]:
        """UAV -> ``(t, x, y)`` from telemetry."""
        out: dict[str, list[tuple[float, float, float]]] = {u: [] for u in self.uav_ids}
        for line in self._lines("telemetry"):
            out.setdefault(line["uav_id"], []).append((line["t"] - self.t0, line["x"], line["y"]))
        return out

    def batteries(self) -> dict[str, list[tuple[float, float]]]:
        """UAV -> ``(t, battery fraction)`` from telemetry."""
        out: dict[str, list[tuple[float, float]]] = {u: [] for u in self.uav_ids}
        for line in self._lines("telemetry"):
            out.setdefault(line["uav_id"], []).append((line["t"] - self.t0, line["battery"]))
        return out

    def executed(self) -> list[Segment]:
        """What each UAV flew: a task begins when its agent's status names it
        and ends at its outcome (or when the status moves on)."""
        kinds = self.kinds()
        outcomes: dict[tuple[str, str], list[dict[str, Any]]] = {}
        for line in self._lines("outcome"):
            outcomes.setdefault((line["uav_id"], line["task_id"]), []).append(line)
        segments: list[Segment] = []
        open_: dict[str, tuple[str, float]] = {}

        def close(uav: str, task_id: str, start: float, until: float) -> None:
            done = [o for o in outcomes.get((uav, task_id), []) if start <= o["t"] <= until + 1.0]
            outcome = done[0] if done else None
            end = min(outcome["t"], until) if outcome else until
            segments.append(
                Segment(
                    uav_id=uav,
                    start_s=start - self.t0,
                    end_s=max(end, start) - self.t0,
                    kind=kinds.get(task_id, task_id.rsplit(".", 1)[-1]),
                    task_id=task_id,
                    action_id=outcome.get("action_id") if outcome else None,
                    result=outcome["result"] if outcome else "",
                    reason=outcome.get("reason", "") if outcome else "",
                )
            )

        for line in self._lines("status"):
            uav, task_id, t = line["uav_id"], line.get("task_id"), line["t"]
            current = open_.get(uav)
            if current and current[0] == task_id:
                continue
            if current:
                close(uav, current[0], current[1], t)
                del open_[uav]
            if task_id:
                open_[uav] = (task_id, t)
        end = max((line["t"] for line in self.flight), default=self.t0)
        for uav, (task_id, start) in open_.items():
            close(uav, task_id, start, end)
        action_of = {t.task_id: t.action_id for plan in self.plans for t in plan.tasks}
        return [
            s if s.action_id else dataclasses.replace(s, action_id=action_of.get(s.task_id))
            for s in segments
        ]

    def first_plan(self) -> tuple[int, list[Segment], int]:
        """The first plan that holds every action (else the one holding the
        most): its epoch, its tasks, and how many actions it holds."""
        wanted = {r.action_id for r in self.actions}
        epochs = sorted({p.epoch for p in self.plans if p.tasks})
        best: tuple[int, int, dict[str, Plan]] = (-1, 0, {})
        for epoch in epochs:
            in_force: dict[str, Plan] = {}
            for plan in self.plans:
                if plan.epoch <= epoch:
                    in_force[plan.uav_id] = plan  # plans are sorted by epoch
            held = {t.action_id for p in in_force.values() for t in p.tasks} & wanted
            if len(held) > best[1] or best[0] < 0:
                best = (epoch, len(held), in_force)
            if held == wanted:
                break
        epoch, count, in_force = best
        t0 = self.t0
        segments = [
            Segment(p.uav_id, t.start_s - t0, t.end_s - t0, tag(t), t.task_id, t.action_id)
            for p in in_force.values()
            for t in p.tasks
        ]
        return epoch, segments, count

    def ended_s(self, action_id: str) -> float | None:
        """When an action reached its final state (report clock), if it did."""
        ends = [t.stamp_s for t in self.transitions.get(action_id, []) if t.to_state in TERMINAL]
        return ends[-1] - self.t0 if ends else None

    def uavs_of(self, action_id: str) -> list[str]:
        """The UAVs that flew a task of the action (else that were planned to)."""
        flown = {s.uav_id for s in self.executed() if s.action_id == action_id}
        if not flown:
            flown = {p.uav_id for p in self.plans for t in p.tasks if t.action_id == action_id}
        return sorted(flown)

    def _lines(self, kind: str) -> list[dict[str, Any]]:
        return [line for line in self.flight if line.get("kind") == kind]


def load_run(run_dir: pathlib.Path) -> Run:
    """Read a run directory; :class:`RunDirError` if it is not one."""
    scenario_file, db = run_dir / "scenario.json", run_dir / "gs.db"
    for needed in (scenario_file, db):
        if not needed.is_file():
            raise RunDirError(
                f"{run_dir} is not a run directory: no {needed.name} "
                "(a run directory is what linecrew up / demo write, e.g. runs/<UTC time>)"
            )
    scenario = msgspec.json.decode(scenario_file.read_bytes(), type=Scenario)
    about = _json(run_dir / "run.json") or {}
    actions, transitions, events, plans = read_store(db)
    flight = read_flight(run_dir / "flight.jsonl")
    starts = [e.stamp_s for e in events] + [line["t"] for line in flight]
    starts += [r.created_s for r in actions]
    t0 = about.get("started_mission_s") or min(starts, default=0.0)
    return Run(run_dir, scenario, about, actions, transitions, events, plans, flight, t0)


def read_store(db: pathlib.Path) -> tuple[list, dict[str, list[Transition]], list, list]:
    """Actions, transitions by action, events and plans from a ground station's store."""
    try:
        conn = sqlite3.connect(f"file:{db}?mode=rw", uri=True)
    except sqlite3.Error as exc:
        raise RunDirError(f"{db}: {exc}") from exc
    try:
        rows = conn.execute("SELECT record FROM actions ORDER BY created_s, rowid").fetchall()
        actions = [codec.decode(r[0], ActionRecord) for r in rows]
        transitions: dict[str, list[Transition]] = {}
        for action_id, old, new, stamp, reason in conn.execute(
            "SELECT action_id, from_state, to_state, stamp_s, reason FROM transitions ORDER BY id"
        ):
            transitions.setdefault(action_id, []).append(Transition(old, new, stamp, reason))
        events = [
            codec.decode(r[0], GsEvent)
            for r in conn.execute("SELECT event FROM events ORDER BY seq")
        ]
        plans = [
            codec.decode(r[0], Plan)
            for r in conn.execute("SELECT plan FROM plans ORDER BY epoch, uav_id")
        ]
    except sqlite3.Error as exc:
        raise RunDirError(f"{db}: not a linecrew store ({exc})") from exc
    finally:
        conn.close()
    return actions, transitions, events, plans


def read_flight(path: pathlib.Path) -> list[dict[str, Any]]:
    """The flight log's lines, by time (none if the run has no flight log);
    a line cut short by a kill is skipped."""
    if not path.is_file():
        return []
    lines = []
    for text in path.read_text(encoding="utf-8").splitlines():
        try:
            lines.append(json.loads(text))
        except ValueError:
            continue
    return sorted(lines, key=lambda line: line.get("t", 0.0))


def _json(path: pathlib.Path) -> Any:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None
