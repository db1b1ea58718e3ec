"""The operator CLI against a real local fleet (every process real, x10):
it finds the live run through the session file and says which, ignores dead
runs listed there, keeps --json output clean, prints the live plan's times
right on a sped-up mission clock, and ends quietly when its reader goes
away (``linecrew events | head``)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time

import msgspec
import pytest

from linecrew.client import session
from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew_runtime.scenarios import load
from tests.support.processes import wait_until

SPEEDUP = 10.0
PAPER = msgspec.structs.replace(load("paper"), actions=[])


@pytest.fixture(scope="module")
def run(tmp_path_factory, private_session_file):
    run_dir = tmp_path_factory.mktemp("cli-live") / "run"
    with LocalRun(PAPER, RunOptions(speedup=SPEEDUP, run_dir=run_dir)) as local:
        yield local


@pytest.fixture(scope="module")
def gateway(run):
    return run.gateway()


def cli(*args: str, env: dict | None = None, **kwargs) -> subprocess.CompletedProcess:
    """``linecrew ARGS`` as a real process (finding the run by itself)."""
    environment = {**os.environ, "COLUMNS": "200", **(env or {})}
    for name in ("LINECREW_URL", "LINECREW_TOKEN"):
        environment.pop(name, None)
    return subprocess.run(
        [sys.executable, "-m", "linecrew.cli", *args],
        capture_output=True,
        text=True,
        timeout=60,
        env=environment,
        **kwargs,
    )


def test_the_run_is_registered_in_the_tests_own_session_file(run, private_session_file):
    assert run.session_file == private_session_file
    listed = {r.url: r for r in session.read_runs(private_session_file)}
    assert listed[run.url].run_dir == str(run.run_dir.resolve())
    assert listed[run.url].speedup == SPEEDUP


def test_the_cli_finds_the_live_run_and_says_which_on_stderr_only(run):
    table = cli("status")
    assert table.returncode == 0, table.stderr
    assert all(u in table.stdout for u in ("uav-1", "uav-2", "uav-3"))
    [said] = table.stderr.splitlines()
    assert str(run.run_dir.resolve()) in said and run.url in said and "x10" in said
    as_json = cli("--json", "status")
    assert as_json.returncode == 0, as_json.stderr
    assert {u["uav_id"] for u in json.loads(as_json.stdout)} == {"uav-1", "uav-2", "uav-3"}
    assert run.url in as_json.stderr


def test_a_newer_dead_run_in_the_session_file_is_skipped(run, private_session_file):
    dead = session.RunEntry(url="http://127.0.0.1:9", token="x", started_s=time.time() + 60)
    session.register(dead, private_session_file)
    try:
        done = cli("actions", "--json")
        assert done.returncode == 0, done.stderr
        assert run.url in done.stderr and "127.0.0.1:9" not in done.stderr
    finally:
        session.unregister(dead.url, private_session_file)


def test_an_explicit_url_works_without_any_session_file(run, tmp_path):
    env = {"LINECREW_SESSION": str(tmp_path / "none.json")}
    done = cli("status", "--json", "--url", run.url, f"--token={run.token}", env=env)
    assert done.returncode == 0, done.stderr
    assert len(json.loads(done.stdout)) == 3 and done.stderr == ""
    nothing = cli("status", env=env)
    assert nothing.returncode == 1 and "no linecrew run found" in nothing.stderr


def test_plan_prints_mission_times_from_now_on_the_sped_up_clock(run, gateway):
    gateway.call(
        "POST",
        "/v1/actions",
        json={"type": "monitor", "worker_id": "W2", "uavs": 1, "duration_s": 200},
    )

    def monitor_planned() -> dict | None:
        for plan in gateway.call("GET", "/v1/plan"):
            for task in plan["tasks"]:
                if task["type"] == "monitor":
                    return task
        return None

    wait_until(monitor_planned, 30, "a monitor task in the plan", period_s=0.3)
    task = monitor_planned()
    assert task is not None
    done = cli("plan")
    now = time.time() * SPEEDUP
    assert done.returncode == 0, done.stderr
    title = re.search(r"Plan from now \(x10\): (\d+) s", done.stdout)
    assert title, done.stdout
    assert int(title.group(1)) < 2000  # not the UNIX epoch times 10 (about 1.8e10 s)
    row = next(line for line in done.stdout.splitlines() if task["task_id"] in line)
    start, end = (int(v) for v in re.findall(r"([+-]\d+) s", row)[:2])
    assert abs(end - (task["end_s"] - now)) < 30, (row, task["end_s"] - now)
    assert abs(start - (task["start_s"] - now)) < 30, (row, task["start_s"] - now)
    quality = gateway.call("GET", "/v1/plan/quality")
    assert quality["objective_s"] > 0
    assert re.search(r"plan objective \d+\.\d s", done.stdout), done.stdout


def test_events_into_head_ends_quietly(run, gateway):
    events = subprocess.Popen(
        [sys.executable, "-m", "linecrew.cli", "events", "--after", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={k: v for k, v in os.environ.items() if k != "LINECREW_URL"},
    )
    head = subprocess.run(["head", "-n", "2"], stdin=events.stdout, capture_output=True, text=True)
    events.stdout.close()
    assert len(head.stdout.splitlines()) == 2
    # the history may all fit in the pipe: new events make the next write fail
    body = {"type": "inspect", "waypoints": [{"position": {"x_m": 0, "y_m": 7, "z_m": 3}}]}
    gateway.call("POST", "/v1/actions", json=body)
    try:
        code = events.wait(30)
    finally:
        if events.poll() is None:
            events.kill()
    err = events.stderr.read().decode()
    events.stderr.close()
    assert code == 0, err
    assert "Traceback" not in err and "BrokenPipe" not in err, err
