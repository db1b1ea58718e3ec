"""How soon, and for how long, a UAV can be at a monitoring slot: the
bounds ``monitor`` and ``monitor_start`` choose segments and start times
with, computed as ``simulate.advance`` would fly them (directly, after a
recharge, or after hops along stations)."""

from __future__ import annotations

from math import dist

from ground_station.planner.energy import EPS_S, EPS_WH, Kin, SiteMap, recharge_time_s
from ground_station.planner.model import Vec3
from ground_station.planner.pads import Ignore, Pads
from ground_station.planner.recharge import next_hop, recharge_option
from ground_station.planner.simulate import MAX_HOPS
from ground_station.planner.state import State


def monitor_reach(
    k: Kin, site: SiteMap, pads: Pads, st: State, pos: Vec3, anchor: float, ign: Ignore, need: float
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
    site: SiteMap,
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
            near = site.nearest(pos).station
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


def hold_floor_wh(k: Kin, site: SiteMap, pos: Vec3, hold_s: float) -> float:
    """Battery needed at ``pos`` to hover ``hold_s`` there and then reach the
    nearest station above the reserve."""
    return k.reserve_wh - EPS_WH + site.nearest(pos).distance_m * k.wh_per_m + k.hover_whps * hold_s


def _hop(
    k: Kin,
    site: SiteMap,
    pads: Pads,
    st: State,
    pos: Vec3,
    ign: Ignore,
    latest: float | None = None,
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
    k: Kin, site: SiteMap, pads: Pads, st: State, pos: Vec3, anchor: float, ign: Ignore, need: float
) -> float | None:
    """``monitor_reach`` without hops: the latest end flying straight from
    ``st``, or after a recharge if that is needed for ``need``."""
    t, p, e, landed, _ = st
    d = dist(p, pos)
    tr = d / k.speed_mps
    ret_e = site.nearest(pos).distance_m * k.wh_per_m
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
