"""``linecrew up``: everything starts healthy, the printed URL and token (and
the two export lines) work, the run is listed in the session file while it
is up, and stopping it (SIGTERM, or even SIGKILL) leaves no process behind."""

from __future__ import annotations

import json
import os
import pathlib
import re
import signal
import subprocess
import sys

import httpx
import pytest

from tests.support.processes import free_port, start, wait_until


def survivors(run_dir) -> list[str]:
    """Processes whose command line mentions the run directory."""
    out = subprocess.run(["pgrep", "-af", str(run_dir)], capture_output=True, text=True)
    return [line for line in out.stdout.splitlines() if "pgrep" not in line]


def children(pid: int) -> set[int]:
    """The processes whose parent is ``pid`` now (the router's command line
    does not name the run directory)."""
    found = set()
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        try:
            ppid = int(stat.read_text().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue  # gone meanwhile
        if ppid == pid:
            found.add(int(stat.parent.name))
    return found


def alive(pids: set[int]) -> set[int]:
    return {p for p in pids if pathlib.Path(f"/proc/{p}").exists()}


@pytest.fixture
def up(tmp_path, monkeypatch):
    monkeypatch.setenv("LINECREW_SESSION", str(tmp_path / "session.json"))
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
    proc = start(args, "up")
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
    assert url in text
    exports = dict(re.findall(r"^export (LINECREW_URL|LINECREW_TOKEN)=(\S+)$", text, re.M))
    assert exports == {"LINECREW_URL": url, "LINECREW_TOKEN": token}
    [listed] = json.loads((tmp_path / "session.json").read_text())["runs"]
    assert (listed["url"], listed["token"], listed["run_dir"]) == (url, token, str(run_dir))
    assert listed["speedup"] == 5
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
    assert json.loads((tmp_path / "session.json").read_text())["runs"] == []


def test_a_killed_up_takes_its_children_with_it(up):
    proc, run_dir, _ = up
    kids = children(proc.popen.pid)
    assert survivors(run_dir) and len(kids) >= 5  # router, gs, sim, gateway, agents
    os.kill(proc.popen.pid, signal.SIGKILL)
    try:
        wait_until(lambda: not survivors(run_dir), 30, "children gone after SIGKILL of up")
    except AssertionError as late:
        raise AssertionError(f"{late}; still running: {survivors(run_dir)}") from None
    wait_until(lambda: not alive(kids), 30, "the router gone too")
