"""Independent plan validator.

A separate code path from the planner: it imports nothing of the planner's
scheduling code and recomputes every UAV's time, position, energy and tool
from the step lists alone (see ``result`` for the step semantics), then
checks the whole plan against the problem (``validate_checks``). Returns a
list of violations, each with a stable code; an empty list means the plan is
valid.
"""

from __future__ import annotations

from collections import defaultdict
from math import dist

from ground_station.planner.model import (
    WAIT_ASIDE_M,
    DeliverJob,
    InspectJob,
    Job,
    MonitorJob,
    Problem,
    Uav,
    Vec3,
)
from ground_station.planner.result import Solution, Step, UavPlan, Violation
from ground_station.planner.validate_checks import (
    TOL_M,
    TOL_S,
    TOL_WH,
    Hold,
    PadUse,
    Report,
    Segment,
    check_actions,
    check_end,
    check_pads,
    check_separation,
    slot_of,
)

STANDOFF_TOL_M = 0.5
SERVICE_KIND = {"inspect": "inspect", "monitor": "monitor", "pick": "deliver", "deliver": "deliver"}
KIND_OF = {InspectJob: "inspect", MonitorJob: "monitor", DeliverJob: "deliver"}


def validate(problem: Problem, plan: Solution) -> list[Violation]:
    """All violations of ``plan`` against ``problem`` (empty when valid)."""
    fleet = _Fleet(problem)
    for up in plan.uavs:
        u = fleet.admit(up)
        if u is not None:
            _Replay(fleet, u).run(up.steps)
    rep = fleet.rep
    check_pads(rep, fleet.stations, fleet.pad_use)
    check_separation(rep, problem.separation_m, fleet.holds)
    check_actions(rep, problem, plan, fleet.monitor_iv, fleet.waypoints, fleet.delivered)
    return rep.items


class _Fleet:
    """The problem's lookups, and what the UAVs' steps add up to."""

    def __init__(self, problem: Problem) -> None:
        self.problem = problem
        self.rep = Report()
        self.uavs = {u.id: u for u in problem.uavs}
        self.types = {t.id: t for t in problem.uav_types}
        self.stations = {s.id: s for s in problem.stations}
        self.actions = {a.id: a for a in problem.actions}
        self.seen: set[str] = set()
        self.pad_use: PadUse = defaultdict(list)
        self.monitor_iv: dict[str, list[Segment]] = defaultdict(list)
        self.waypoints: dict[str, list[int]] = defaultdict(list)
        self.delivered: dict[str, int] = defaultdict(int)
        self.holds: list[Hold] = []

    def admit(self, up: UavPlan) -> Uav | None:
        """The UAV whose steps ``up`` lists, if they are to be checked
        (unknown, duplicate and unavailable UAVs are reported)."""
        uid = up.uav_id
        u = self.uavs.get(uid)
        if u is None:
            self.rep.add("unknown_uav", f"plan for unknown UAV {uid!r}", uid)
            return None
        if uid in self.seen:
            self.rep.add("duplicate_uav", f"two step lists for {uid!r}", uid)
        self.seen.add(uid)
        if not up.steps and not u.available:
            return None
        if not u.available:
            self.rep.add("uav_unavailable", "steps for an unavailable UAV", uid)
        return u


