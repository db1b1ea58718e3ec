"""Incremental replanning: apply one event to a live plan.

A ``Session`` plans once, then ``apply(event)`` changes only what the event
touches: the routes carrying the affected action (or the affected UAV's
route) are edited and re-simulated, and the displaced parts re-inserted with
the heuristic's cheapest insertion; other routes are not rebuilt. Running
(pinned) tasks stay first on their UAV. Events take effect at the problem's
``now_s``: to move time forward, start a new session from a fresh problem.
"""

from __future__ import annotations

from collections.abc import Callable

import msgspec

from ground_station.planner import heuristic, monitor
from ground_station.planner.energy import Kin
from ground_station.planner.errors import PlanningProblemError
from ground_station.planner.export import export
from ground_station.planner.load import check_problem
from ground_station.planner.model import InspectJob, Job, MonitorJob, Problem, Uav, Vec3
from ground_station.planner.removal import remove
from ground_station.planner.result import Solution
from ground_station.planner.routes import (
    Ctx,
    Grounded,
    Options,
    Route,
    emergency_landing,
    queue_order,
)
from ground_station.planner.simulate import State, Visit, simulate

replace = msgspec.structs.replace


class ActionAdded(msgspec.Struct, frozen=True, kw_only=True, tag=True):
    action: Job


class ActionChanged(msgspec.Struct, frozen=True, kw_only=True, tag=True):
    action: Job


class ActionCancelled(msgspec.Struct, frozen=True, kw_only=True, tag=True):
    action_id: str


class TaskFinished(msgspec.Struct, frozen=True, kw_only=True, tag=True):
    """The UAV's first planned task is done; it is now at ``position_m``."""

    uav_id: str
    position_m: Vec3
    energy_wh: float


class UavLost(msgspec.Struct, frozen=True, kw_only=True, tag=True):
    uav_id: str


class UavBack(msgspec.Struct, frozen=True, kw_only=True, tag=True):
    uav: Uav


class BatteryLow(msgspec.Struct, frozen=True, kw_only=True, tag=True):
    """The UAV's battery is below the plan's estimate: it has ``energy_wh`` now."""

    uav_id: str
    energy_wh: float


Event = (
    ActionAdded | ActionChanged | ActionCancelled | TaskFinished | UavLost | UavBack | BatteryLow
)


