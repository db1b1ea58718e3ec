"""Turning the planning state into a ``Solution``."""

from __future__ import annotations

from math import dist

from ground_station.planner.ending import end_steps, landing_step
from ground_station.planner.metrics import compute_metrics
from ground_station.planner.result import Solution, Step, UavPlan, Unplaced
from ground_station.planner.routes import Ctx


def emergency_steps(ctx: Ctx, uid: str) -> tuple[Step, ...]:
    """Land a UAV that cannot reach a station above the reserve."""
    grounded = ctx.emergency[uid]
    st, station = grounded.state, ctx.site.by_id[grounded.station_id]
    d = dist(st.pos, station.position_m)
    if d < 1e-9 and st.landed:
        return ()
    return (landing_step(grounded.kin, st, station.position_m, station.id, d),)


def export(ctx: Ctx) -> Solution:
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
        pads.book(res, u.id)
        uavs.append(UavPlan(uav_id=u.id, steps=(*r.steps, *home)))
    unplaced: list[Unplaced] = []
    for a in ctx.problem.actions:
        unplaced.extend(ctx.unplaced.get(a.id, ()))
    plan = Solution(uavs=tuple(uavs), unplaced=tuple(unplaced))
    return Solution(
        uavs=plan.uavs, unplaced=plan.unplaced, metrics=compute_metrics(ctx.problem, plan)
    )
