"""Plan metrics, computed from the plan document alone (plus the problem)."""

from __future__ import annotations

from ground_station.planner.model import Problem
from ground_station.planner.result import Metrics, Solution


def completion_times(plan: Solution) -> dict[str, float]:
    """Per action, the end of its last step (deliver, last waypoint, monitoring end)."""
    out: dict[str, float] = {}
    for up in plan.uavs:
        for s in up.steps:
            if (
                s.action_id is not None
                and s.kind != "pick"
                and s.end_s > out.get(s.action_id, float("-inf"))
            ):
                out[s.action_id] = s.end_s
    return out


def compute_metrics(problem: Problem, plan: Solution, planning_time_s: float = 0.0) -> Metrics:
    """Makespan, distance, energy used, recharges, weighted completion."""
    now = problem.now_s
    types = {t.id: t for t in problem.uav_types}
    uavs = {u.id: u for u in problem.uavs}
    makespan = 0.0
    distance = 0.0
    energy = 0.0
    recharges = 0
    for up in plan.uavs:
        if not up.steps:
            continue
        u = uavs[up.uav_id]
        t = types[u.type]
        wh_per_m = t.flight_power_w / t.cruise_speed_mps / 3600.0
        e = u.energy_wh
        for s in up.steps:
            distance += s.distance_m
            if s.kind == "recharge":
                energy += s.distance_m * wh_per_m
                recharges += 1
            else:
                energy += max(0.0, e - s.energy_after_wh)
            e = s.energy_after_wh
        makespan = max(makespan, up.steps[-1].end_s - now)
    done = completion_times(plan)
    failed = {x.action_id for x in plan.unplaced}
    weighted = sum(
        a.weight * (done[a.id] - now)
        for a in problem.actions
        if a.id in done and a.id not in failed
    )
    return Metrics(
        makespan_s=makespan,
        distance_m=distance,
        energy_wh=energy,
        recharges=recharges,
        weighted_completion_s=weighted,
        unplaced_parts=len(plan.unplaced),
        planning_time_s=planning_time_s,
        mean_completion_s=weighted / max(1e-9, sum(a.weight for a in problem.actions)),
    )