class _Replay:
    """One UAV's steps flown again from its state at ``now_s``: time,
    position, energy, tool, each step checked on the way."""

    def __init__(self, fleet: _Fleet, u: Uav) -> None:
        problem = fleet.problem
        self.fleet, self.rep, self.u, self.uid = fleet, fleet.rep, u, u.id
        self.type = t = fleet.types[u.type]
        self.cap = t.battery_wh
        self.normal_floor = self.floor = problem.reserve_fraction * self.cap
        wh_per_m = t.flight_power_w / t.cruise_speed_mps / 3600.0
        stations = fleet.stations.values()
        to_station = min((dist(x.position_m, u.position_m) for x in stations), default=0.0)
        # A battery fault (cannot reach any station above the reserve, or below
        # the reserve on a pad): until its first recharge or landing the UAV may
        # only wait, recharge or land, and must not run dry.
        self.emergency = u.energy_wh - to_station * wh_per_m < self.floor - TOL_WH
        if self.emergency:
            self.floor = 0.0
        self.pos, self.time, self.e = u.position_m, problem.now_s, u.energy_wh
        self.landed, self.tool = not u.airborne, u.tool
        # A running task is continued (its remaining time suffices) only if it is
        # the UAV's first service, before any recharge; otherwise it is redone.
        self.fresh = True

    def run(self, steps: tuple[Step, ...]) -> None:
        """Check the UAV's end (unless in a battery fault: it only lands,
        where it can), then each step."""
        f = self.fleet
        if not self.emergency:
            check_end(self.rep, f.problem, self.u, steps, f.stations, f.pad_use)
        for n, s in enumerate(steps):
            self._step(f"step {n} ({s.kind})", s, steps[n - 1] if n else None, n == len(steps) - 1)

    def _step(self, where: str, s: Step, before: Step | None, last: bool) -> None:
        """Check step ``s`` (``before`` it, the previous one; ``last``: the
        UAV's last) and fly it: time, position, energy, tool, hover."""
        at_station = self._arrive(where, s)
        serve = s.end_s - s.arrive_s
        if self.emergency and s.kind in SERVICE_KIND:
            self.rep.add(
                "below_reserve", f"{where}: works before recovering from low battery", self.uid
            )
        hold = _hold_point(s, before, self.fleet.actions, at_station, self.landed)
        if hold is not None and serve > TOL_S:
            self.fleet.holds.append(Hold(s.arrive_s, s.end_s, hold, self.uid))
        if s.kind in SERVICE_KIND:
            self._work(where, s, serve)
        elif s.kind == "wait":
            self.landed = self.landed or at_station
            if not self.landed:
                self.e -= self.type.hover_power_w * serve / 3600.0
        elif s.kind == "recharge":
            self._recharge(where, s, serve)
        elif s.kind == "home":
            self._home(where, s, last)
        else:
            self.rep.add("unknown_step", f"{where}: unknown kind", self.uid)
        if s.energy_after_wh > self.e + TOL_WH:
            detail = f"{where}: reports {s.energy_after_wh:.3f} > {self.e:.3f}"
            self.rep.add("energy_mismatch", detail, self.uid)
        if self.e < self.floor - TOL_WH:
            self.rep.add("below_reserve", f"{where}: {self.e:.2f} Wh", self.uid)
        self.pos, self.time = s.position_m, s.end_s
        if s.kind in SERVICE_KIND:
            self.fresh = False
        if s.kind in ("recharge", "home") and self.emergency:
            self.emergency, self.floor = False, self.normal_floor

    def _arrive(self, where: str, s: Step) -> bool:
        """Check the flight to ``s`` (times, speed, a wait that moves) and
        spend its energy; whether ``s`` is at a station."""
        uid = self.uid
        if abs(s.start_s - self.time) > TOL_S:
            detail = f"{where} starts at {s.start_s}, previous end {self.time}"
            self.rep.add("time_discontinuity", detail, uid)
        if s.arrive_s < s.start_s - TOL_S or s.end_s < s.arrive_s - TOL_S:
            self.rep.add("time_order", f"{where}: start/arrive/end out of order", uid)
        d = dist(self.pos, s.position_m)
        flight_s = s.arrive_s - s.start_s
        if flight_s < d / self.type.cruise_speed_mps - TOL_S:
            self.rep.add("travel_too_fast", f"{where}: {d:.1f} m in {flight_s:.2f} s", uid)
        stations = self.fleet.stations.values()
        at_station = any(dist(st.position_m, s.position_m) <= TOL_M for st in stations)
        if s.kind == "wait" and d > TOL_M and not at_station:
            self.rep.add("wait_moves", f"{where}: a wait may only fly to a station", uid)
        if d > TOL_M:
            self.landed = False
        self.e -= self.type.flight_power_w * max(flight_s, 0.0) / 3600.0
        if self.e < self.floor - TOL_WH:
            self.rep.add("below_reserve", f"{where}: {self.e:.2f} Wh on arrival", uid)
        return at_station

    def _work(self, where: str, s: Step, serve: float) -> None:
        """A pick, drop, inspection or monitoring step."""
        act = self.fleet.actions.get(s.action_id) if s.action_id is not None else None
        drop_s = None  # a running delivery may finish with its remaining drop time
        run = self.u.running
        if s.kind == "deliver" and run is not None and run.action_id == s.action_id and self.fresh:
            drop_s = min(run.remaining_s, act.drop_s) if isinstance(act, DeliverJob) else None
        self._check_work(s, act, where, drop_s)
        if s.kind == "pick":
            self._pick(where, s)
        elif s.kind == "deliver":
            self._deliver(where, s, act)
        elif s.kind == "inspect" and s.action_id is not None and s.index is not None:
            self.fleet.waypoints[s.action_id].append(s.index)
            self._check_inspection(where, s, act, serve)
        elif s.kind == "monitor" and s.action_id is not None and s.index is not None:
            self.fleet.monitor_iv[s.action_id].append(Segment(s.index, s.arrive_s, s.end_s))
        self.e -= self.type.hover_power_w * serve / 3600.0

    def _pick(self, where: str, s: Step) -> None:
        """A pick: empty-handed, at a tool station holding the tool."""
        if self.tool is not None:
            self.rep.add("pick_with_tool", f"{where}: already holds {self.tool!r}", self.uid)
        if not any(
            s.tool in ts.tools and dist(ts.position_m, s.position_m) <= TOL_M
            for ts in self.fleet.problem.tool_stations
        ):
            self.rep.add("tool_not_at_station", f"{where}: no {s.tool!r} here", self.uid)
        self.tool = s.tool

    def _deliver(self, where: str, s: Step, act: Job | None) -> None:
        """A drop: with the action's tool in hand."""
        want = act.tool if isinstance(act, DeliverJob) else None
        if self.tool is None or self.tool != want:
            detail = f"{where}: holds {self.tool!r}"
            self.rep.add("deliver_without_tool", detail, self.uid, s.action_id)
        self.fleet.delivered[s.action_id or ""] += 1
        self.tool = None

    def _check_inspection(self, where: str, s: Step, act: Job | None, serve: float) -> None:
        """The waypoint's whole service time (or the running task's rest)."""
        run, index = self.u.running, s.index
        need = None
        if isinstance(act, InspectJob) and index is not None and 0 <= index < len(act.waypoints):
            need = act.waypoints[index].service_s
            if self.fresh and run is not None and (run.action_id, run.index) == (act.id, index):
                need = min(need, run.remaining_s)  # continuing the running task
        if need is not None and serve < need - TOL_S:
            self.rep.add("service_too_short", f"{where}: {serve:.2f} s < {need} s", self.uid)

    def _recharge(self, where: str, s: Step, serve: float) -> None:
        """On a pad of a charging station: the energy it can have charged."""
        self.fresh = False
        st = self.fleet.stations.get(s.station or "")
        if st is None or st.pads < 1 or dist(st.position_m, s.position_m) > TOL_M:
            self.rep.add("recharge_station", f"{where}: not a charging station", self.uid)
        else:
            self.fleet.pad_use[st.id].append((s.arrive_s, s.end_s))
            cap = self.cap
            if st.recharge == "swap":
                top = cap if serve >= st.swap_s - TOL_S else self.e
            else:
                top = min(cap, self.e + cap * serve / st.full_charge_s)
            if s.energy_after_wh > top + TOL_WH:
                self.rep.add("energy_mismatch", f"{where}: charged beyond {top:.2f} Wh", self.uid)
            self.e = min(top, s.energy_after_wh)
        self.landed = True

    def _home(self, where: str, s: Step, last: bool) -> None:
        """The final landing: at a station, as the last step."""
        st = self.fleet.stations.get(s.station or "")
        if st is None or dist(st.position_m, s.position_m) > TOL_M:
            self.rep.add("home_station", f"{where}: not a station", self.uid)
        if not last:
            self.rep.add("home_not_last", f"{where}: home must be the last step", self.uid)
        self.landed = True

    def _check_work(
        self, s: Step, act: Job | None, where: str, drop_s: float | None = None
    ) -> None:
        """A work step against its action: capability, release, altitude,
        then where and how long it works (``drop_s``: a running drop's rest)."""
        uid, kind = self.uid, SERVICE_KIND[s.kind]
        if kind not in self.type.capabilities:
            self.rep.add("capability", f"{where}: UAV type cannot {kind}", uid, s.action_id)
        if act is None or KIND_OF[type(act)] != kind:
            detail = f"{where}: no {kind} action {s.action_id!r}"
            self.rep.add("unknown_action", detail, uid, s.action_id)
            return
        if s.arrive_s < act.release_s - TOL_S:
            self.rep.add("before_release", f"{where}: starts before release", uid, act.id)
        if s.position_m[2] < self.fleet.problem.min_altitude_m - TOL_M:
            detail = f"{where}: z {s.position_m[2]:.1f} m below the minimum"
            self.rep.add("too_low", detail, uid, act.id)
        if isinstance(act, InspectJob):
            if s.index is None or not 0 <= s.index < len(act.waypoints):
                self.rep.add("bad_index", f"{where}: waypoint index {s.index}", uid, act.id)
            elif dist(act.waypoints[s.index].position_m, s.position_m) > TOL_M:
                self.rep.add("wrong_position", f"{where}: not at waypoint {s.index}", uid, act.id)
        elif isinstance(act, MonitorJob):
            if s.index is None or not 0 <= s.index < act.k:
                self.rep.add("bad_index", f"{where}: slot {s.index}", uid, act.id)
            elif dist(slot_of(act, s.index), s.position_m) > STANDOFF_TOL_M:
                self.rep.add("wrong_position", f"{where}: not at slot {s.index}", uid, act.id)
        elif isinstance(act, DeliverJob):
            self._check_delivery(s, act, where, drop_s)

    def _check_delivery(self, s: Step, act: DeliverJob, where: str, drop_s: float | None) -> None:
        """A pick or drop: the action's tool, the drop at the worker, long enough."""
        uid = self.uid
        if s.tool != act.tool:
            self.rep.add("wrong_tool", f"{where}: tool {s.tool!r}", uid, act.id)
        if s.kind == "deliver":
            if dist(act.worker_m, s.position_m) > TOL_M:
                self.rep.add("wrong_position", f"{where}: not at the worker", uid, act.id)
            if s.end_s - s.arrive_s < (act.drop_s if drop_s is None else drop_s) - TOL_S:
                self.rep.add("service_too_short", f"{where}: drop too short", uid, act.id)
        elif s.end_s - s.arrive_s < act.pick_s - TOL_S:
            self.rep.add("service_too_short", f"{where}: pick too short", uid, act.id)


def _hold_point(
    s: Step, before: Step | None, actions: dict[str, Job], at_station: bool, landed: bool
) -> Vec3 | None:
    """Where step ``s`` hovers (None if it does not): its position for work,
    an airborne wait's too, or aside of the slot it follows (``WAIT_ASIDE_M``)."""
    if s.kind in SERVICE_KIND:
        return s.position_m
    if s.kind != "wait" or at_station or landed:
        return None
    if before is not None and before.kind == "monitor" and before.index is not None:
        act = actions.get(before.action_id) if before.action_id is not None else None
        if isinstance(act, MonitorJob):
            return slot_of(act, before.index, WAIT_ASIDE_M)
    return s.position_m
