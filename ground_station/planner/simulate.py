"""Turn one UAV's ordered task list into timed steps, inserting waits and
recharges so the battery never goes below the reserve.

A task is an abstract job (one inspection waypoint, one monitoring segment,
a pick, a drop). Waits are inserted before a task's release time or before
an anchored task (a monitoring segment must start exactly at ``anchor_s``);
a recharge is inserted before a task when doing it directly would leave the
UAV unable to reach the nearest charging station above the reserve, or when
an airborne UAV would otherwise hover idle for long.
"""

from __future__ import annotations

from math import dist

from ground_station.planner.energy import EPS_S, EPS_WH, Kin, Site, recharge_time_s
from ground_station.planner.model import Vec3
from ground_station.planner.pads import Ignore, Pads
from ground_station.planner.recharge import emit_recharge, next_hop, recharge_option
from ground_station.planner.state import Fail, Sim, State, Task

__all__ = [
    "Fail",
    "Sim",
    "State",
    "Task",
    "advance",
    "direct_arrival",
    "hold_floor_wh",
    "monitor_reach",
    "monitor_ready",
    "simulate",
]

MAX_HOPS = 12
LONG_WAIT_S = 120.0
"""An airborne UAV facing a longer idle wait lands to recharge if it can."""
HOLDS = frozenset({"inspect", "pick", "deliver"})
"""Tasks that hold a point (``Site.points``) one UAV at a time: a second
UAV waits until the first has left (an airborne wait there holds it too)."""


def hold_wait(
    site: Site, pads: Pads, pos: Vec3, start: float, end: float, ign: Ignore, res: list
) -> bool:
    """Book an airborne wait at ``pos`` in ``res`` if that is a hold point
    (hovering on there, it stays taken); False if another UAV holds it then."""
    point = site.points.get(pos)
    if point is None or end - start <= EPS_S:
        return True
    if pads.earliest(point, start, end - start, ign) > start + EPS_S:
        return False
    res.append((point, start, end))
    return True


def _service_end_e(k: Kin, e_at: float, service_s: float) -> float:
    return e_at - k.hover_whps * service_s


def advance(
    k: Kin,
    site: Site,
    pads: Pads,
    st: State,
    task: Task,
    steps: list,
    res: list,
    ign: Ignore,
    depth: int = 0,
    soft: float | None = None,
) -> State | str:
    """Schedule ``task`` after ``st``; returns the new state or a reason code."""
    st0, n_steps, n_res = st, len(steps), len(res)
    t, pos, e, landed, tool = st
    if task.kind == "pick" and tool is not None:
        return "tool_busy"
    if task.kind == "deliver" and tool != task.tool:
        return "tool_missing"
    d = dist(pos, task.pos)
    tr = d / k.speed_mps
    ret_e = site.nearest(task.pos)[0] * k.wh_per_m
    arr = t + tr
    if task.release_s > arr:
        arr = task.release_s
    anchor = task.anchor_s
    if anchor is not None:
        if arr > anchor + EPS_S:
            return "late"
        arr = anchor
    wait = arr - tr - t
    if wait < EPS_S:
        wait = 0.0
    e_wait = e if landed else e - k.hover_whps * wait
    e_at = e_wait - d * k.wh_per_m
    e_end = _service_end_e(k, e_at, task.service_s)
    direct_ok = e_end - ret_e >= k.reserve_wh - EPS_WH and e_wait >= k.reserve_wh - EPS_WH
    rc = None
    service = task.service_s
    if not direct_ok or (wait > LONG_WAIT_S and not landed) or (task.topup and not landed):
        rc = recharge_option(k, site, pads, st, task.pos, task.release_s, anchor, ign, soft=soft)
        if rc is not None:
            if task.full_s is not None:  # a running task redone in full after recharging
                service = task.full_s
            e_end_rc = _service_end_e(k, rc.e_at_task, service)
            short = e_end_rc - ret_e < k.reserve_wh - EPS_WH
            later = direct_ok and anchor is None and rc.arrive_task > arr + EPS_S
            if short or (later and not task.topup):
                rc = None
        if rc is None and not direct_ok:
            # Too far for one recharge: hop along stations towards the task.
            if depth >= MAX_HOPS:
                return "battery"
            si = next_hop(k, site, st, task.pos)
            if si is None:
                return "battery"
            hop = recharge_option(k, site, pads, st, site.positions[si], 0.0, None, ign, None, si)
            if hop is None:
                return "battery"
            st = emit_recharge(k, site, st, hop, steps, res)
            return advance(k, site, pads, st, task.resumed(), steps, res, ign, depth + 1, soft)
    if rc is not None:
        st = emit_recharge(k, site, st, rc, steps, res)
        arr = rc.arrive_task
        tr = dist(st.pos, task.pos) / k.speed_mps
        d = tr * k.speed_mps
        wait = arr - tr - st.t
        e_wait = st.e
        e_at = rc.e_at_task
        e_end = _service_end_e(k, e_at, service)
        t, pos = st.t, st.pos
    else:
        service = task.service_s
    point = site.points.get(task.pos) if task.kind in HOLDS else None
    if point is not None:
        free = pads.earliest(point, arr, service, ign)
        if free > arr + EPS_S:  # another UAV holds the point then: come later
            if anchor is not None or depth >= MAX_HOPS:
                return "point_busy"
            del steps[n_steps:], res[n_res:]
            deferred = task.released(free)
            return advance(k, site, pads, st0, deferred, steps, res, ign, depth + 1, soft)
    if wait > EPS_S:
        if not st.landed and not hold_wait(site, pads, pos, t, t + wait, ign, res):
            return "point_busy"
        steps.append(("wait", t, t, t + wait, e_wait, pos, None, None, None, None, 0.0))
    end = arr + service
    steps.append(
        (
            task.kind,
            arr - tr,
            arr,
            end,
            e_end,
            task.pos,
            task.action_id,
            task.index,
            None,
            task.tool,
            d,
        )
    )
    if point is not None:
        res.append((point, arr, end))
    if task.kind == "pick":
        tool = task.tool
    elif task.kind == "deliver":
        tool = None
    return State(end, task.pos, e_end, False, tool)


