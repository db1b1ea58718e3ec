"""``linecrew chaos``: a seed names one schedule, and a short seeded run on a
real local fleet ends with a report of zero violations."""

from __future__ import annotations

import heapq
import importlib
import itertools
import threading
import time
import types

import httpx
import pytest

from linecrew.chaos import ChaosOptions, ChaosRunner, Checker, main, make_schedule
from linecrew.chaos.invariants import EXECUTING_TWICE_S
from linecrew.chaos.netns import NetnsError
from linecrew.chaos.report import reproduce
from linecrew.chaos.schedule import DISRUPTIONS
from linecrew.chaos.timeline import Timeline
from linecrew_runtime.process import Shutdown
from linecrew_runtime.scenarios import load
from proto import Point, SafetyViolation, SimState, VehicleTruth, WatchRecord

chaos_main = importlib.import_module("linecrew.chaos.main")  # the package exports main()

PAPER = load("paper")
SEED = 7


def test_a_seed_gives_the_same_schedule_every_time():
    first = make_schedule(SEED, 120.0, PAPER)
    assert first == make_schedule(SEED, 120.0, PAPER)
    assert first != make_schedule(SEED + 1, 120.0, PAPER)
    assert {i.kind for i in first} >= {"partition", "action"}


@pytest.mark.parametrize("netns", [False, True])
@pytest.mark.parametrize("seed", range(20))
def test_disruptions_never_overlap_and_stay_in_the_run(seed, netns):
    schedule = make_schedule(seed, 90.0, PAPER, netns)
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


def test_the_checker_flags_one_task_executed_by_two_only_while_both_are_heard_on_it():
    """Two UAVs' statuses naming one task count once they have for
    ``EXECUTING_TWICE_S``; a silent UAV's last status is no evidence (chaos
    seed 12: a killed agent's last word named the waypoint a replan had
    just given another, until it fell silent)."""

    def fleet(silent: bool = False) -> list[dict]:
        busy = {"state": "busy", "task_id": "a2.wp0-0"}
        quiet = {"silent_since_s": 10.0} if silent else {}
        return [
            {"uav_id": "u1", "state": "ok", "status": busy, **quiet},
            {"uav_id": "u2", "state": "ok", "status": busy},
        ]

    checker = Checker(reserve_fraction=0.2)
    checker.sample(10.0, None, None, fleet(), None)
    checker.sample(11.0, None, None, fleet(), None)
    checker.sample(12.0, None, None, fleet(silent=True), None)
    checker.sample(16.0, None, None, fleet(silent=True), None)
    assert checker.violations == []
    checker.sample(17.0, None, None, fleet(), None)
    checker.sample(17.0 + EXECUTING_TWICE_S, None, None, fleet(), None)
    assert [v.detail for v in checker.violations] == ["a2.wp0-0 executed by ['u1', 'u2']"]


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


def test_an_action_left_waiting_by_a_crash_is_excused_any_other_unfinished_is_not():
    """Chaos seed 16: a delivery asked for after a motor fault crashed the
    only UAV with a gripper waits for a capable UAV: a person must act."""
    waiting = {"action_id": "a1", "state": "accepted", "reason": "no_capable_uav"}
    crashed = VehicleTruth(
        uav_id="uav-1",
        position=Point(x_m=0, y_m=0),
        battery_fraction=0.5,
        state="crashed",
        armed=False,
    )
    for fault, violations in (("motor fault", 0), (None, 1)):
        checker = Checker(reserve_fraction=0.2)
        if fault:
            checker.excuse("uav-1", fault)
        checker.accepted("a1", 0.0)
        checker.sample(
            1.0, None, None, None, SimState(sim_time_s=1.0, speedup=1.0, vehicles=[crashed])
        )
        checker.finish(2.0, [waiting])
        assert len(checker.violations) == violations, checker.violations
        assert len(checker.excused) == 1 - violations


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


def _cuts(netns: bool) -> list:
    return [
        i
        for seed in range(40)
        for i in make_schedule(seed, 120.0, PAPER, netns)
        if i.kind in {"partition", "cut_burst"}
    ]


def test_partitions_cut_agents_and_ground_processes_the_gateway_only_for_real():
    uavs = {u.id for u in PAPER.fleet.uavs}
    real = {i.target for i in _cuts(True)}
    frozen = {i.target for i in _cuts(False)}
    assert real == uavs | {"ground-station", "gateway", "router"}
    assert frozen == uavs | {"ground-station", "router"}  # a frozen gateway stalls the observer
    holds = [i.hold_s for i in _cuts(True) if i.kind == "partition"]
    assert any(3.0 < h < 5.0 for h in holds), "cuts at the agents' and the gs's grace boundary"


