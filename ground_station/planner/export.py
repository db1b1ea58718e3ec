"""Turning the planning state into a ``Plan`` document."""

from __future__ import annotations

from math import dist

from ground_station.planner.ending import end_steps
from ground_station.planner.metrics import compute_metrics
from ground_station.planner.result import Plan, Step, UavPlan, Unplaced
from ground_station.planner.routes import Ctx


def to_step(raw: tuple) -> Step:
    kind, start, arrive, end, e_after, pos, action_id, index, station, tool, d = raw
    return Step(
        kind=kind,
        start_s=start,
        arrive_s=arrive,
        end_s=end,
        position_m=pos,
        energy_after_wh=e_after,
        distance_m=d,
        action_id=action_id,
        index=index,
        station=station,
        tool=tool,
    )


def emergency_steps(ctx: Ctx, uid: str) -> tuple[Step, ...]:
    """Land a UAV that cannot reach a station above the reserve."""
    sid, st, kin = ctx.emergency[uid]
    station = ctx.site.by_id[sid]
    d = dist(st.pos, station.position_m)
    if d < 1e-9 and st.landed:
        return ()
    end = st.t + d / kin.speed_mps
    e = st.e - d * kin.wh_per_m
    return (to_step(("home", st.t, end, end, e, station.position_m, None, None, sid, None, d)),)


def export(ctx: Ctx) -> Plan:
    """The plan: every UAV's steps (home legs added), unplaced parts, metrics."""
    pads = ctx.pads.copy()
    uavs = []
    for u in ctx.problem.uavs:
        r = ctx.routes.get(u.id)
        if u.id in ctx.emergency:
            uavs.append(UavPlan(uav_id=u.id, steps=emergency_steps(ctx, u.id)))
            continue
        if r is None:
            uavs.append(UavPlan(uav_id=u.id))
            continue
        home, res = end_steps(r.kin, ctx.site, pads, r.tail(), None)
        for si, s, e in res:
            pads.add(si, s, e, u.id)
        steps = tuple(to_step(s) for s in (*r.steps, *home))
        uavs.append(UavPlan(uav_id=u.id, steps=steps))
    unplaced: list[Unplaced] = []
    for a in ctx.problem.actions:
        unplaced.extend(ctx.unplaced.get(a.id, ()))
    plan = Plan(uavs=tuple(uavs), unplaced=tuple(unplaced))
    return Plan(uavs=plan.uavs, unplaced=plan.unplaced, metrics=compute_metrics(ctx.problem, plan))