def _deadlines(k: Kin, tasks: list[Task]) -> list[float | None]:
    """Latest arrival at each task that still lets the UAV reach the next
    anchored task in time (ignoring recharges); None if none follows."""
    out: list[float | None] = [None] * len(tasks)
    nxt: float | None = None
    for i in range(len(tasks) - 1, -1, -1):
        t = tasks[i]
        if t.anchor_s is not None:
            nxt = t.anchor_s
        elif nxt is not None:
            nxt -= t.service_s + dist(t.pos, tasks[i + 1].pos) / k.speed_mps
        out[i] = nxt
    return out


def simulate(
    k: Kin,
    site: Site,
    pads: Pads,
    st: State,
    tasks: list[Task],
    ign: Ignore,
    old: list[State] | None = None,
    old_map: list[int] | None = None,
) -> Sim | Fail:
    """Simulate ``tasks`` from ``st``; a reason code (``Fail``) if one is
    infeasible. With ``old``/``old_map`` (task i was task ``old_map[i]`` of
    the route being edited, -1 if new), stops as soon as the state after a
    task equals the old one: the rest of the old route is then unchanged."""
    steps: list = []
    res: list = []
    states: list[State] = []
    marks: list[int] = []
    soft = _deadlines(k, tasks)
    for i, task in enumerate(tasks):
        marks.append(len(steps))
        nxt = advance(k, site, pads, st, task, steps, res, ign, 0, soft[i])
        if isinstance(nxt, str):
            fail = Fail(nxt)
            fail.task_index = i
            return fail
        states.append(nxt)
        st = nxt
        if old_map is not None and old is not None:
            j = old_map[i]
            if j >= 0:
                o = old[j]
                if (
                    abs(o.t - nxt.t) < 1e-9
                    and abs(o.e - nxt.e) < 1e-9
                    and o.pos == nxt.pos
                    and o.landed == nxt.landed
                    and o.tool == nxt.tool
                ):
                    return Sim(steps, marks, states, res, j + 1)
    return Sim(steps, marks, states, res)


def monitor_reach(
    k: Kin, site: Site, pads: Pads, st: State, pos: Vec3, anchor: float, ign: Ignore, need: float
) -> float | None:
    """Latest end a monitoring segment at ``pos`` starting at ``anchor`` can
    last until on ``st``'s battery (direct, after a recharge, or after hops
    along stations, as ``advance`` would fly it); None if the UAV cannot be
    there at ``anchor``."""
    for _ in range(MAX_HOPS + 1):
        if st.t + dist(st.pos, pos) / k.speed_mps > anchor + EPS_S:
            return None
        best = _reach_once(k, site, pads, st, pos, anchor, ign, need)
        if best is not None:
            return best
        hopped = _hop(k, site, pads, st, pos, ign, anchor)
        if hopped is None:
            return None
        st = hopped
    return None