def test_a_burst_is_three_to_five_short_cuts_with_gaps_inside_its_hold():
    bursts = [i for i in _cuts(True) if i.kind == "cut_burst"]
    assert bursts
    for burst in bursts:
        cuts = burst.params["cuts"]
        assert 3 <= len(cuts) <= 5
        assert all(0.5 <= hold <= 1.5 for _, hold in cuts)
        for (start, hold), (after, _) in itertools.pairwise(cuts):
            assert 0.29 <= after - (start + hold) <= 1.51  # rounded to 0.01 s
        assert burst.hold_s == pytest.approx(sum(cuts[-1]), abs=0.01)


def test_a_router_kill_follows_a_new_action_within_half_a_second():
    kills = [
        i
        for seed in range(40)
        for i in make_schedule(seed, 120.0, PAPER)
        if i.kind == "replan_kill_router"
    ]
    assert kills
    for kill in kills:
        assert kill.params["action"]["action_id"].startswith("chaos-")
        assert 0 < kill.params["kill_after_s"] <= 0.5
        assert kill.hold_s == pytest.approx(kill.params["kill_after_s"] + kill.params["down_s"])


def test_the_timeline_runs_steps_in_due_order_on_time_and_the_rest_at_close():
    t0 = time.monotonic()
    timeline = Timeline(lambda: time.monotonic() - t0)
    done: list[tuple[str, float]] = []

    def step(name: str):
        return lambda: done.append((name, time.monotonic() - t0))

    def broken():
        raise RuntimeError("a step that fails")

    timeline.at(0.3, step("second"))
    timeline.at(0.1, broken)
    timeline.at(0.2, step("first"))
    timeline.at(60.0, step("left"))
    deadline = time.monotonic() + 10
    while timeline.pending() > 1 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert [name for name, _ in done] == ["first", "second"]
    assert done[0][1] >= 0.2 and done[1][1] >= 0.3
    timeline.close()
    assert [name for name, _ in done] == ["first", "second", "left"]
    assert timeline.pending() == 0


def test_the_final_action_list_waits_for_a_gateway_that_just_came_back():
    answers = iter([503, 503, 200])

    def gateway(request: httpx.Request) -> httpx.Response:
        status = next(answers, 200)
        return httpx.Response(status, json=[] if status == 200 else {"error": "gs unreachable"})

    runner = ChaosRunner(PAPER, ChaosOptions(seed=SEED), Shutdown())
    client = httpx.Client(base_url="http://gateway", transport=httpx.MockTransport(gateway))
    assert runner._final(client) == []


def test_the_reproduce_line_names_every_option_of_the_run():
    options = ChaosOptions(seed=4, duration_s=120, drain_s=60, scenario_actions=False, netns=True)
    assert reproduce(options) == (
        "linecrew chaos --seed 4 --duration 120 --speedup 10 --drain 60 "
        "--no-scenario-actions --netns"
    )
    assert "--netns" not in reproduce(ChaosOptions(seed=4))


def test_netns_refused_is_a_clear_error(monkeypatch, capsys):
    def refused() -> None:
        raise NetnsError("network namespaces need `ip netns add`: Operation not permitted")

    monkeypatch.setattr(chaos_main, "check_available", refused)
    assert chaos_main.main(["--seed", "1", "--netns"]) == 2
    assert "--netns: network namespaces need `ip netns add`" in capsys.readouterr().err


class _Faults:
    """Records what the runner does to the router, and on which thread."""

    def __init__(self) -> None:
        self.done: list[tuple[str, float, bool]] = []

    def kill(self, name: str) -> None:
        self.done.append((f"kill {name}", time.monotonic(), _on_main_thread()))

    def restart(self, name: str):
        self.done.append((f"restart {name}", time.monotonic(), _on_main_thread()))
        return types.SimpleNamespace(popen=types.SimpleNamespace(pid=1))


def _on_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def test_the_replan_router_kill_follows_the_answer_and_restarts_on_the_main_thread():
    # a child started off the main thread dies with that thread (PR_SET_PDEATHSIG)
    kill = next(
        i
        for seed in range(40)
        for i in make_schedule(seed, 120.0, PAPER)
        if i.kind == "replan_kill_router"
    )
    answered: list[float] = []

    def gateway(request: httpx.Request) -> httpx.Response:
        answered.append(time.monotonic())
        return httpx.Response(201, json={})

    runner = ChaosRunner(PAPER, ChaosOptions(seed=SEED), Shutdown())
    runner._t0 = time.monotonic()
    faults = _Faults()
    client = httpx.Client(base_url="http://gateway", transport=httpx.MockTransport(gateway))
    runner._apply(kill, None, faults, client)
    while runner._heals:
        due, _, step = heapq.heappop(runner._heals)
        time.sleep(max(0.0, due - runner._now()))
        step()
    (killed, kill_t, kill_main), (restarted, restart_t, restart_main) = faults.done
    assert (killed, restarted) == ("kill router", "restart router")
    assert kill_t - answered[0] >= kill.params["kill_after_s"] - 0.01
    assert restart_t - kill_t >= kill.params["down_s"] - 0.01
    assert kill_main and restart_main
    assert list(runner.checker.accepted_at) == [kill.params["action"]["action_id"]]
