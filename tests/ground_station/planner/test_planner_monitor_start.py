"""Monitoring start times when the UAVs must recharge first (issue 16, item 4)."""

from __future__ import annotations

import msgspec
import pytest

from ground_station.planner import (
    Airframe,
    InspectJob,
    MonitorJob,
    Problem,
    Station,
    Uav,
    Viewpoint,
    plan,
    validate,
)

SAFETY = Airframe(
    id="safety",
    capabilities={"monitor": 0.0},
    cruise_speed_mps=10.0,
    battery_wh=60.0,
    flight_power_w=230.0,
    hover_power_w=210.0,
)
INSPECTION = Airframe(
    id="inspection",
    capabilities={"inspect": 0.0, "monitor": 0.5},
    cruise_speed_mps=10.0,
    battery_wh=60.0,
    flight_power_w=230.0,
    hover_power_w=210.0,
)
CHARGE_S = 600.0


def _problem() -> Problem:
    """U1 (monitoring only) sits on the pad with too little battery to watch
    at all; U2 is busy with a long inspection first. The monitoring should
    start as soon as U1 has recharged, not when U2 is free."""
    station = Station(id="S", position_m=(0.0, 0.0, 0.0), full_charge_s=CHARGE_S)
    uavs = (
        Uav(id="U1", type="safety", position_m=(0.0, 0.0, 0.0), home_station="S", energy_wh=15.0),
        Uav(
            id="U2", type="inspection", position_m=(0.0, 0.0, 0.0), home_station="S", energy_wh=60.0
        ),
    )
    inspect = InspectJob(
        id="line",
        weight=2.0,
        waypoints=tuple(
            Viewpoint(position_m=(x, 20.0, 5.0), service_s=300.0)
            for x in (-40.0, -20.0, 20.0, 40.0)
        ),
    )
    watch = MonitorJob(id="watch", worker_m=(100.0, 0.0, 0.0), duration_s=300.0)
    return Problem(
        stations=(station,),
        uav_types=(SAFETY, INSPECTION),
        uavs=uavs,
        actions=(inspect, watch),
    )


def test_monitoring_starts_after_recharge_first_not_at_the_fleets_last_finish() -> None:
    problem = _problem()
    result = plan(problem)
    assert validate(problem, result) == []
    assert result.unplaced == ()
    steps = {u.uav_id: u.steps for u in result.uavs}
    t0 = min(s.arrive_s for s in steps["U1"] + steps["U2"] if s.action_id == "watch")
    inspect_end = max(s.end_s for s in steps["U2"] if s.action_id == "line")
    # U1 charges 15 -> 60 Wh (3/4 of a full charge) and flies 100 m at 10 m/s.
    ready = 0.75 * CHARGE_S + 10.0
    assert t0 <= ready + 1.0
    assert t0 < inspect_end
    assert [s.kind for s in steps["U1"]][:2] == ["recharge", "monitor"]


def test_a_synchronised_start_leaves_the_take_off_time_to_a_uav_on_a_pad() -> None:
    """Two landed UAVs watch one worker together: the start is their flight
    time plus ``takeoff_s`` (the live fleet's UAVs arrived 5-10 s into the
    window, having armed and climbed in time the plan did not count)."""
    station = Station(id="S", position_m=(0.0, 0.0, 0.0))
    uavs = tuple(
        Uav(id=u, type="safety", position_m=(0.0, 0.0, 0.0), home_station="S", energy_wh=60.0)
        for u in ("U1", "U2")
    )
    watch = MonitorJob(id="watch", worker_m=(100.0, 0.0, 0.0), k=2, duration_s=120.0)
    base = Problem(stations=(station,), uav_types=(SAFETY,), uavs=uavs, actions=(watch,))

    def start(problem: Problem) -> float:
        result = plan(problem)
        assert validate(problem, result) == []
        segments = [s for u in result.uavs for s in u.steps if s.kind == "monitor"]
        assert len(segments) == 2
        return max(s.end_s - 120.0 for s in segments)

    flight = start(base)
    assert flight >= 100.0 / 10.0 - 4.0  # about 10 s at 10 m/s to the ring
    later = start(msgspec.structs.replace(base, takeoff_s=8.0))
    assert later == pytest.approx(flight + 8.0, abs=0.5)
