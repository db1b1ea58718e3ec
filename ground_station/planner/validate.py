"""Independent plan validator.

A separate code path from the planner: it imports nothing of the planner's
scheduling code and recomputes every UAV's time, position, energy and tool
from the step lists alone (see ``result`` for the step semantics), then
checks the whole plan against the problem. Returns a list of violations,
each with a stable code; an empty list means the plan is valid.
"""

from __future__ import annotations

from collections import defaultdict
from math import cos, dist, pi, radians, sin

from ground_station.planner.model import (
    WAIT_ASIDE_M,
    Action,
    DeliverAction,
    InspectAction,
    MonitorAction,
    Problem,
    Station,
    Uav,
    Vec3,
)
from ground_station.planner.result import Plan, Step, Violation

TOL_S = 1e-3
TOL_WH = 1e-3
TOL_M = 0.01
STANDOFF_TOL_M = 0.5
SERVICE_KIND = {"inspect": "inspect", "monitor": "monitor", "pick": "deliver", "deliver": "deliver"}
Hold = tuple[float, float, Vec3, str]
"""A hover: from, until, where, which UAV."""
PadUse = dict[str, list[tuple[float, float]]]
"""Station id -> the (from, until) intervals a pad there is taken."""
KIND_OF = {InspectAction: "inspect", MonitorAction: "monitor", DeliverAction: "deliver"}


class _Report:
    def __init__(self) -> None:
        self.items: list[Violation] = []

    def add(
        self, code: str, detail: str, uav: str | None = None, action: str | None = None
    ) -> None:
        self.items.append(Violation(code=code, detail=detail, uav_id=uav, action_id=action))


