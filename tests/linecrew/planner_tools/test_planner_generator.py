"""Instance families of the bench generator: each has the shape it names,
and the planner's plans for them validate."""

from __future__ import annotations

from math import dist

import pytest

from ground_station.planner import DeliverJob, MonitorJob, plan, validate
from linecrew.planner_tools.generator import FAMILIES, TYPES, generate, ring_bearing


def test_the_default_family_is_the_corridor() -> None:
    assert generate(6, 12, 3) == generate(6, 12, 3, "corridor")
    assert generate(6, 12, 3, "long") != generate(6, 12, 3)


def test_long_corridors_put_the_work_several_charges_from_home() -> None:
    problem = generate(3, 6, 0, "long")
    home = problem.stations[0]
    assert {u.home_station for u in problem.uavs} == {home.id}
    nearest_work = min(
        dist(home.position_m, w.position_m)
        for a in problem.actions
        for w in getattr(a, "waypoints", ())
    )
    ranges_m = [
        t.battery_wh * (1 - problem.reserve_fraction) * 3600 / t.flight_power_w * t.cruise_speed_mps
        for t in TYPES
    ]  # 6.7 to 10.1 km on a full battery
    assert nearest_work > 2 * min(ranges_m) and nearest_work > 1.4 * max(ranges_m)


def test_charge_family_has_slow_single_pad_charging_only() -> None:
    problem = generate(4, 12, 1, "charge")
    assert all(s.recharge == "charge" and s.pads == 1 for s in problem.stations)
    assert min(s.full_charge_s for s in problem.stations) >= 1200.0


def test_monitor_family_watches_long_with_several_uavs() -> None:
    problem = generate(10, 30, 0, "monitors")
    watches = [a for a in problem.actions if isinstance(a, MonitorJob)]
    assert len(watches) >= len(problem.actions) // 2
    assert all(2 <= a.k <= 3 and a.duration_s >= 1200 for a in watches)


def test_tools_family_has_one_gripper_for_many_deliveries() -> None:
    problem = generate(6, 20, 0, "tools")
    kinds = {t.id: t.capabilities for t in problem.uav_types}
    grippers = [u for u in problem.uavs if "deliver" in kinds[u.type]]
    assert len(grippers) == 1
    assert sum(isinstance(a, DeliverJob) for a in problem.actions) >= len(problem.actions) // 2


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_plans_for_every_family_validate(family: str) -> None:
    problem = generate(4, 12, 2, family)
    assert validate(problem, plan(problem)) == []


def test_a_workers_next_monitor_is_turned_away_from_every_slot_of_the_others():
    """k = 3 at 0 deg holds 0/120/240: a k = 1 watch goes midway (60 deg), a
    k = 2 one 30 deg from the nearest slot; never to a bearing that is new
    only for slot 0 (the old rule gave 37 deg steps: 481 deg is 1 deg off 120)."""
    worker = (0.0, 0.0, 10.0)
    three = MonitorJob(id="a", worker_m=worker, k=3, bearing_deg=0.0, duration_s=60.0)
    assert ring_bearing([three], worker) == 60.0
    assert ring_bearing([three], worker, 2) in (30.0, 90.0)
    assert ring_bearing([three], (5.0, 0.0, 10.0)) == 0.0  # another worker's slots do not count


@pytest.mark.parametrize(("family", "apart_deg"), [("monitors", 15.0), ("corridor", 30.0)])
def test_slots_of_one_worker_in_a_generated_instance_stay_apart(family, apart_deg):
    """(13 watches on one worker in ``monitors``; the slots of watches that
    overlap in time came within 1 m at a 10 m stand-off and the replan
    stream reported 77 ``separation`` violations at 20x200.)"""
    by_worker: dict = {}
    for a in generate(20, 200, 0, family=family).actions:
        if isinstance(a, MonitorJob):
            slots = [(a.bearing_deg + 360.0 * s / a.k) % 360.0 for s in range(a.k)]
            by_worker.setdefault(a.worker_m, []).extend(slots)
    assert max(len(b) for b in by_worker.values()) >= 8
    for bearings in by_worker.values():
        for i, x in enumerate(bearings):
            for y in bearings[i + 1 :]:
                d = abs(x - y) % 360.0
                assert min(d, 360.0 - d) >= apart_deg, bearings
