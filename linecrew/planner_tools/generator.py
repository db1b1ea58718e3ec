"""Seeded instance generator: a power-line corridor.

Towers every 250-350 m along a gently curving line, charging stations beside
the line every few kilometres (a mix of battery swap and charging, 1-3
pads), tool stations, a mix of physical / inspection / safety UAVs on small
batteries (about 12-15 min of flight, so long jobs force recharges and
monitoring forces hand-overs), and a mix of actions around the towers.
Same arguments, same problem.

Families (``FAMILIES``) stress one shape each: ``corridor`` (the mix above),
``long`` (the work starts 15 km from the homes, 1.5 to 2.3 full batteries
out), ``charge`` (charging stations only, one pad each, slow:
partial charges matter), ``monitors`` (k = 2-3 monitors lasting 20-30 min,
more than a battery) and ``tools`` (mostly deliveries, one gripper UAV).
"""

from __future__ import annotations

import dataclasses
import random
from collections.abc import Iterable
from math import sin

from ground_station.planner.model import (
    Airframe,
    DeliverJob,
    InspectJob,
    Job,
    MonitorJob,
    Problem,
    Station,
    ToolDepot,
    Uav,
    Vec3,
    Viewpoint,
)

TOOLS = ("hammer", "wrench", "multimeter", "pliers", "insulator_tester")
TYPES = (
    Airframe(
        id="physical",
        capabilities={"deliver": 0.0, "inspect": 1.0, "monitor": 1.0},
        cruise_speed_mps=10.0,
        battery_wh=70.0,
        flight_power_w=300.0,
        hover_power_w=280.0,
    ),
    Airframe(
        id="inspection",
        capabilities={"inspect": 0.0, "monitor": 0.5},
        cruise_speed_mps=14.0,
        battery_wh=55.0,
        flight_power_w=220.0,
        hover_power_w=200.0,
    ),
    Airframe(
        id="safety",
        capabilities={"monitor": 0.0, "inspect": 0.5},
        cruise_speed_mps=12.0,
        battery_wh=60.0,
        flight_power_w=230.0,
        hover_power_w=210.0,
    ),
)


RING_STEP_DEG = 5.0
"""Bearings tried for a worker's next monitoring, this far apart."""


def _slots_deg(bearing_deg: float, k: int) -> list[float]:
    return [(bearing_deg + 360.0 * s / k) % 360.0 for s in range(k)]


def _apart_deg(a: float, b: float) -> float:
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def ring_bearing(actions: Iterable[Job], worker_m: Vec3, k: int = 1) -> float:
    """A bearing for one more ``k``-UAV monitoring of the worker at
    ``worker_m`` that keeps its slots farthest from those of the worker's
    monitors in ``actions`` (the smallest angle maximised, as the ground
    station spreads them), so that no two slots coincide."""
    taken = [
        b
        for a in actions
        if isinstance(a, MonitorJob) and a.worker_m == worker_m
        for b in _slots_deg(a.bearing_deg, a.k)
    ]
    if not taken:
        return 0.0
    candidates = [i * RING_STEP_DEG for i in range(round(360.0 / k / RING_STEP_DEG))]
    return max(
        candidates,
        key=lambda c: min(_apart_deg(m, t) for m in _slots_deg(c, k) for t in taken),
    )


@dataclasses.dataclass(frozen=True)
class Family:
    """Knobs of one instance family (the defaults are ``corridor``)."""

    lead_m: float = 0.0
    """Empty line before the first tower (stations along it too)."""
    homes_at_start: bool = False
    """Every UAV's home is the first station (else spread along the line)."""
    swap_share: float = 0.4
    pads: tuple[int, int] = (1, 3)
    full_charge_s: tuple[float, ...] = (900.0, 1200.0)
    mix: tuple[float, float] = (0.5, 0.8)
    """Action kinds: inspect below the first, monitor below the second,
    else deliver."""
    k: tuple[int, ...] = (1, 1, 2, 2, 3)
    """Monitoring UAVs per watch (1 below 6 UAVs unless ``k_always``: then
    at most a third of the fleet)."""
    k_always: bool = False
    durations_s: tuple[float, ...] = (300, 600, 900, 1200)
    one_gripper: bool = False
    """Only the first UAV can deliver (the others inspect or watch)."""


FAMILIES = {
    "corridor": Family(),
    "long": Family(lead_m=15000.0, homes_at_start=True),
    "charge": Family(swap_share=0.0, pads=(1, 1), full_charge_s=(1200.0, 1800.0)),
    "monitors": Family(
        swap_share=0.8, mix=(0.3, 0.9), k=(2, 3), k_always=True, durations_s=(1200, 1800)
    ),
    "tools": Family(mix=(0.2, 0.35), one_gripper=True),
}