def validate(problem: Problem, plan: Plan) -> list[Violation]:
    """All violations of ``plan`` against ``problem`` (empty when valid)."""
    rep = _Report()
    uavs = {u.id: u for u in problem.uavs}
    types = {t.id: t for t in problem.uav_types}
    stations = {s.id: s for s in problem.stations}
    tool_stations = list(problem.tool_stations)
    actions = {a.id: a for a in problem.actions}
    reserve = problem.reserve_fraction
    seen: set[str] = set()
    pad_use: PadUse = defaultdict(list)
    monitor_iv: dict[str, list[tuple[int, float, float]]] = defaultdict(list)
    waypoints: dict[str, list[int]] = defaultdict(list)
    delivered: dict[str, int] = defaultdict(int)
    holds: list[Hold] = []
    for up in plan.uavs:
        uid = up.uav_id
        u = uavs.get(uid)
        if u is None:
            rep.add("unknown_uav", f"plan for unknown UAV {uid!r}", uid)
            continue
        if uid in seen:
            rep.add("duplicate_uav", f"two step lists for {uid!r}", uid)
        seen.add(uid)
        if not up.steps and not u.available:
            continue
        if not u.available:
            rep.add("uav_unavailable", "steps for an unavailable UAV", uid)
        t = types[u.type]
        cap = t.battery_wh
        floor = reserve * cap
        wh_per_m = t.flight_power_w / t.cruise_speed_mps / 3600.0
        to_station = min((dist(x.position_m, u.position_m) for x in stations.values()), default=0.0)
        # A battery fault (cannot reach any station above the reserve, or below
        # the reserve on a pad): until its first recharge or landing the UAV may
        # only wait, recharge or land, and must not run dry.
        emergency = u.energy_wh - to_station * wh_per_m < floor - TOL_WH
        if not emergency:  # a UAV in a battery fault only lands, where it can
            _check_end(rep, problem, u, up.steps, stations, pad_use)
        normal_floor = floor
        if emergency:
            floor = 0.0
        pos, time, e, landed, tool = (
            u.position_m,
            problem.now_s,
            u.energy_wh,
            not u.airborne,
            u.tool,
        )
        # A running task is continued (its remaining time suffices) only if it is
        # the UAV's first service, before any recharge; otherwise it is redone.
        fresh = True
        for n, s in enumerate(up.steps):
            where = f"step {n} ({s.kind})"
            if abs(s.start_s - time) > TOL_S:
                rep.add(
                    "time_discontinuity", f"{where} starts at {s.start_s}, previous end {time}", uid
                )
            if s.arrive_s < s.start_s - TOL_S or s.end_s < s.arrive_s - TOL_S:
                rep.add("time_order", f"{where}: start/arrive/end out of order", uid)
            d = dist(pos, s.position_m)
            flight_s = s.arrive_s - s.start_s
            if flight_s < d / t.cruise_speed_mps - TOL_S:
                rep.add("travel_too_fast", f"{where}: {d:.1f} m in {flight_s:.2f} s", uid)
            at_station = any(dist(st.position_m, s.position_m) <= TOL_M for st in stations.values())
            if s.kind == "wait" and d > TOL_M and not at_station:
                rep.add("wait_moves", f"{where}: a wait may only fly to a station", uid)
            if d > TOL_M:
                landed = False
            e -= t.flight_power_w * max(flight_s, 0.0) / 3600.0
            if e < floor - TOL_WH:
                rep.add("below_reserve", f"{where}: {e:.2f} Wh on arrival", uid)
            serve = s.end_s - s.arrive_s
            act = actions.get(s.action_id) if s.action_id is not None else None
            if emergency and s.kind in SERVICE_KIND:
                rep.add("below_reserve", f"{where}: works before recovering from low battery", uid)
            hold = _hold_point(s, up.steps[n - 1] if n else None, actions, at_station, landed)
            if hold is not None and serve > TOL_S:
                holds.append((s.arrive_s, s.end_s, hold, uid))
            if s.kind in SERVICE_KIND:
                drop_s = None  # a running delivery may finish with its remaining drop time
                run = u.running
                if (
                    s.kind == "deliver"
                    and run is not None
                    and run.action_id == s.action_id
                    and fresh
                ):
                    drop_s = (
                        min(run.remaining_s, act.drop_s) if isinstance(act, DeliverAction) else None
                    )
                _check_action_step(rep, problem, u.id, t.capabilities, s, act, where, drop_s)
                if s.kind == "pick":
                    if tool is not None:
                        rep.add("pick_with_tool", f"{where}: already holds {tool!r}", uid)
                    if not any(
                        s.tool in ts.tools and dist(ts.position_m, s.position_m) <= TOL_M
                        for ts in tool_stations
                    ):
                        rep.add("tool_not_at_station", f"{where}: no {s.tool!r} here", uid)
                    tool = s.tool
                elif s.kind == "deliver":
                    want = act.tool if isinstance(act, DeliverAction) else None
                    if tool is None or tool != want:
                        rep.add(
                            "deliver_without_tool", f"{where}: holds {tool!r}", uid, s.action_id
                        )
                    delivered[s.action_id or ""] += 1
                    tool = None
                elif s.kind == "inspect" and s.action_id is not None and s.index is not None:
                    waypoints[s.action_id].append(s.index)
                    run = u.running
                    need = None
                    if isinstance(act, InspectAction) and 0 <= s.index < len(act.waypoints):
                        need = act.waypoints[s.index].service_s
                        if (
                            fresh
                            and run is not None
                            and (run.action_id, run.index) == (act.id, s.index)
                        ):  # continuing the running task
                            need = min(need, run.remaining_s)
                    if need is not None and serve < need - TOL_S:
                        rep.add("service_too_short", f"{where}: {serve:.2f} s < {need} s", uid)
                elif s.kind == "monitor" and s.action_id is not None and s.index is not None:
                    monitor_iv[s.action_id].append((s.index, s.arrive_s, s.end_s))
                e -= t.hover_power_w * serve / 3600.0
            elif s.kind == "wait":
                landed = landed or at_station
                if not landed:
                    e -= t.hover_power_w * serve / 3600.0
            elif s.kind == "recharge":
                fresh = False
                st = stations.get(s.station or "")
                if st is None or st.pads < 1 or dist(st.position_m, s.position_m) > TOL_M:
                    rep.add("recharge_station", f"{where}: not a charging station", uid)
                else:
                    pad_use[st.id].append((s.arrive_s, s.end_s))
                    if st.recharge == "swap":
                        top = cap if serve >= st.swap_s - TOL_S else e
                    else:
                        top = min(cap, e + cap * serve / st.full_charge_s)
                    if s.energy_after_wh > top + TOL_WH:
                        rep.add("energy_mismatch", f"{where}: charged beyond {top:.2f} Wh", uid)
                    e = min(top, s.energy_after_wh)
                landed = True
            elif s.kind == "home":
                st = stations.get(s.station or "")
                if st is None or dist(st.position_m, s.position_m) > TOL_M:
                    rep.add("home_station", f"{where}: not a station", uid)
                if n != len(up.steps) - 1:
                    rep.add("home_not_last", f"{where}: home must be the last step", uid)
                landed = True
            else:
                rep.add("unknown_step", f"{where}: unknown kind", uid)
            if s.energy_after_wh > e + TOL_WH:
                rep.add(
                    "energy_mismatch", f"{where}: reports {s.energy_after_wh:.3f} > {e:.3f}", uid
                )
            if e < floor - TOL_WH:
                rep.add("below_reserve", f"{where}: {e:.2f} Wh", uid)
            pos, time = s.position_m, s.end_s
            if s.kind in SERVICE_KIND:
                fresh = False
            if s.kind in ("recharge", "home") and emergency:
                emergency, floor = False, normal_floor
    _check_pads(rep, stations, pad_use)
    _check_separation(rep, problem.separation_m, holds)
    _check_actions(rep, problem, plan, monitor_iv, waypoints, delivered)
    return rep.items