def monitor_ready(
    k: Kin,
    site: Site,
    pads: Pads,
    st: State,
    pos: Vec3,
    release_s: float,
    ign: Ignore,
    hold_s: float,
) -> float | None:
    """Earliest time (not before ``release_s``) the UAV in ``st`` can be at
    ``pos`` with the battery to hover there ``hold_s`` and still reach a
    station above the reserve: directly, after a recharge first, or after
    hops along stations; None if it cannot get there."""
    floor = hold_floor_wh(k, site, pos, hold_s)
    for _ in range(MAX_HOPS + 1):
        arr, e_at = direct_arrival(k, st, pos, release_s)
        if e_at >= floor:
            return arr
        rc = recharge_option(k, site, pads, st, pos, release_s, None, ign)
        if rc is None or rc.e_at_task < floor:  # the earliest is short: the nearest station
            near = site.nearest(pos)[1]
            rc = recharge_option(k, site, pads, st, pos, release_s, None, ign, None, near)
        if rc is not None and rc.e_at_task >= floor:
            return rc.arrive_task
        hopped = _hop(k, site, pads, st, pos, ign)
        if hopped is None:
            return None
        st = hopped
    return None


def direct_arrival(k: Kin, st: State, pos: Vec3, release_s: float) -> tuple[float, float]:
    """(arrival, energy there) flying straight from ``st`` to ``pos``, not
    arriving before ``release_s`` (an airborne UAV hovers while it waits)."""
    tr = dist(st.pos, pos) / k.speed_mps
    arr = max(release_s, st.t + tr)
    e_wait = st.e if st.landed else st.e - k.hover_whps * (arr - tr - st.t)
    return arr, e_wait - tr * k.speed_mps * k.wh_per_m


def hold_floor_wh(k: Kin, site: Site, pos: Vec3, hold_s: float) -> float:
    """Battery needed at ``pos`` to hover ``hold_s`` there and then reach the
    nearest station above the reserve."""
    return k.reserve_wh - EPS_WH + site.nearest(pos)[0] * k.wh_per_m + k.hover_whps * hold_s


def _hop(
    k: Kin, site: Site, pads: Pads, st: State, pos: Vec3, ign: Ignore, latest: float | None = None
) -> State | None:
    """The state on the pad after a recharge at the next station towards
    ``pos`` (``next_hop``), as ``advance`` would fly it; None if there is
    none, or if through it the UAV cannot be at ``pos`` by ``latest``."""
    si = next_hop(k, site, st, pos)
    if si is None:
        return None
    d1 = site.dists(st.pos)[si]
    if latest is not None:
        charge_s = recharge_time_s(site.charging[si], k.capacity_wh, st.e - d1 * k.wh_per_m)
        if st.t + (d1 + site.dists(pos)[si]) / k.speed_mps + charge_s > latest + EPS_S:
            return None
    hop = recharge_option(k, site, pads, st, site.positions[si], 0.0, None, ign, None, si)
    if hop is None:
        return None
    t_pad = st.t + d1 / k.speed_mps + hop.wait_s
    return State(t_pad + hop.dur_s, site.positions[si], hop.e_charged, True, st.tool)


def _reach_once(
    k: Kin, site: Site, pads: Pads, st: State, pos: Vec3, anchor: float, ign: Ignore, need: float
) -> float | None:
    t, p, e, landed, _ = st
    d = dist(p, pos)
    tr = d / k.speed_mps
    ret_e = site.nearest(pos)[0] * k.wh_per_m
    hover = k.hover_whps if k.hover_whps > 0 else 1e-12
    wait = anchor - tr - t
    e_at = (e if landed else e - k.hover_whps * wait) - d * k.wh_per_m
    best = None
    if e_at - ret_e >= k.reserve_wh - EPS_WH and e_at + d * k.wh_per_m >= k.reserve_wh - EPS_WH:
        best = anchor + (e_at - ret_e - k.reserve_wh) / hover
    if best is None or best < need - EPS_S:
        rc = recharge_option(k, site, pads, st, pos, 0.0, anchor, ign)
        if rc is not None:
            end_rc = anchor + (rc.e_at_task - ret_e - k.reserve_wh) / hover
            if end_rc > anchor and (best is None or end_rc > best):
                best = end_rc
    return best
