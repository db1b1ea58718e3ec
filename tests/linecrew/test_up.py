"""``linecrew up``: everything starts healthy, the printed URL and token work,
and stopping it (SIGTERM, or even SIGKILL) leaves no process behind."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys

import httpx
import pytest

from tests.support.processes import Process, free_port, wait_until


def survivors(run_dir) -> list[str]:
    """Processes whose command line mentions the run directory."""
    out = subprocess.run(["pgrep", "-af", str(run_dir)], capture_output=True, text=True)
    return [line for line in out.stdout.splitlines() if "pgrep" not in line]


@pytest.fixture
def up(tmp_path):
    run_dir = tmp_path / "run"
    port = free_port()
    args = [
        sys.executable,
        "-m",
        "linecrew.cli",
        "up",
        "--speedup",
        "5",
        "--port",
        str(port),
        "--run-dir",
        str(run_dir),
    ]
    cwd = os.getcwd()
    os.chdir(tmp_path)  # the session file goes to ./.linecrew
    try:
        proc = Process(args, "up")
    finally:
        os.chdir(cwd)
    try:
        wait_until(
            lambda: "linecrew is up" in proc.output() or proc.popen.poll() is not None,
            120,
            "linecrew up ready",
        )
        assert proc.popen.poll() is None, proc.output()
        yield proc, run_dir, port
    finally:
        proc.kill()
        wait_until(lambda: not survivors(run_dir), 20, "no processes left")


def test_up_prints_a_working_url_and_token_and_stops_cleanly(up, tmp_path):
    proc, run_dir, port = up
    text = proc.output()
    token = re.search(r"token\s+(\S+)", text).group(1)
    url = f"http://127.0.0.1:{port}"
    assert url in text and (tmp_path / ".linecrew" / "session.json").is_file()
    headers = {"Authorization": f"Bearer {token}"}

    def fleet_ready() -> bool:
        uavs = httpx.get(f"{url}/v1/fleet", headers=headers, timeout=5).json()
        return len(uavs) == 3 and all(u["state"] != "lost" for u in uavs)

    wait_until(fleet_ready, 60, "every agent present")
    assert httpx.get(f"{url}/v1/fleet", timeout=5).status_code == 401
    assert {p.name for p in run_dir.iterdir()} >= {
        "router.log",
        "ground-station.log",
        "gateway.log",
        "sim.log",
        "agent-uav-1.log",
        "gs.db",
    }
    os.killpg(proc.popen.pid, signal.SIGTERM)
    assert proc.popen.wait(60) == 0, proc.output()
    assert not survivors(run_dir)


def test_a_killed_up_takes_its_children_with_it(up):
    proc, run_dir, _ = up
    assert survivors(run_dir)
    os.kill(proc.popen.pid, signal.SIGKILL)
    wait_until(lambda: not survivors(run_dir), 30, "children gone after SIGKILL of up")
