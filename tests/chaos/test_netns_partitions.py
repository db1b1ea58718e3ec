"""Partitions, a ground-station crash and a router crash on real processes,
each in a network namespace of its own (placement and why:
:mod:`linecrew.chaos.netns_run`). Skipped, with the reason, where
``ip netns add`` is not permitted.

Every wait samples the plans and checks that no piece of work is in two
UAVs' plans at once (:class:`linecrew.chaos.Checker`)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import msgspec
import pytest

from linecrew.chaos import Checker, main
from linecrew.chaos.faults import ProcessFaults
from linecrew.chaos.netns_run import NetnsRun
from linecrew.launch.local_run import RunOptions
from linecrew_runtime.scenarios import load
from proto import EventKind, GetHistory, GetSimState, HistoryReply, SimState
from proto.keys import Role

SPEEDUP = 10.0
PAPER = load("paper")
UAVS = [u.id for u in PAPER.fleet.uavs]


def _inspect(action_id: str, count: int, service_s: float) -> dict[str, Any]:
    """A line of ``count`` waypoints along the towers, ``service_s`` each."""
    waypoints = [
        {"position": {"x_m": -14.0 + 2.0 * i, "y_m": 7.0, "z_m": 6.0}, "service_s": service_s}
        for i in range(count)
    ]
    return {
        "type": "inspect",
        "action_id": action_id,
        "request_id": f"req-{action_id}",
        "waypoints": waypoints,
    }


class Watch:
    """REST and simulator views of the fleet, with the invariants checked on
    every look."""

    def __init__(self, fleet: NetnsRun) -> None:
        self.fleet = fleet
        self.http = fleet.http(timeout_s=4.0)
        self.checker = Checker(PAPER.fleet.reserve_fraction)
        self.started = time.monotonic()

    def _t(self) -> float:
        return time.monotonic() - self.started

    def get(self, path: str) -> Any:
        try:
            response = self.http.get(path)
        except Exception:
            return None
        return response.json() if response.status_code == 200 else None

    def submit(self, body: dict[str, Any]) -> None:
        response = self.http.post("/v1/actions", json=body)
        assert response.status_code == 201, response.text
        self.checker.accepted(body["action_id"], self._t())

    def sample(self) -> None:
        self.checker.sample(self._t(), self.get("/v1/actions"), self.get("/v1/plan"), None, None)

    def until(self, what: str, predicate: Callable[[], object], timeout_s: float = 60.0) -> Any:
        """Poll (sampling the invariants) until ``predicate()`` is truthy."""
        deadline = time.monotonic() + timeout_s
        while True:
            self.sample()
            value = predicate()
            if value:
                return value
            if time.monotonic() > deadline:
                raise AssertionError(f"timed out after {timeout_s:.0f} s: {what}")
            time.sleep(0.25)

    def history(self) -> list[Any]:
        assert self.fleet.bus is not None
        reply = self.fleet.bus.query(
            self.fleet.keys.rpc("history"), GetHistory(limit=5000), HistoryReply, 5.0
        )
        return reply.events

    def truth(self, uav_id: str) -> Any:
        assert self.fleet.bus is not None
        state = self.fleet.bus.query(self.fleet.keys.sim("state"), GetSimState(), SimState, 5.0)
        return next(v for v in state.vehicles if v.uav_id == uav_id)

    def record(self, action_id: str) -> dict[str, Any]:
        return next(r for r in self.get("/v1/actions") or [] if r["action_id"] == action_id)

    def state(self, action_id: str) -> str:
        records = self.get("/v1/actions") or []
        return next((r["state"] for r in records if r["action_id"] == action_id), "")

    def plan(self, uav_id: str) -> dict[str, Any]:
        return next((p for p in self.get("/v1/plan") or [] if p["uav_id"] == uav_id), {})

    def status(self, uav_id: str) -> dict[str, Any]:
        fleet = self.get("/v1/fleet") or []
        uav = next((u for u in fleet if u["uav_id"] == uav_id), {})
        return uav.get("status") or {}

    def waypoints(self, uav_id: str, action_id: str) -> set[int]:
        return {
            w["index"]
            for t in self.plan(uav_id).get("tasks", [])
            if t["type"] == "inspect" and t["action_id"] == action_id
            for w in t["waypoints"]
        }

    def events(self, kind: EventKind, uav_id: str, after_seq: int = 0) -> list[Any]:
        return [
            e for e in self.history() if e.kind == kind and e.uav_id == uav_id and e.seq > after_seq
        ]

    def assert_clean(self) -> None:
        assert not self.checker.violations, self.checker.violations


@pytest.fixture
def fleet(netns, tmp_path):
    options = RunOptions(speedup=SPEEDUP, run_dir=tmp_path / "run", register=False)
    with NetnsRun(PAPER, options) as run:
        yield run


def test_partitions_shorter_and_longer_than_the_grace(fleet):
    watch = Watch(fleet)
    watch.submit(_inspect("inspect-long", 14, 8.0))
    victim = watch.until(
        "a UAV flying inspect-long",
        lambda: next(
            (
                u
                for u in UAVS
                if (watch.status(u).get("task_id") or "").startswith("inspect-long")
                and watch.status(u).get("progress", 0) > 0
            ),
            None,
        ),
    )
    last_seq = watch.history()[-1].seq

    # brief: 2 s < the agent's 3 s < the ground station's 5 s
    fleet.cut(f"agent-{victim}")
    time.sleep(2.0)  # hold the partition
    fleet.heal(f"agent-{victim}")
    watch.until(
        f"{victim} still on inspect-long after a brief cut",
        lambda: (
            (watch.status(victim).get("task_id") or "").startswith("inspect-long")
            and watch.status(victim).get("state") == "busy"
        ),
        20,
    )
    assert not watch.events(EventKind.UAV_LOST, victim, last_seq)
    assert watch.state("inspect-long") in {"planned", "in_progress"}

    # long: past both graces, held until the vehicle has landed
    epoch_before = watch.plan(victim)["epoch"]
    mine = watch.waypoints(victim, "inspect-long")
    assert mine, "the victim holds part of the inspection"
    last_seq = watch.history()[-1].seq
    fleet.cut(f"agent-{victim}")
    try:
        watch.until(
            f"{victim} lost", lambda: watch.events(EventKind.UAV_LOST, victim, last_seq), 20
        )

        def moved() -> bool:
            record = watch.record("inspect-long")
            left = mine - set(record["waypoints_done"])
            others = set().union(*(watch.waypoints(u, "inspect-long") for u in UAVS if u != victim))
            return record["state"] == "completed" or bool(left & others)

        watch.until("the victim's waypoints in another UAV's plan", moved, 20)
        watch.until(f"{victim} landed", lambda: watch.truth(victim).state == "landed", 40)
    finally:
        fleet.heal(f"agent-{victim}")
    watch.until(f"{victim} back", lambda: watch.events(EventKind.UAV_BACK, victim, last_seq), 20)
    watch.until(
        f"{victim}'s report of its abandoned tasks",
        lambda: any("failed" in e.detail for e in watch.events(EventKind.FAULT, victim, last_seq)),
        20,
    )
    watch.until(
        f"{victim} on a higher epoch",
        lambda: watch.status(victim).get("epoch", 0) > epoch_before,
        20,
    )
    watch.until("inspect-long completed", lambda: watch.state("inspect-long") == "completed", 90)
    watch.assert_clean()


def test_ground_station_kill_9_and_restart_loses_nothing(fleet):
    watch = Watch(fleet)
    ids = []
    for scripted in PAPER.actions:
        if scripted.id == "monitor-w2":
            continue  # seven minutes of monitoring add nothing here
        body = {**msgspec.to_builtins(scripted.action), "action_id": scripted.id}
        body["request_id"] = f"req-{scripted.id}"
        watch.submit(body)
        ids.append(scripted.id)
    watch.until(
        "work in progress",
        lambda: any(watch.state(i) in {"in_progress", "completed"} for i in ids),
        30,
    )
    print({i: watch.state(i) for i in ids})
    faults = ProcessFaults(fleet)
    faults.kill("ground-station")
    time.sleep(1.5)  # hold the outage
    faults.restart("ground-station")
    watch.until(
        "every accepted action listed again",
        lambda: {r["action_id"] for r in watch.get("/v1/actions") or []} >= set(ids),
        20,
    )
    watch.until(
        "mission complete",
        lambda: all(watch.state(i) == "completed" for i in ids),
        150,
    )
    watch.assert_clean()


def test_router_kill_and_return_everyone_recovers(fleet):
    watch = Watch(fleet)
    faults = ProcessFaults(fleet)
    faults.kill("router")
    time.sleep(2.0)  # hold the outage
    faults.restart("router")
    for uav in UAVS:
        watch.until(f"agent {uav} present", lambda u=uav: fleet.alive(Role.AGENT, u), 30)
    watch.until("ground station present", lambda: fleet.alive(Role.GROUND_STATION, "gs"), 30)
    watch.until("gateway answers", lambda: watch.get("/v1/fleet") is not None, 30)
    watch.until(
        "every UAV reported by the ground station",
        lambda: all(u["state"] != "lost" for u in watch.get("/v1/fleet") or [{"state": "lost"}]),
        30,
    )
    watch.submit(_inspect("after-router", 2, 3.0))
    watch.until(
        "the new action planned",
        lambda: (
            any(watch.waypoints(u, "after-router") for u in UAVS)
            or watch.state("after-router") == "completed"
        ),
        30,
    )
    watch.until("the new action completed", lambda: watch.state("after-router") == "completed", 60)
    watch.assert_clean()


# cuts an agent past both graces, the gs at the grace boundary and the gateway,
# and kills the router right after a new action's answer
CI_SEED = 44
LONG_SEEDS = (1, 2, 3)


def _chaos(tmp_path, capsys, seed: int, duration_s: float, drain_s: float) -> tuple[int, str]:
    """``linecrew chaos --netns`` on the chaos schedule alone: exit code and report."""
    args = ["--seed", str(seed), "--duration", f"{duration_s:g}", "--drain", f"{drain_s:g}"]
    args += ["--speedup", "10", "--no-scenario-actions", "--netns"]
    code = main([*args, "--run-dir", str(tmp_path / "run")])
    report = capsys.readouterr().out
    assert "partitions: real cuts" in report, report
    assert report.rstrip().endswith("--netns"), report
    return code, report


def test_a_short_netns_chaos_run_reports_zero_violations(netns, tmp_path, capsys):
    code, report = _chaos(tmp_path, capsys, CI_SEED, 35, 40)
    for cut in ("partition uav-2 for 9.3 s", "partition ground-station", "partition gateway"):
        assert "healed at" in report.split(cut)[1].splitlines()[0], report
    assert "router restarted" in report, report
    assert "violations: 0" in report, report
    assert f"reproduce: linecrew chaos --seed {CI_SEED} --duration 35" in report
    assert code == 0, report


@pytest.mark.chaos_long
@pytest.mark.parametrize("seed", LONG_SEEDS)
def test_long_netns_chaos_runs_report_zero_violations(netns, tmp_path, capsys, seed):
    code, report = _chaos(tmp_path, capsys, seed, 120, 150)
    print(report)
    assert "violations: 0" in report, report
    assert code == 0, report
