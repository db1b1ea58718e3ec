"""A UAV whose agent is frozen (SIGSTOP) for less than the ground station's
link timeout, every process real, x10: the gateway shows it silent since
the moment it stopped, its tasks unknown (not failed, not lost, nothing
replanned away), and one event says so; thawed, it is heard again, one
event says that, and its action is flown to the end."""

from __future__ import annotations

import time

import msgspec
import pytest

from ground_station.config import GsConfig
from ground_station.fleet_monitor import SILENT_AFTER_S
from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew_runtime.clock import time_of_day
from linecrew_runtime.scenarios import load
from proto import EventKind
from tests.e2e.truth import TruthLog
from tests.support.freeze import frozen
from tests.support.processes import wait_until

SPEEDUP = 10.0
PAPER = msgspec.structs.replace(load("paper"), actions=[])
LINK_TIMEOUT_S = GsConfig().link_timeout_s


@pytest.fixture
def truth(tmp_path):
    with LocalRun(PAPER, RunOptions(speedup=SPEEDUP, run_dir=tmp_path / "run")) as run:
        yield TruthLog(run)


def fleet(truth: TruthLog) -> dict[str, dict]:
    return {u["uav_id"]: u for u in truth.gateway.call("GET", "/v1/fleet")}


def test_a_uav_frozen_within_the_grace_is_silent_its_tasks_unknown_then_back(truth):
    body = {"type": "monitor", "worker_id": "W2", "uavs": 1, "duration_s": 120}
    watch = truth.submit(body)["action_id"]
    [victim] = truth.until("a UAV works on the watch", lambda: truth.working_on(watch), 60)
    seen = truth.events()[-1].seq
    frozen_at = time.time() * SPEEDUP  # the run's mission clock: every process reads it so

    with frozen(truth.run, f"agent-{victim}") as stopped:

        def silent() -> dict | None:
            assert time.monotonic() - stopped < LINK_TIMEOUT_S - 0.5, "not shown silent in time"
            uav = fleet(truth)[victim]
            return uav if uav["silent_since_s"] and uav["unknown_tasks"] else None

        wait_until(silent, LINK_TIMEOUT_S, "the victim shown silent", period_s=0.1)
        shown = fleet(truth)[victim]
        record = truth.action(watch)
    assert shown["state"] not in ("lost", "failed") and shown["silent_s"] >= SILENT_AFTER_S
    # its silence began when it was last heard: at most a status period before it froze
    assert frozen_at - 1.5 * SPEEDUP <= shown["silent_since_s"] <= frozen_at + 0.2 * SPEEDUP
    [plan] = [p for p in truth.gateway.call("GET", "/v1/plan") if p["uav_id"] == victim]
    watching = [t["task_id"] for t in plan["tasks"] if t.get("action_id") == watch]
    assert set(watching) <= set(shown["unknown_tasks"]) and watching
    assert record["state"] in ("planned", "in_progress")  # unknown, not failed

    def heard() -> bool:
        uav = fleet(truth)[victim]
        return uav["silent_s"] is None and not uav["unknown_tasks"]

    wait_until(heard, 15, "the victim heard again", period_s=0.2)
    told = [e for e in truth.events() if e.seq > seen and e.uav_id == victim]
    kinds = [e.kind for e in told if e.kind in (EventKind.UAV_SILENT, EventKind.UAV_HEARD)]
    assert kinds == [EventKind.UAV_SILENT, EventKind.UAV_HEARD]  # one of each, no storm
    [said] = [e for e in told if e.kind == EventKind.UAV_SILENT]
    assert f"silent since {time_of_day(shown['silent_since_s'])}" in said.detail
    assert EventKind.UAV_LOST not in [e.kind for e in told]
    truth.until("the watch ends", lambda: truth.finished(watch), 150)
    assert truth.action(watch)["state"] == "completed", truth.action(watch)
    assert not [e for e in truth.events() if e.kind == EventKind.ACTION_FAILED]
