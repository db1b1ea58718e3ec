"""Mutable planning state: one task route per UAV plus the shared pads.

Lists in a ``Route`` are replaced, never mutated in place, so a snapshot is
a cheap tuple of references (used to try and roll back drafts).
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass, field
from math import dist
from typing import NamedTuple

import msgspec

from ground_station.planner.energy import Kin, SiteMap
from ground_station.planner.model import (
    CostWeights,
    DeliverJob,
    InspectJob,
    Job,
    Problem,
    RunningTask,
)
from ground_station.planner.pads import Pads
from ground_station.planner.result import Step, Unplaced
from ground_station.planner.simulate import Sim, State, Visit, simulate


@dataclass(frozen=True, kw_only=True)
class Options:
    """Planner options.

    ``mode``: ``"complete"`` (this planner) or ``"paper"`` (the plain paper
    heuristic: distance-based J2 with the paper's 50/1/3 weights, fixed
    1/2/3-way splits, append-only, recharges only when a task would not fit).
    ``weights`` overrides the problem's cost weights.
    """

    mode: str = "complete"
    weights: CostWeights | None = None
    max_split: int = 4
    resource_factor: float = 0.3
    """Weight of the UAV time an inspection split uses when choosing how many
    UAVs share it (more finish sooner but take the fleet from later actions)."""
    max_eval: int = 6
    """complete mode simulates at most this many insertion candidates per
    part (best lower bounds first)."""
    restarts: int | None = None
    """Differently tuned constructions tried by time-bounded improvement
    before local search; None chooses by instance size."""


class GapCache(NamedTuple):
    """Insertion positions worth trying in a route (``insertion.gap_positions``),
    valid while its task list is ``tasks`` and ``anywhere`` is unchanged."""

    tasks: list[Visit]
    anywhere: bool
    positions: list[int]


class Route:
    """A UAV's tasks and their simulation (steps exclude the final home leg)."""

    __slots__ = ("gap_cache", "init", "kin", "marks", "states", "steps", "tasks")

    def __init__(self, kin: Kin, init: State) -> None:
        self.kin = kin
        self.init = init
        self.tasks: list[Visit] = []
        self.states: list[State] = []
        self.steps: list[Step] = []
        self.marks: list[int] = []
        self.gap_cache: GapCache | None = None

    def state_before(self, pos: int) -> State:
        return self.states[pos - 1] if pos > 0 else self.init

    def tail(self) -> State:
        return self.states[-1] if self.states else self.init


class RouteState(msgspec.Struct, frozen=True, gc=False):
    """A route's lists at a snapshot (they are replaced, never mutated)."""

    init: State
    tasks: list[Visit]
    states: list[State]
    steps: list[Step]
    marks: list[int]


class Snapshot(NamedTuple):
    """A planning state to roll back to (``Ctx.snapshot``)."""

    routes: dict[str, RouteState]
    pads: Pads
    unplaced: dict[str, list[Unplaced]]


class Grounded(NamedTuple):
    """A UAV in a battery fault: it lands at ``station_id`` from ``state``."""

    station_id: str
    state: State
    kin: Kin


