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

from ground_station.planner.energy import EPS_S, EPS_WH, Kin, SiteMap
from ground_station.planner.model import Vec3
from ground_station.planner.pads import Ignore, Pads
from ground_station.planner.recharge import emit_recharge, next_hop, recharge_option
from ground_station.planner.result import Step
from ground_station.planner.state import Booking, Fail, Sim, State, Visit, wait_step

__all__ = ["Fail", "Sim", "State", "Visit", "advance", "simulate"]

MAX_HOPS = 12
"""Recursion bound of ``advance``: hops along stations and deferrals."""
LONG_WAIT_S = 120.0
"""An airborne UAV facing a longer idle wait lands to recharge if it can."""
HOLDS = frozenset({"inspect", "pick", "deliver"})
"""Tasks that hold a point (``SiteMap.points``) one UAV at a time: a second
UAV waits until the first has left (an airborne wait there holds it too)."""


def hold_wait(
    site: SiteMap,
    pads: Pads,
    pos: Vec3,
    start: float,
    end: float,
    ign: Ignore,
    res: list[Booking],
) -> bool:
    """Book an airborne wait at ``pos`` in ``res`` if that is a hold point
    (hovering on there, it stays taken); False if another UAV holds it then."""
    point = site.points.get(pos)
    if point is None or end - start <= EPS_S:
        return True
    if pads.earliest(point, start, end - start, ign) > start + EPS_S:
        return False
    res.append(Booking(point, start, end))
    return True


def _service_end_e(k: Kin, e_at: float, service_s: float) -> float:
    return e_at - k.hover_whps * service_s


def advance(
    k: Kin,
    site: SiteMap,
    pads: Pads,
    st: State,
    task: Visit,
    steps: list[Step],
    res: list[Booking],
    ign: Ignore,
    depth: int = 0,
    soft: float | None = None,
) -> State | str:
    """Schedule ``task`` after ``st``; returns the new state or a reason code.

    The UAV flies straight there if its battery allows; otherwise (or
    instead of a long airborne wait, or for a top-up) after a recharge, or
    hopping along stations when no single recharge gets it there (recursing,
    as it does to defer the task when another UAV holds its point then).

    Kept in one piece on purpose: it runs for every task of every simulated
    candidate, and split into helpers (direct leg, recharge choice, emitted
    steps) full plans measured 1-3 % slower."""
    st0, n_steps, n_res = st, len(steps), len(res)
    t, pos, e, landed, tool = st
    if task.kind == "pick" and tool is not None:
        return "tool_busy"
    if task.kind == "deliver" and tool != task.tool:
        return "tool_missing"
    d = dist(pos, task.pos)
    tr = d / k.speed_mps
    ret_e = site.nearest(task.pos).distance_m * k.wh_per_m
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
    e_end = _service_end_e(k, e_wait - d * k.wh_per_m, task.service_s)
    floor_wh = k.reserve_wh - EPS_WH
    direct_ok = e_end - ret_e >= floor_wh and e_wait >= floor_wh
    rc = None
    service = task.service_s
    if not direct_ok or (not landed and (wait > LONG_WAIT_S or task.topup)):
        rc = recharge_option(k, site, pads, st, task.pos, task.release_s, anchor, ign, soft=soft)
        if rc is not None:
            if task.full_s is not None:  # a running task redone in full after recharging
                service = task.full_s
            short = _service_end_e(k, rc.e_at_task, service) - ret_e < floor_wh
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
        e_end = _service_end_e(k, rc.e_at_task, service)
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
        steps.append(wait_step(t, t + wait, e_wait, pos))
    end = arr + service
    steps.append(
        Step(
            kind=task.kind,
            start_s=arr - tr,
            arrive_s=arr,
            end_s=end,
            energy_after_wh=e_end,
            position_m=task.pos,
            distance_m=d,
            action_id=task.action_id,
            index=task.index,
            tool=task.tool,
        )
    )
    if point is not None:
        res.append(Booking(point, arr, end))
    if task.kind == "pick":
        tool = task.tool
    elif task.kind == "deliver":
        tool = None
    return State(end, task.pos, e_end, False, tool)


def _deadlines(k: Kin, tasks: list[Visit]) -> list[float | None]:
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
    site: SiteMap,
    pads: Pads,
    st: State,
    tasks: list[Visit],
    ign: Ignore,
    old: list[State] | None = None,
    old_map: list[int] | None = None,
) -> Sim | Fail:
    """Simulate ``tasks`` from ``st``; a reason code (``Fail``) if one is
    infeasible. With ``old``/``old_map`` (task i was task ``old_map[i]`` of
    the route being edited, -1 if new), stops as soon as the state after a
    task equals the old one: the rest of the old route is then unchanged."""
    steps: list[Step] = []
    res: list[Booking] = []
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