def _check_action_step(
    rep: _Report,
    problem: Problem,
    uid: str,
    caps: dict[str, float],
    s: Step,
    act: Action | None,
    where: str,
    drop_s: float | None = None,
) -> None:
    kind = SERVICE_KIND[s.kind]
    if kind not in caps:
        rep.add("capability", f"{where}: UAV type cannot {kind}", uid, s.action_id)
    if act is None or KIND_OF[type(act)] != kind:
        rep.add("unknown_action", f"{where}: no {kind} action {s.action_id!r}", uid, s.action_id)
        return
    if s.arrive_s < act.release_s - TOL_S:
        rep.add("before_release", f"{where}: starts before release", uid, act.id)
    if s.position_m[2] < problem.min_altitude_m - TOL_M:
        rep.add("too_low", f"{where}: z {s.position_m[2]:.1f} m below the minimum", uid, act.id)
    if isinstance(act, InspectAction):
        if s.index is None or not 0 <= s.index < len(act.waypoints):
            rep.add("bad_index", f"{where}: waypoint index {s.index}", uid, act.id)
        elif dist(act.waypoints[s.index].position_m, s.position_m) > TOL_M:
            rep.add("wrong_position", f"{where}: not at waypoint {s.index}", uid, act.id)
    elif isinstance(act, MonitorAction):
        if s.index is None or not 0 <= s.index < act.k:
            rep.add("bad_index", f"{where}: slot {s.index}", uid, act.id)
        elif dist(_slot(act, s.index), s.position_m) > STANDOFF_TOL_M:
            rep.add("wrong_position", f"{where}: not at slot {s.index}", uid, act.id)
    elif isinstance(act, DeliverAction):
        if s.tool != act.tool:
            rep.add("wrong_tool", f"{where}: tool {s.tool!r}", uid, act.id)
        if s.kind == "deliver":
            if dist(act.worker_m, s.position_m) > TOL_M:
                rep.add("wrong_position", f"{where}: not at the worker", uid, act.id)
            if s.end_s - s.arrive_s < (act.drop_s if drop_s is None else drop_s) - TOL_S:
                rep.add("service_too_short", f"{where}: drop too short", uid, act.id)
        elif s.end_s - s.arrive_s < act.pick_s - TOL_S:
            rep.add("service_too_short", f"{where}: pick too short", uid, act.id)


def _slot(act: MonitorAction, slot: int, aside_m: float = 0.0) -> tuple[float, float, float]:
    """Where slot ``slot`` is, from the action's definition (not the
    planner's code); ``aside_m`` along the ring (counter-clockwise)."""
    x, y, z = act.worker_m
    bearing = radians(act.bearing_deg) + 2 * pi * slot / act.k
    r = act.standoff_m
    return (
        x + r * cos(bearing) - aside_m * sin(bearing),
        y + r * sin(bearing) + aside_m * cos(bearing),
        z + act.height_m,
    )


def _hold_point(
    s: Step, before: Step | None, actions: dict[str, Action], at_station: bool, landed: bool
) -> Vec3 | None:
    """Where step ``s`` hovers (None if it does not): its position for work,
    an airborne wait's too, or aside of the slot it follows (``WAIT_ASIDE_M``)."""
    if s.kind in SERVICE_KIND:
        return s.position_m
    if s.kind != "wait" or at_station or landed:
        return None
    if before is not None and before.kind == "monitor" and before.index is not None:
        act = actions.get(before.action_id) if before.action_id is not None else None
        if isinstance(act, MonitorAction):
            return _slot(act, before.index, WAIT_ASIDE_M)
    return s.position_m


