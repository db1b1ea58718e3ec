"""``linecrew chaos``: a seed names one schedule, and a short seeded run on a
real local fleet ends with a report of zero violations."""

from __future__ import annotations

import itertools

import pytest

from linecrew.chaos import Checker, main, make_schedule
from linecrew.chaos.schedule import DISRUPTIONS
from linecrew.scenarios import load
from proto import Point, SafetyViolation, SimState, WatchRecord

PAPER = load("paper")
SEED = 7


def test_a_seed_gives_the_same_schedule_every_time():
    first = make_schedule(SEED, 120.0, PAPER)
    assert first == make_schedule(SEED, 120.0, PAPER)
    assert first != make_schedule(SEED + 1, 120.0, PAPER)
    assert {i.kind for i in first} >= {"partition", "action"}


@pytest.mark.parametrize("seed", range(20))
def test_disruptions_never_overlap_and_stay_in_the_run(seed):
    schedule = make_schedule(seed, 90.0, PAPER)
    disruptions = [i for i in schedule if i.kind in DISRUPTIONS]
    for before, after in itertools.pairwise(disruptions):
        assert before.at_s + before.hold_s < after.at_s
    assert all(0 < i.at_s < 90.0 for i in schedule)
    assert [i.at_s for i in schedule] == sorted(i.at_s for i in schedule)


def test_the_checker_flags_a_lost_action_and_work_planned_twice():
    checker = Checker(reserve_fraction=0.2)
    checker.accepted("a1", 0.0)
    task = {
        "type": "inspect",
        "action_id": "a2",
        "task_id": "a2.wp0-0",
        "waypoints": [{"index": 0}],
    }
    plans = [{"uav_id": "u1", "tasks": [task]}, {"uav_id": "u2", "tasks": [task]}]
    checker.sample(1.0, [], plans, None, None)
    assert [v.invariant for v in checker.violations] == ["action_lost", "double_task"]
    checker.finish(2.0, [{"action_id": "a1", "state": "failed", "reason": ""}])
    assert checker.violations[-1].invariant == "failed_without_reason"


def test_the_checker_flags_what_the_simulator_saw_as_unsafe_once_each():
    checker = Checker(reserve_fraction=0.2)
    checker.excuse("uav-3", "battery fault 0.05")
    close = SafetyViolation(
        kind="separation",
        uav_id="uav-1",
        sim_time_s=3.0,
        position=Point(x_m=0, y_m=0),
        detail="uav-2",
    )
    crash = SafetyViolation(
        kind="ground_contact", uav_id="uav-3", sim_time_s=4.0, position=Point(x_m=0, y_m=0)
    )
    checker.sample(1.0, None, None, None, SimState(sim_time_s=3.0, speedup=1.0, violations=[close]))
    truth = SimState(sim_time_s=4.0, speedup=1.0, violations=[close, crash])
    checker.sample(2.0, None, None, None, truth)
    checker.sample(3.0, None, None, None, truth)
    assert [(v.invariant, v.detail) for v in checker.violations] == [
        ("unsafe", "separation uav-1 uav-2 at sim 3.0 s")
    ]
    assert len(checker.excused) == 1 and "battery fault" in checker.excused[0]


def test_a_short_seeded_run_reports_zero_violations(tmp_path, capsys):
    code = main(
        [
            "--seed",
            str(SEED),
            "--duration",
            "45",
            "--drain",
            "90",
            "--speedup",
            "10",
            "--no-scenario-actions",
            "--run-dir",
            str(tmp_path / "run"),
        ]
    )
    report = capsys.readouterr().out
    assert "violations: 0" in report, report
    assert f"reproduce: linecrew chaos --seed {SEED}" in report
    assert code == 0, report


def _monitor(worker: str, uavs: int, monitored_s: float) -> dict:
    action = {"type": "monitor", "worker_id": worker, "uavs": uavs, "duration_s": 600.0}
    return {
        "action_id": f"m-{worker}",
        "state": "in_progress",
        "action": action,
        "monitored_s": monitored_s,
    }


def test_the_checker_flags_monitoring_recorded_beyond_what_the_simulator_saw_watched():
    checker = Checker(reserve_fraction=0.2)
    watched = [
        WatchRecord(worker_id="W1", uav_id="uav-1", seconds=100.0),
        WatchRecord(worker_id="W1", uav_id="uav-2", seconds=98.0),
        WatchRecord(worker_id="W2", uav_id="uav-3", seconds=50.0),
    ]
    truth = SimState(sim_time_s=200.0, speedup=1.0, watched=watched)
    honest = [_monitor("W1", 2, 100.0), _monitor("W2", 1, 50.0)]
    checker.sample(1.0, honest, None, None, truth)
    assert checker.checks["overcredited"] == 1 and not checker.violations
    inflated = [_monitor("W1", 2, 100.0), _monitor("W2", 1, 120.0)]  # 120 s recorded, 50 flown
    checker.sample(2.0, inflated, None, None, truth)
    checker.sample(3.0, inflated, None, None, truth)  # reported once
    assert [(v.invariant, v.detail) for v in checker.violations] == [
        ("overcredited", "W2: 120 UAV-s of monitoring recorded, 50 s watched")
    ]