def _k(fam: Family, rng: random.Random, n_uavs: int) -> int:
    """Monitoring UAVs for one watch: at most a third of the fleet when every
    watch has several (each slot needs reliefs)."""
    if fam.k_always:
        return min(rng.choice(fam.k), max(1, n_uavs // 3))
    return rng.choice(fam.k) if n_uavs >= 6 else 1


def generate(n_uavs: int, n_actions: int, seed: int = 0, family: str = "corridor") -> Problem:
    """A problem of ``family`` with ``n_uavs`` UAVs and ``n_actions`` actions."""
    fam = FAMILIES[family]
    rng = random.Random(seed * 1_000_003 + n_uavs * 1009 + n_actions)
    n_towers = max(8, n_actions // 3 + 4, n_uavs * 2)
    towers = []
    x = fam.lead_m
    for i in range(n_towers):
        x += rng.uniform(250.0, 350.0)
        towers.append((x, 120.0 * sin(i / 7.0), rng.uniform(25.0, 40.0)))
    length = towers[-1][0]
    n_st = max(2, round(length / 2500.0) + 1)
    stations = []
    for i in range(n_st):
        sx = length * i / (n_st - 1)
        side = 80.0 if i % 2 else -80.0
        swap = rng.random() < fam.swap_share
        stations.append(
            Station(
                id=f"S{i}",
                position_m=(round(sx, 1), round(120.0 * sin(sx / 300.0 / 7.0) + side, 1), 0.0),
                pads=rng.randint(*fam.pads),
                recharge="swap" if swap else "charge",
                swap_s=90.0,
                full_charge_s=rng.choice(fam.full_charge_s),
            )
        )
    tool_stations = [
        ToolDepot(
            id=f"T{i}",
            position_m=(stations[i].position_m[0] + 30.0, stations[i].position_m[1], 2.0),
            tools=TOOLS,
        )
        for i in range(0, n_st, 2)
    ]
    uavs = []
    for i in range(n_uavs):
        utype = TYPES[(i % 2 + 1 if i else 0) if fam.one_gripper else i % 3]
        st = stations[0 if fam.homes_at_start else (i * 7) % n_st]
        uavs.append(
            Uav(
                id=f"U{i:02d}",
                type=utype.id,
                position_m=st.position_m,
                home_station=st.id,
                energy_wh=round(utype.battery_wh * rng.uniform(0.6, 1.0), 2),
            )
        )
    actions: list[Job] = []
    for i in range(n_actions):
        r = rng.random()
        weight = float(rng.randint(1, 5))
        release = 0.0 if rng.random() < 0.7 else round(rng.uniform(0.0, 1800.0), 1)
        centre = rng.randrange(n_towers)
        if r < fam.mix[0]:
            n_wp = rng.randint(3, min(10, n_towers))
            start = max(0, min(centre, n_towers - n_wp))
            wps = tuple(
                Viewpoint(
                    position_m=(
                        towers[j][0] + rng.uniform(-8, 8),
                        towers[j][1] + 10.0,
                        towers[j][2],
                    ),
                    service_s=float(rng.randint(20, 60)),
                )
                for j in range(start, start + n_wp)
            )
            actions.append(
                InspectJob(id=f"A{i:03d}", weight=weight, release_s=release, waypoints=wps)
            )
        elif r < fam.mix[1]:
            tx, ty, tz = towers[centre]
            k = _k(fam, rng, n_uavs)
            actions.append(
                MonitorJob(
                    bearing_deg=ring_bearing(actions, (tx, ty, tz - 5.0), k),
                    id=f"A{i:03d}",
                    weight=weight,
                    release_s=release,
                    worker_m=(tx, ty, tz - 5.0),
                    k=k,
                    standoff_m=10.0,
                    duration_s=float(rng.choice(fam.durations_s)),
                )
            )
        else:
            tx, ty, tz = towers[centre]
            ts = min(tool_stations, key=lambda s: abs(s.position_m[0] - tx))
            actions.append(
                DeliverJob(
                    id=f"A{i:03d}",
                    weight=weight,
                    release_s=release,
                    tool=rng.choice(TOOLS),
                    tool_station=ts.id,
                    worker_m=(tx, ty, tz - 5.0),
                    pick_s=15.0,
                    drop_s=20.0,
                )
            )
    return Problem(
        stations=tuple(stations),
        tool_stations=tuple(tool_stations),
        uav_types=TYPES,
        uavs=tuple(uavs),
        actions=tuple(actions),
    )