class Session:
    """A problem, its planning state, and incremental updates."""

    def __init__(
        self, problem: Problem, options: Options | None = None, ctx: Ctx | None = None
    ) -> None:
        """Plan ``problem`` from scratch, or take ``ctx``, a planning state
        of it (:meth:`build_until`)."""
        check_problem(problem)
        self.problem = problem
        self.ctx = ctx if ctx is not None else heuristic.build(problem, options or Options())
        self._pending: list[str] = []

    @classmethod
    def build_until(
        cls, problem: Problem, options: Options | None, should_stop: Callable[[], bool]
    ) -> Session | None:
        """A new session, its construction polling ``should_stop`` between
        actions; None if stopped."""
        check_problem(problem)
        ctx = heuristic.build_until(problem, options, should_stop)
        return None if ctx is None else cls(problem, ctx=ctx)

    def plan(self) -> Solution:
        """The current plan."""
        return export(self.ctx)

    def next_visits(self, uav_id: str) -> list[tuple[str, str, int | None]]:
        """The UAV's planned visits in order, as (kind, action id, waypoint
        index or slot): a ``TaskFinished`` ends the first."""
        route = self.ctx.routes.get(uav_id)
        return [(v.kind, v.action_id, v.index) for v in route.tasks] if route else []

    # -- helpers ----------------------------------------------------------------
    def _set_problem(self, problem: Problem) -> None:
        self.problem = problem
        self.ctx.problem = problem
        self.ctx.actions = {a.id: a for a in problem.actions}

    def _uav_index(self, uid: str) -> int:
        for i, u in enumerate(self.problem.uavs):
            if u.id == uid:
                return i
        raise PlanningProblemError("$.event.uav_id", f"unknown UAV {uid!r}")

    def _strip(self, aid: str) -> None:
        """Remove all of an action's tasks (pinned ones too) and its reasons.

        If a route cannot be re-simulated without them (a later anchored
        segment no longer fits), the actions after them on that route are
        displaced too and re-inserted.
        """
        ctx = self.ctx
        displaced: list[str] = []
        for uid in ctx.placed_uavs(aid):
            mine = lambda t: t.action_id == aid  # noqa: E731
            if not remove(ctx, uid, mine):
                displaced.extend(sorted(ctx.remove_displacing(uid, mine)))
        ctx.pinned = {(a, i) for a, i in ctx.pinned if a != aid}
        ctx.unplaced.pop(aid, None)
        for other in dict.fromkeys(displaced):
            self._strip(other)
        self._pending.extend(displaced)

    def _flush(self) -> None:
        """Re-insert whatever parts of the displaced actions are missing (a
        displaced monitoring is re-planned whole)."""
        ctx = self.ctx
        for _ in range(100):
            if not self._pending:
                return
            pending, self._pending = list(dict.fromkeys(self._pending)), []
            whole: list[Job] = []
            for aid in pending:
                a = ctx.actions.get(aid)
                if a is None:
                    continue
                if isinstance(a, InspectJob):
                    have = {
                        t.index for r in ctx.routes.values() for t in r.tasks if t.action_id == aid
                    }
                    have |= {x.part for x in ctx.unplaced.get(aid, ())}
                    missing = [
                        i for i in range(len(a.waypoints)) if i not in have and i not in a.done
                    ]
                    if missing:
                        heuristic.place_inspect(ctx, a, missing)
                else:
                    if ctx.placed_uavs(aid):
                        self._strip(aid)
                    ctx.unplaced.pop(aid, None)
                    whole.append(a)
            self._place(whole)

    def _replace_uav(self, uav: Uav) -> None:
        uavs = list(self.problem.uavs)
        uavs[self._uav_index(uav.id)] = uav
        self._set_problem(replace(self.problem, uavs=tuple(uavs)))

    def _place(self, actions: list[Job]) -> None:
        for a in queue_order(actions):
            heuristic.place_action(self.ctx, a)

    def _hold_points(self, a: Job) -> None:
        """Register ``a``'s hold points; bookings of groups it merges move along."""
        for merged, joined in self.ctx.site.points.add_action(a):
            self.ctx.pads.merge(merged, joined)

    # -- events -------------------------------------------------------------------
    def apply(self, event: Event) -> Solution:
        """Apply one event; returns the new plan. Raises ``PlanningProblemError``
        if the event refers to unknown things or makes the problem invalid."""
        ctx = self.ctx
        ctx.fast = True
        match event:
            case ActionAdded(action=a):
                if a.id in ctx.actions:
                    raise PlanningProblemError("$.event.action.id", f"duplicate id {a.id!r}")
                self._set_problem(replace(self.problem, actions=(*self.problem.actions, a)))
                check_problem(self.problem)
                self._hold_points(a)
                self._place([a])
            case ActionChanged(action=a):
                self._require_action(a.id)
                self._strip(a.id)
                acts = tuple(a if x.id == a.id else x for x in self.problem.actions)
                self._set_problem(replace(self.problem, actions=acts))
                check_problem(self.problem)
                self._hold_points(a)
                self._place([a])
            case ActionCancelled(action_id=aid):
                self._require_action(aid)
                self._strip(aid)
                acts = tuple(x for x in self.problem.actions if x.id != aid)
                self._set_problem(replace(self.problem, actions=acts))
            case TaskFinished(uav_id=uid, position_m=pos, energy_wh=e):
                self._task_finished(uid, pos, e)
            case UavLost(uav_id=uid):
                self._uav_lost(uid)
            case UavBack(uav=u):
                self._uav_back(u)
            case BatteryLow(uav_id=uid, energy_wh=e):
                self._battery_low(uid, e)
        self._flush()
        return self.plan()

    def _require_action(self, aid: str) -> None:
        if aid not in self.ctx.actions:
            raise PlanningProblemError("$.event.action_id", f"unknown action {aid!r}")

    def _task_finished(self, uid: str, pos: Vec3, e: float) -> None:
        ctx = self.ctx
        r = ctx.routes.get(uid)
        if r is None or not r.tasks:
            return
        done = r.tasks[0]
        if done.kind not in ("inspect", "deliver"):
            return  # picks and monitoring segments are not reported one by one
        a = ctx.actions[done.action_id]
        u = self.problem.uavs[self._uav_index(uid)]
        tool = r.states[0].tool
        running = u.running if u.running and u.running.action_id != a.id else None
        self._replace_uav(
            replace(u, position_m=pos, energy_wh=e, airborne=True, tool=tool, running=running)
        )
        if isinstance(a, InspectJob) and done.index is not None:
            a2 = replace(a, done=tuple(sorted({*a.done, done.index})))
            acts = tuple(a2 if x.id == a.id else x for x in self.problem.actions)
            self._set_problem(replace(self.problem, actions=acts))
        elif done.kind == "deliver":
            acts = tuple(x for x in self.problem.actions if x.id != a.id)
            self._set_problem(replace(self.problem, actions=acts))
        ctx.pinned.discard((done.action_id, done.index))
        ctx.pads.remove_uav(uid, -1e18)
        r.tasks, r.states, r.steps, r.marks = r.tasks[1:], [], [], []
        init = State(ctx.problem.now_s, pos, e, False, tool)
        if not self._grounded(uid, init) and not ctx.reinit(uid, init):
            self._shed(uid, init)

    def _shed(self, uid: str, init: State) -> None:
        """Make a route feasible from a new initial state by dropping the
        actions whose tasks no longer fit (the failing one first, the whole
        tail as a last resort), then re-insert them elsewhere."""
        ctx = self.ctx
        r = ctx.routes[uid]
        dropped: dict[str, list[Visit]] = {}
        tasks = list(r.tasks)
        for attempt in range(12):
            sim = simulate(r.kin, ctx.site, ctx.pads, init, tasks, (uid, -1e18))
            if not isinstance(sim, str):
                break
            j = max(0, sim.task_index)
            bad = {tasks[j].action_id} if attempt < 10 else {t.action_id for t in tasks[j:]}
            for t in tasks:
                if t.action_id in bad:
                    dropped.setdefault(t.action_id, []).append(t)
            tasks = [t for t in tasks if t.action_id not in bad]
        r.tasks = tasks
        if not ctx.reinit(uid, init):
            for t in r.tasks:
                dropped.setdefault(t.action_id, []).append(t)
            r.tasks = []
            ctx.reinit(uid, init)
        ctx.pinned = {(a, i) for a, i in ctx.pinned if a not in dropped}
        for aid, lost in dropped.items():
            a = ctx.actions[aid]
            if isinstance(a, MonitorJob):
                if monitor.repair(ctx, a, monitor.segment_needs(lost)):
                    continue
                self._strip(aid)
            self._pending.append(aid)

    def _grounded(self, uid: str, init: State) -> bool:
        """If a battery fault leaves the UAV unable to reach a station above the
        reserve, take it out of planning and land it; True if so."""
        r = self.ctx.routes[uid]
        landing = emergency_landing(self.problem, r.kin, init, self.ctx.site)
        if landing is None:
            return False
        self._drop_route(uid)
        self.ctx.emergency[uid] = Grounded(landing, init, r.kin)
        return True

    def _uav_lost(self, uid: str) -> None:
        i = self._uav_index(uid)
        self._replace_uav(replace(self.problem.uavs[i], available=False, running=None))
        self.ctx.emergency.pop(uid, None)
        self._drop_route(uid)

    def _drop_route(self, uid: str) -> None:
        """Remove a UAV's route and re-insert its work on the others."""
        ctx = self.ctx
        r = ctx.routes.pop(uid, None)
        if r is None:
            return
        ctx.pads.remove_uav(uid, -1e18)
        ctx.running.pop(uid, None)
        lost: dict[str, list[int]] = {}
        for t in r.tasks:
            lost.setdefault(t.action_id, [])
            if t.kind == "inspect" and t.index is not None:
                lost[t.action_id].append(t.index)
            ctx.pinned.discard((t.action_id, t.index))
        for aid, idx in lost.items():
            a = ctx.actions[aid]
            if aid in self._pending:
                continue  # displaced meanwhile: re-planned whole by _flush
            if isinstance(a, InspectJob):
                heuristic.place_inspect(ctx, a, idx)
            elif isinstance(a, MonitorJob) and monitor.repair(
                ctx, a, monitor.segment_needs(t for t in r.tasks if t.action_id == aid)
            ):
                continue
            else:
                self._strip(aid)
                self._place([a])

    def _uav_back(self, u: Uav) -> None:
        ctx = self.ctx
        u = replace(u, available=True)
        self._replace_uav(u)
        check_problem(self.problem)
        ctx.emergency.pop(u.id, None)
        types = {t.id: t for t in self.problem.uav_types}
        home = ctx.site.by_id[u.home_station]
        kin = Kin(u, types[u.type], self.problem.reserve_fraction, home)
        init = State(self.problem.now_s, u.position_m, u.energy_wh, not u.airborne, u.tool)
        landing = emergency_landing(self.problem, kin, init, ctx.site)
        if landing is not None:
            if u.id in ctx.routes:
                self._drop_route(u.id)
            ctx.emergency[u.id] = Grounded(landing, init, kin)
        elif u.id in ctx.routes:
            if not ctx.reinit(u.id, init):
                self._shed(u.id, init)
        else:
            ctx.routes[u.id] = Route(kin, init)
        retry = [ctx.actions[aid] for aid in list(ctx.unplaced)]
        for a in retry:
            if isinstance(a, InspectJob):
                parts = [x.part for x in ctx.unplaced.pop(a.id) if x.part is not None]
                heuristic.place_inspect(ctx, a, parts)
            else:
                self._strip(a.id)
                self._place([a])

    def _battery_low(self, uid: str, e: float) -> None:
        ctx = self.ctx
        u = self.problem.uavs[self._uav_index(uid)]
        self._replace_uav(replace(u, energy_wh=e))
        r = ctx.routes.get(uid)
        if r is None:
            return
        init = r.init._replace(e=e)
        if not self._grounded(uid, init) and not ctx.reinit(uid, init):
            self._shed(uid, init)


def replan_once(
    problem: Problem, event: Event, options: Options | None = None
) -> tuple[Problem, Solution]:
    """One-shot helper: plan ``problem``, apply ``event``; (new problem, plan).

    For repeated events keep a ``Session``: that is what makes a replan cheap.
    """
    s = Session(problem, options)
    plan = s.apply(event)
    return s.problem, plan