@dataclass
class Ctx:
    """Everything the heuristic mutates while planning."""

    problem: Problem
    options: Options
    site: SiteMap
    routes: dict[str, Route]
    pads: Pads
    actions: dict[str, Job]
    weights: CostWeights
    unplaced: dict[str, list[Unplaced]] = field(default_factory=dict)
    running: dict[str, RunningTask] = field(default_factory=dict)  # by UAV, in routes
    pinned: set[tuple[str, int | None]] = field(default_factory=set)
    anywhere: bool = False  # improvement: also insert between any two actions
    fast: bool = False  # replanning: fewer alternatives per placement
    rng: random.Random | None = None  # improvement: randomised placement choices
    emergency: dict[str, Grounded] = field(default_factory=dict)
    last_fail: Visit | None = None  # the task that made the last removal fail

    # -- drafts -----------------------------------------------------------
    def snapshot(self) -> Snapshot:
        routes = {
            u: RouteState(r.init, r.tasks, r.states, r.steps, r.marks)
            for u, r in self.routes.items()
        }
        unplaced = {a: list(v) for a, v in self.unplaced.items()}
        return Snapshot(routes, self.pads.copy(), unplaced)

    def restore(self, snap: tuple) -> None:
        """Go back to ``snap``, a ``Snapshot`` (callers may keep it as a plain tuple)."""
        routes, pads, unplaced = snap
        for u, saved in routes.items():
            r = self.routes[u]
            r.init, r.tasks, r.states = saved.init, saved.tasks, saved.states
            r.steps, r.marks = saved.steps, saved.marks
        self.pads = pads.copy()
        self.unplaced = {a: list(v) for a, v in unplaced.items()}

    # -- route edits --------------------------------------------------------
    def try_insert(self, uid: str, pos: int, new: list[Visit]) -> Sim | str:
        """Simulate ``new`` inserted at ``pos`` plus the suffix after it
        (stopping early where the suffix is unchanged)."""
        r = self.routes[uid]
        st = r.state_before(pos)
        if pos >= len(r.tasks):
            return simulate(r.kin, self.site, self.pads, st, new, (uid, st.t))
        tasks = new + r.tasks[pos:]
        old_map = [-1] * len(new) + list(range(pos, len(r.tasks)))
        return simulate(r.kin, self.site, self.pads, st, tasks, (uid, st.t), r.states, old_map)

    def _resumed(self, uid: str) -> list[Visit]:
        """The route with its running first task turned into a normal one (a
        task that is interrupted is redone in full when resumed)."""
        r = self.routes[uid]
        return [r.tasks[0].resumed(), *r.tasks[1:]]

    def try_preempt(self, uid: str, new: list[Visit]) -> Sim | str:
        """Simulate ``new`` before the UAV's running task (J3 interruption)."""
        r = self.routes[uid]
        tasks = new + self._resumed(uid)
        old_map = [-1] * (len(new) + 1) + list(range(1, len(r.tasks)))
        return simulate(
            r.kin, self.site, self.pads, r.init, tasks, (uid, r.init.t), r.states, old_map
        )

    def commit_preempt(self, uid: str, new: list[Visit], sim: Sim) -> None:
        """Apply ``try_preempt``; the interrupted task stays pinned to this UAV."""
        self._replace_suffix(uid, 0, new + self._resumed(uid), sim)

    def commit(self, uid: str, pos: int, new: list[Visit], sim: Sim) -> None:
        """Apply a successful ``try_insert``."""
        r = self.routes[uid]
        self._replace_suffix(uid, pos, new + r.tasks[pos:], sim)

    def _replace_suffix(self, uid: str, pos: int, tasks: list[Visit], sim: Sim) -> None:
        """The route's tasks from ``pos`` become ``tasks`` as simulated by
        ``sim`` (if ``sim`` converged, the old route's tail is kept as is)."""
        r = self.routes[uid]
        st = r.state_before(pos)
        base = r.marks[pos] if pos < len(r.marks) else len(r.steps)
        n = len(sim.states)
        on = sim.old_next
        if on < 0:
            r.tasks = r.tasks[:pos] + tasks
            r.states = r.states[:pos] + sim.states
            r.marks = r.marks[:pos] + [base + m for m in sim.marks]
            r.steps = r.steps[:base] + sim.steps
            self.pads.remove_uav(uid, st.t)
        else:
            conv_t = r.states[on - 1].t
            old_base = r.marks[on] if on < len(r.marks) else len(r.steps)
            shift = base + len(sim.steps) - old_base
            r.tasks = r.tasks[:pos] + tasks[:n] + r.tasks[on:]
            r.states = r.states[:pos] + sim.states + r.states[on:]
            r.marks = (
                r.marks[:pos] + [base + m for m in sim.marks] + [m + shift for m in r.marks[on:]]
            )
            r.steps = r.steps[:base] + sim.steps + r.steps[old_base:]
            self.pads.remove_uav(uid, st.t, conv_t)
        self.pads.book(sim.res, uid)

    def remove_tasks(self, uid: str, pred: Callable[[Visit], bool]) -> list[Visit] | None:
        """Remove matching tasks and re-simulate; None (unchanged) if infeasible."""
        r = self.routes[uid]
        first = next((i for i, t in enumerate(r.tasks) if pred(t)), None)
        if first is None:
            return []
        removed = [t for t in r.tasks[first:] if pred(t)]
        last = max(i for i, t in enumerate(r.tasks) if pred(t))
        keep: list[Visit] = []
        old_map: list[int] = []
        for i in range(first, len(r.tasks)):
            if not pred(r.tasks[i]):
                keep.append(r.tasks[i])
                old_map.append(i if i > last else -1)
        st = r.state_before(first)
        ign = (uid, st.t)
        sim = simulate(r.kin, self.site, self.pads, st, keep, ign, r.states, old_map)
        for _ in range(3):
            # Repair: a later task may need the recharge the removed work used
            # to trigger; ask for a top-up just before the failing task.
            if not isinstance(sim, str) or sim.task_index < 0:
                break
            failed = sim.task_index
            j = failed if keep[failed].anchor_s is None else max(0, failed - 1)
            if keep[j].topup:
                break
            keep = [*keep[:j], keep[j].copy_topup(), *keep[j + 1 :]]
            sim = simulate(r.kin, self.site, self.pads, st, keep, ign, r.states, old_map)
        if isinstance(sim, str):
            self.last_fail = keep[sim.task_index] if sim.task_index >= 0 else None
            return None
        self._replace_suffix(uid, first, keep, sim)
        return removed

    def remove_displacing(self, uid: str, pred: Callable[[Visit], bool]) -> set[str]:
        """Remove matching tasks; if a later task no longer fits, also remove
        that task's whole action from this route. Returns those displaced
        actions (the caller re-plans them); always succeeds."""
        displaced: set[str] = set()
        for _ in range(len(self.routes[uid].tasks) + 1):
            gone = self.remove_tasks(uid, lambda t: pred(t) or t.action_id in displaced)
            if gone is not None:
                return displaced
            fail = self.last_fail
            if fail is None or fail.action_id in displaced:
                break
            displaced.add(fail.action_id)
        # Give up on finesse: drop everything after the first removed task.
        r = self.routes[uid]
        first = next(i for i, t in enumerate(r.tasks) if pred(t) or t.action_id in displaced)
        displaced |= {t.action_id for t in r.tasks[first:] if not pred(t)}
        self.remove_tasks(uid, lambda t: pred(t) or t.action_id in displaced)
        return displaced

    def reinit(self, uid: str, init: State) -> bool:
        """Change a UAV's initial state and re-simulate its whole route."""
        r = self.routes[uid]
        sim = simulate(r.kin, self.site, self.pads, init, r.tasks, (uid, -1e18))
        if isinstance(sim, str):
            return False
        r.init = init
        tasks = r.tasks
        r.tasks, r.states, r.steps, r.marks = [], [], [], []
        self.pads.remove_uav(uid, -1e18)
        self.commit(uid, 0, tasks, sim)
        return True

    # -- queries --------------------------------------------------------------
    def capable(self, kind: str) -> list[str]:
        return [u for u, r in self.routes.items() if kind in r.kin.caps]

    def add_unplaced(self, action_id: str, part: int | None, reason: str) -> None:
        self.unplaced.setdefault(action_id, []).append(
            Unplaced(action_id=action_id, part=part, reason=reason)
        )

    def placed_uavs(self, action_id: str) -> list[str]:
        return [u for u, r in self.routes.items() if any(t.action_id == action_id for t in r.tasks)]


