"""Recharge decisions: where to charge, for how long, and pad slots.

A recharge detour flies to a station (landing to wait if no pad is free),
charges to full (or partially, when an anchored task or a soft deadline
leaves less time) and flies on. Hops chain recharges along the stations
when a target is beyond one battery's range.
"""

from __future__ import annotations

from math import dist
from typing import NamedTuple

from ground_station.planner.energy import (
    EPS_S,
    EPS_WH,
    Kin,
    SiteMap,
    energy_after_recharge,
    recharge_time_s,
)
from ground_station.planner.model import Vec3
from ground_station.planner.pads import Ignore, Pads
from ground_station.planner.result import Step
from ground_station.planner.state import Booking, State

PAD_WAIT_S = 300.0
"""A recharge that waits longer than this for a pad makes us try every station."""
LATE_MARGIN_S = 1e-3
"""Slack over ``latest`` beyond which even the shortest detour is surely too
late (far above rounding error and ``EPS_S``), so no station is tried."""


class RcOption(NamedTuple):
    """A recharge detour: at charging station ``si``, after a wait of
    ``wait_s`` for a pad, charging ``dur_s`` from ``e_before`` to
    ``e_charged`` Wh; the target is then reached at ``arrive_task`` with
    ``e_at_task`` Wh."""

    si: int
    wait_s: float
    dur_s: float
    e_before: float
    e_charged: float
    arrive_task: float
    e_at_task: float


def recharge_option(
    k: Kin,
    site: SiteMap,
    pads: Pads,
    st: State,
    target: Vec3,
    release_s: float,
    latest: float | None,
    ign: Ignore,
    target_wh: float | None = None,
    only: int | None = None,
    soft: float | None = None,
) -> RcOption | None:
    """Best recharge detour from ``st`` before flying to ``target``.

    The UAV flies to a station (landing to wait if no pad is free), charges
    (to full; or as much as fits before ``latest``, the required arrival at
    ``target``; or, charge model, to ``target_wh`` plus the onward leg) and
    flies on. Best = earliest arrival at ``target``, then most energy.
    ``only`` restricts the choice to one station index. ``soft``: arrive by
    then if a shorter (partial) charge allows it (keeps later anchored tasks
    reachable).
    """
    if only is not None:
        return _rc_best(k, site, pads, st, target, release_s, latest, ign, target_wh, soft, [only])
    first, rest, shortest_m = site.candidates(st.pos, target)
    if latest is not None and st.t + shortest_m / k.speed_mps > latest + LATE_MARGIN_S:
        return None  # no detour arrives in time
    best = _rc_best(k, site, pads, st, target, release_s, latest, ign, target_wh, soft, first)
    if best is None or best.wait_s > PAD_WAIT_S:
        # Pads near by are busy (or out of reach): look at every station.
        best = _rc_best(
            k, site, pads, st, target, release_s, latest, ign, target_wh, soft, rest, best
        )
    return best


def _rc_best(
    k: Kin,
    site: SiteMap,
    pads: Pads,
    st: State,
    target: Vec3,
    release_s: float,
    latest: float | None,
    ign: Ignore,
    target_wh: float | None,
    soft: float | None,
    stations: list[int],
    best: RcOption | None = None,
) -> RcOption | None:
    """``best`` or the first option at ``stations`` that beats it.

    One loop over the stations kept whole: it runs for every recharge
    considered (the planner's hottest loop after ``advance``), and a helper
    call per station would cost more than its body."""
    t, pos, e, _landed, _ = st
    speed, wh_per_m, capacity = k.speed_mps, k.wh_per_m, k.capacity_wh
    floor_wh = k.reserve_wh - EPS_WH
    d_from, d_to = site.dists(pos), site.dists(target)
    for si in stations:
        station = site.charging[si]
        d1 = d_from[si]
        ea = e - d1 * wh_per_m
        if ea < floor_wh and d1 > 0.0:
            continue
        t_arr = t + d1 / speed
        tr2 = d_to[si] / speed
        if latest is not None and t_arr > latest - tr2 + EPS_S:
            continue  # cannot be on the pad before it must leave (``first_fit``)
        dur = recharge_time_s(station, capacity, ea)
        if target_wh is not None and station.recharge == "charge":
            want = min(capacity, target_wh + tr2 * speed * wh_per_m)
            dur = min(dur, station.full_charge_s * max(0.0, want - ea) / capacity)
        if latest is None:
            start = pads.earliest(si, t_arr, dur, ign)
            if soft is not None and station.recharge == "charge":
                cap = soft - tr2 - start
                if EPS_S < cap < dur:
                    dur = cap
        else:
            if best is not None and max(capacity, ea) - tr2 * speed * wh_per_m <= best.e_at_task:
                continue  # arrives at ``latest`` like ``best``, with no more energy
            need = station.swap_s if station.recharge == "swap" else EPS_S
            fit = pads.first_fit(si, t_arr, latest - tr2, dur, need, ign)
            if fit is None:
                continue
            start, dur = fit
        charged = energy_after_recharge(station, capacity, ea, dur)
        arrive = max(start + dur + tr2, release_s)
        if latest is not None:
            if arrive > latest + EPS_S:
                continue
            arrive = latest
        e_at = charged - tr2 * speed * wh_per_m
        if (
            best is None
            or arrive < best.arrive_task
            or (arrive == best.arrive_task and e_at > best.e_at_task)
        ):
            best = RcOption(si, start - t_arr, dur, ea, charged, arrive, e_at)
    return best


def emit_recharge(
    k: Kin, site: SiteMap, st: State, rc: RcOption, steps: list[Step], res: list[Booking]
) -> State:
    """Append the flight to the pad (landing to wait for a free pad if needed)
    and the recharge; returns the state on the pad."""
    t, pos, _e, _landed, tool = st
    station = site.charging[rc.si]
    sp = site.positions[rc.si]
    d1 = site.dists(pos)[rc.si]
    arr = t + d1 / k.speed_mps
    if rc.wait_s > EPS_S:
        end = arr + rc.wait_s
        steps.append(
            Step(
                kind="wait",
                start_s=t,
                arrive_s=arr,
                end_s=end,
                energy_after_wh=rc.e_before,
                position_m=sp,
                distance_m=d1,
            )
        )
        t, arr, d1 = end, end, 0.0
    end = arr + rc.dur_s
    steps.append(
        Step(
            kind="recharge",
            start_s=t,
            arrive_s=arr,
            end_s=end,
            energy_after_wh=rc.e_charged,
            position_m=sp,
            distance_m=d1,
            station=station.id,
        )
    )
    res.append(Booking(rc.si, arr, end))
    return State(end, sp, rc.e_charged, True, tool)


def next_hop(k: Kin, site: SiteMap, st: State, target: Vec3) -> int | None:
    """The reachable charging station nearest ``target`` and nearer than us."""
    d_from, d_to = site.dists(st.pos), site.dists(target)
    floor_wh = k.reserve_wh - EPS_WH
    best, best_d = None, dist(st.pos, target) - 1.0
    for si, d in enumerate(d_to):
        if d < best_d and st.e - d_from[si] * k.wh_per_m >= floor_wh:
            best, best_d = si, d
    return best
