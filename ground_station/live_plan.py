"""The live planning state of the ground station: one incremental planner
``Session`` that every replan goes through, and the anytime improvement of
it with hysteresis.

Pure planning, no I/O, no clock: it runs on the planning worker's thread
(see :mod:`ground_station.plan_worker`), never in a Zenoh callback and never
on a request's path.

- **Incremental.** A session is built at a base mission time ``base_s``. A
  replan within ``window_s`` of it diffs the new problem (built on the same
  time base) against the session's and applies the differences as planner
  events: an action added, changed or cancelled, a UAV lost, a battery below
  what the session assumed. A UAV on its course (flying the session's plan:
  taken off, moved, its battery no lower than the plan has it by the end of
  the step in progress) is no difference but for its battery, taken as what
  it had at the session's start (the safe side): at 100 UAVs, rebuilding for every
  UAV that had moved rebuilt at every new action and re-dealt the work of
  a quarter of the fleet each time. An inspection or a delivery completed
  as planned (the first of the UAV's visits) is applied as a finished task,
  from where the UAV is then. Anything else (time moved on, a UAV moved off
  its plan, came back or charged, other work finished, an event the session
  refuses) rebuilds the session from the current state: the full rebuild is
  the fallback, with the same planner.
- **Improvement.** ``improve`` runs the planner's ruin-and-recreate local
  search on the session's state for a fixed number of rounds (deterministic
  for a state and a seed); the candidate is kept only if ``accept`` says so:
  better by ``margin`` (a fraction of the objective, or fewer unplaced
  parts) and no task started or starting within ``freeze_s`` changed.
  Otherwise the state is restored as it was; a candidate short only of the
  margin is kept aside (``keep``) and the next attempt goes on from it, so
  small gains add up until together they pass the margin.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Callable

from ground_station import planner as pl
from ground_station.planner import improve as improvement
from ground_station.planner.api import variants
from ground_station.session_changes import Rebuild, Visited, diff, planned_floor, visits_of
from proto.plan import InspectTask, MonitorTask, Task, WaitTask

Objective = tuple[int, float]
"""(unplaced parts, weight-averaged completion + makespan in seconds)."""


@dataclasses.dataclass
class Planned:
    """The outcome of one replan on the session."""

    plan: pl.Solution
    base_s: float  # mission seconds of the planner's time 0
    incremental: bool  # events applied to the kept session (else rebuilt)
    events: int  # planner events applied (0 when rebuilt)
    objective: Objective
    rebuilt_for: str = ""  # why the session was rebuilt (when it was)


@dataclasses.dataclass
class Candidate:
    """An improved plan, not yet adopted."""

    plan: pl.Solution
    base_s: float
    before: Objective
    after: Objective
    rounds: int
    session: pl.Session  # the live session, or a fresh construction of its problem
    state: tuple  # the candidate's planner state (to go on from it)
    restore: Callable[[], None]  # puts the live session back as it was before improving


class LivePlan:
    """The session every replan and improvement goes through."""

    def __init__(self, options: pl.Options | None = None, window_s: float = 10.0) -> None:
        self.options = options
        self.window_s = window_s
        self.session: pl.Session | None = None
        self.course: pl.Solution | None = None  # the session's plan, as last adopted
        self.base_s = 0.0
        self.stale = ""  # why the session no longer matches the plans held: rebuild
        self.rebuilds = 0
        self.incremental = 0
        self._kept: tuple[pl.Session, tuple] | None = None  # a candidate below the margin
        self._kept_objective: Objective = (0, 0.0)
        self._starts = 0  # constructions from scratch tried for this state
        self._finished: deque[tuple[str, list[Visited]]] = deque()  # (UAV, visits) since

    def unusable(self, now_s: float) -> str:
        """Why a replan at ``now_s`` may not use the session ("" if it may)."""
        if self.session is None:
            return "no session yet"
        if not 0 <= now_s - self.base_s <= self.window_s:
            return f"{now_s - self.base_s:.0f} s past the session's start"
        return self.stale

    def invalidate(self, why: str) -> None:
        """The next replan rebuilds, for ``why`` (a task finished, a result
        was dropped)."""
        self.stale = why
        self._new_state()

    def finished(self, uav_id: str, task: Task, completed: bool) -> None:
        """``task`` ended on ``uav_id`` (from the loop; the worker replans):
        a completed inspection or delivery is applied at the next replan as
        finished visits (if they were the UAV's next), a wait is no change;
        anything else rebuilds."""
        visits = visits_of(task) if completed else None
        if visits is None:
            self.invalidate(f"{uav_id} ended {task.task_id}")
        elif visits:
            self._finished.append((uav_id, visits))

    def objective(self) -> Objective | None:
        """The live state's objective, if planned."""
        return improvement.objective(self.session.ctx) if self.session else None

    # -- replans ---------------------------------------------------------------

    def replan(
        self, build: Callable[[float], pl.Problem], now_s: float, capacities: dict[str, float]
    ) -> Planned:
        """Plan the problem ``build(base)`` gives: incrementally on the kept
        session if it can, else a fresh session at ``now_s``. Raises
        ``PlanningProblemError`` if the problem itself is invalid."""
        self._new_state()  # candidates of the old state are moot
        why = self.unusable(now_s)
        if not why:
            assert self.session is not None and self.course is not None
            problem = build(self.base_s)
            try:
                self._apply_finished(problem)
                floors = planned_floor(self.course, now_s - self.base_s)
                events = diff(self.session.problem, problem, capacities, floors)
                for event in events:
                    self.session.apply(event)
                self.incremental += 1
                plan = self.course = self.session.plan()
                return Planned(plan, self.base_s, True, len(events), self._objective())
            except Rebuild as exc:
                why = str(exc)
            except pl.PlanningProblemError as exc:  # rebuild from the state
                why = f"the session refused the change: {exc}"
        self._finished.clear()  # the rebuilt session starts from them done
        problem = build(now_s)
        session = pl.Session(problem, self.options)
        self.session, self.base_s, self.stale = session, now_s, ""
        self.rebuilds += 1
        self.course = session.plan()
        return Planned(self.course, now_s, False, 0, self._objective(), why)

    def _apply_finished(self, problem: pl.Problem) -> None:
        """Apply the visits finished since the last replan (each UAV at its
        place in ``problem``); ``Rebuild`` if one was not the next planned."""
        assert self.session is not None
        uavs = {u.id: u for u in problem.uavs}
        while self._finished:
            uav_id, visits = self._finished.popleft()
            if self.session.next_visits(uav_id)[: len(visits)] != visits or uav_id not in uavs:
                raise Rebuild(f"{uav_id} finished work the session had not planned next")
            u = uavs[uav_id]
            for _ in visits:
                self.session.apply(
                    pl.TaskFinished(uav_id=u.id, position_m=u.position_m, energy_wh=u.energy_wh)
                )

    def _objective(self) -> Objective:
        assert self.session is not None
        return improvement.objective(self.session.ctx)

    # -- improvement -------------------------------------------------------------

    def improve(
        self,
        rounds: int,
        seed: int,
        frozen: set[tuple[str, int | None]],
        should_stop: Callable[[], bool] = lambda: False,
        restart: bool = False,
    ) -> Candidate | None:
        """Run ``rounds`` rounds of local search (tasks in ``frozen`` stay
        where they are). The search goes on from the best candidate kept for
        this state (``keep``), or from the session; with ``restart``, and
        while nothing is frozen, it starts instead from the next construction
        from scratch of the session's problem (the planner's tunings in turn,
        as the offline planner tries them): a state grown by many insertions
        is a poor start, and a search that stopped gaining needs another.
        None if interrupted by ``should_stop``; the session is then as it was."""
        if self.session is None or self.stale:
            return None
        live = self.session
        before = improvement.objective(live.ctx)
        snap = live.ctx.snapshot()
        stopped: list[bool] = []

        def stop() -> bool:
            if should_stop():
                stopped.append(True)
                return True
            return False

        work = live
        if restart and self.can_restart(frozen):
            fresh = pl.Session.build_until(live.problem, self._tunings()[self._starts], stop)
            if fresh is None:
                return None  # interrupted mid-construction: this start is tried again
            work, self._starts = fresh, self._starts + 1
        elif self._kept is not None:
            work, state = self._kept
            work.ctx.restore(state)
        ctx = work.ctx
        pinned = set(ctx.pinned)
        ctx.pinned = pinned | frozen
        try:
            improvement.improve(ctx, stop, max_rounds=rounds, seed=seed)
        finally:
            ctx.pinned = pinned

        def restore() -> None:
            live.ctx.restore(snap)

        if stopped:
            restore()
            return None
        after = improvement.objective(ctx)
        return Candidate(
            work.plan(), self.base_s, before, after, rounds, work, ctx.snapshot(), restore
        )

    def can_restart(self, frozen: set[tuple[str, int | None]]) -> bool:
        """Whether a restart from scratch is left for this state (nothing
        frozen, and a tuning not tried yet)."""
        return self.session is not None and not frozen and self._starts < len(self._tunings())

    def _tunings(self) -> list[pl.Options]:
        assert self.session is not None
        options = self.options or pl.Options()
        weights = options.weights or self.session.problem.weights
        return [options, *variants(options, weights)]

    def take(self, candidate: Candidate) -> None:
        """Adopt ``candidate``: its session is the live one from now on."""
        self.session, self.course = candidate.session, candidate.plan
        self._new_state()

    def keep(self, candidate: Candidate) -> None:
        """Remember a candidate not adopted (its gain is below the margin so
        far) if it is the best yet: later attempts on this state go on from
        it, so gains add up instead of being thrown away one by one."""
        if self._kept is None or candidate.after < self._kept_objective:
            self._kept = (candidate.session, candidate.state)
            self._kept_objective = candidate.after

    def kept_objective(self) -> Objective | None:
        """The objective of the best candidate kept for this state."""
        return self._kept_objective if self._kept is not None else None

    def _new_state(self) -> None:
        self._kept, self._kept_objective, self._starts = None, (0, 0.0), 0


# -- hysteresis -----------------------------------------------------------------


def better_by(before: Objective, after: Objective, margin: float) -> bool:
    """Whether ``after`` beats ``before`` by the margin: fewer unplaced
    parts, or as many and an objective lower by ``margin`` of it."""
    if after[0] != before[0]:
        return after[0] < before[0]
    return after[1] < before[1] * (1.0 - margin) - 1e-9


def frozen_tasks(plans: dict[str, list[Task]], now_s: float, freeze_s: float) -> dict[str, list]:
    """Per UAV, the tasks of its plan started or starting within ``freeze_s``
    (the plan's prefix up to the horizon)."""
    horizon = now_s + freeze_s
    out: dict[str, list] = {}
    for uav, tasks in plans.items():
        prefix = []
        for task in tasks:
            if task.start_s > horizon:
                break
            prefix.append(task)
        out[uav] = prefix
    return out


def frozen_parts(frozen: dict[str, list[Task]]) -> set[tuple[str, int | None]]:
    """The planner's (action, part) keys of the frozen tasks, to pin them."""
    parts: set[tuple[str, int | None]] = set()
    for tasks in frozen.values():
        for task in tasks:
            if task.action_id is None:
                continue
            if isinstance(task, InspectTask):
                parts |= {(task.action_id, w.index) for w in task.waypoints}
            elif isinstance(task, MonitorTask):
                parts.add((task.action_id, task.slot))
            else:
                parts.add((task.action_id, None))
    return parts


def freeze_broken(frozen: dict[str, list[Task]], candidate: dict[str, list[Task]]) -> list[str]:
    """The UAVs whose frozen tasks the candidate changes (other ids, order,
    or wait deadlines)."""
    return [
        uav
        for uav, prefix in frozen.items()
        if _signature(candidate.get(uav, [])[: len(prefix)]) != _signature(prefix)
    ]


def _signature(tasks: list[Task]) -> list[tuple[str, int]]:
    return [(t.task_id, round(t.until_s) if isinstance(t, WaitTask) else 0) for t in tasks]


def accept(
    before: Objective,
    after: Objective,
    frozen: dict[str, list[Task]],
    candidate: dict[str, list[Task]],
    margin: float,
) -> tuple[bool, str]:
    """The hysteresis: (adopt?, why)."""
    if not better_by(before, after, margin):
        return False, f"gain below the {margin:.1%} margin ({before[1]:.1f} -> {after[1]:.1f} s)"
    broken = freeze_broken(frozen, candidate)
    if broken:
        return False, f"would change frozen tasks of {', '.join(broken)}"
    return True, f"objective {before[1]:.1f} -> {after[1]:.1f} s"