def emergency_landing(problem: Problem, kin: Kin, st: State, site: SiteMap) -> str | None:
    """The station to land at if the UAV cannot reach any station above the
    reserve (a battery fault); None if it can plan normally (including a UAV
    on a charging station, which just recharges first)."""
    if site.charging and site.nearest(st.pos).distance_m < 1e-9:
        return None
    best = min(problem.stations, key=lambda s: dist(s.position_m, st.pos), default=None)
    if best is None:
        return None
    if st.e - dist(best.position_m, st.pos) * kin.wh_per_m >= kin.reserve_wh - 1e-6:
        return None
    return best.id


def queue_order(actions: list[Job] | tuple[Job, ...]) -> list[Job]:
    """The paper's FCFS-by-weight queue: heavier first, then release, then input order."""
    order = sorted(range(len(actions)), key=lambda i: (-actions[i].weight, actions[i].release_s, i))
    return [actions[i] for i in order]


def new_ctx(problem: Problem, options: Options) -> Ctx:
    """Build routes for the available UAVs, with running tasks pinned first."""
    site = SiteMap(problem)
    types = {t.id: t for t in problem.uav_types}
    actions = {a.id: a for a in problem.actions}
    routes: dict[str, Route] = {}
    emergency: dict[str, Grounded] = {}
    for u in problem.uavs:
        if not u.available:
            continue
        kin = Kin(u, types[u.type], problem.reserve_fraction, site.by_id[u.home_station])
        init = State(problem.now_s, u.position_m, u.energy_wh, not u.airborne, u.tool)
        landing = emergency_landing(problem, kin, init, site)
        if landing is not None:
            emergency[u.id] = Grounded(landing, init, kin)
        else:
            routes[u.id] = Route(kin, init)
    pads = Pads([s.pads for s in site.charging])
    weights = options.weights or (
        CostWeights(suitability_s=50.0, travel=1.0, interruption_s=3.0)
        if options.mode == "paper"
        else problem.weights
    )
    ctx = Ctx(problem, options, site, routes, pads, actions, weights, emergency=emergency)
    for u in problem.uavs:
        run = u.running
        if run is None or u.id not in routes:
            continue
        act = actions[run.action_id]
        ctx.running[u.id] = run
        task = None
        if isinstance(act, InspectJob):
            wp = act.waypoints[run.index]
            task = Visit("inspect", act.id, run.index, wp.position_m, run.remaining_s)
            task.full_s = wp.service_s
        elif isinstance(act, DeliverJob):
            task = Visit(
                "deliver", act.id, None, act.worker_m, run.remaining_s or act.drop_s, tool=act.tool
            )
            task.full_s = act.drop_s
        if task is not None:
            sim = ctx.try_insert(u.id, 0, [task])
            if not isinstance(sim, str):
                ctx.commit(u.id, 0, [task], sim)
                ctx.pinned.add((act.id, task.index))
    return ctx