def _check_separation(rep: _Report, separation_m: float, holds: list[Hold]) -> None:
    """No two UAVs hover nearer than ``separation_m`` at once."""
    active: list[Hold] = []
    for hold in sorted(holds):
        start, end, where, uid = hold
        active = [a for a in active if a[1] > start + TOL_S]
        for _, other_end, there, other in active:
            if other != uid and dist(where, there) < separation_m - TOL_M:
                rep.add(
                    "separation",
                    f"{dist(where, there):.2f} m from {other} "
                    f"{start:.1f}-{min(end, other_end):.1f} s",
                    uid,
                )
        active.append(hold)


def _check_end(
    rep: _Report,
    problem: Problem,
    u: Uav,
    steps: tuple[Step, ...],
    stations: dict[str, Station],
    pad_use: PadUse,
) -> None:
    """``problem.end``: the UAV ends landed at home, or (``any_station``) at
    a station, where away from home it holds a pad from its landing on."""
    last = steps[-1] if steps else None
    pos = last.position_m if last else u.position_m
    at = [s for s in stations.values() if dist(s.position_m, pos) <= TOL_M]
    landed = (last.kind in ("recharge", "home", "wait") and bool(at)) if last else not u.airborne
    if landed and any(s.id == u.home_station for s in at):
        return
    if problem.end == "home":
        rep.add("not_home", f"ends at {pos}, not on {u.home_station}", u.id)
    elif not landed or not at:
        rep.add("end_station", f"ends at {pos}, not on a station", u.id)
    else:
        pad_use[at[0].id].append((last.end_s if last else problem.now_s, float("inf")))


def _check_pads(rep: _Report, stations: dict[str, Station], pad_use: PadUse) -> None:
    for sid, ivs in pad_use.items():
        events = sorted([(a + TOL_S, 1) for a, _ in ivs] + [(b, -1) for _, b in ivs])
        level = 0
        for at, delta in events:
            level += delta
            if level > stations[sid].pads:
                rep.add("pad_capacity", f"station {sid}: {level} UAVs on pads at {at:.1f} s")
                break


def _check_actions(
    rep: _Report,
    problem: Problem,
    plan: Plan,
    monitor_iv: dict[str, list[tuple[int, float, float]]],
    waypoints: dict[str, list[int]],
    delivered: dict[str, int],
) -> None:
    unplaced: dict[str, set] = defaultdict(set)
    for x in plan.unplaced:
        unplaced[x.action_id].add(x.part)
    for a in problem.actions:
        whole_unplaced = None in unplaced[a.id]
        if isinstance(a, InspectAction):
            counts: dict[int, int] = defaultdict(int)
            for i in waypoints.get(a.id, ()):
                counts[i] += 1
            for i in range(len(a.waypoints)):
                expect = 0 if (i in a.done or i in unplaced[a.id] or whole_unplaced) else 1
                if counts[i] != expect:
                    code = "waypoint_duplicate" if counts[i] > expect else "waypoint_missing"
                    rep.add(code, f"waypoint {i} inspected {counts[i]} times", action=a.id)
        elif isinstance(a, DeliverAction):
            expect = 0 if whole_unplaced else 1
            if delivered.get(a.id, 0) != expect:
                rep.add("deliver_count", f"delivered {delivered.get(a.id, 0)} times", action=a.id)
        elif isinstance(a, MonitorAction):
            ivs = monitor_iv.get(a.id, [])
            if whole_unplaced:
                if ivs:
                    rep.add("unplaced_but_planned", "monitoring planned and unplaced", action=a.id)
                continue
            if not ivs:
                rep.add("monitor_missing", "monitoring not planned", action=a.id)
                continue
            t0 = min(b for _, b, _ in ivs)
            if t0 < a.release_s - TOL_S:
                rep.add("before_release", "monitoring starts before release", action=a.id)
            for slot in range(a.k):
                mine = sorted((b, e) for s, b, e in ivs if s == slot)
                if not mine or mine[0][0] > t0 + TOL_S:
                    rep.add(
                        "monitor_not_synchronised", f"slot {slot} not started at T0", action=a.id
                    )
                    continue
                covered = t0
                for b, e in mine:
                    if b > covered + TOL_S:
                        rep.add(
                            "monitor_gap",
                            f"slot {slot} uncovered {covered:.1f}-{b:.1f}",
                            action=a.id,
                        )
                    covered = max(covered, e)
                if covered < t0 + a.duration_s - TOL_S:
                    rep.add("monitor_gap", f"slot {slot} ends early at {covered:.1f}", action=a.id)
