"""The operator CLI against a live gateway: tables, JSON, clear errors."""

from __future__ import annotations

import json
import subprocess
import sys

from tests.ground_station.gateway.conftest import TOKEN


def linecrew(url: str, command: str, *args: str, token: str = TOKEN):
    """Run ``linecrew COMMAND --url URL --token TOKEN ARGS...``."""
    argv = [sys.executable, "-m", "linecrew.cli", command, "--url", url, f"--token={token}", *args]
    return subprocess.run(argv, capture_output=True, text=True, timeout=60)


def test_submit_list_cancel_round_trip(gateway_url):
    made = linecrew(
        gateway_url, "submit", "--json", "deliver", "wrench", "--from", "tp-wrench", "--to", "W1"
    )
    assert made.returncode == 0, made.stderr
    action_id = json.loads(made.stdout)["action_id"]
    listed = linecrew(gateway_url, "actions")
    assert listed.returncode == 0 and action_id in listed.stdout and "deliver" in listed.stdout
    inspect = linecrew(gateway_url, "submit", "--json", "inspect", "0,7,3,5", "7,7,3")
    assert json.loads(inspect.stdout)["action"]["waypoints"][0]["service_s"] == 5.0
    cancelled = linecrew(gateway_url, "cancel", action_id, "--json")
    assert json.loads(cancelled.stdout)["state"] == "cancelled"


def test_status_plan_and_gesture(gateway_url):
    status = linecrew(gateway_url, "status")
    assert status.returncode == 0 and "uav-1" in status.stdout and "lost" in status.stdout
    assert linecrew(gateway_url, "plan").returncode == 0
    gesture = linecrew(gateway_url, "gesture", "watch-me", "W2", "--json")
    assert json.loads(gesture.stdout)["action"]["worker_id"] == "W2"


def test_errors_are_one_clear_line_and_exit_1(gateway_url):
    bad = linecrew(gateway_url, "gesture", "moonwalk", "W1")
    assert bad.returncode == 1 and "unknown_gesture" in bad.stderr and "bring-wrench" in bad.stderr
    denied = linecrew(gateway_url, "actions", token="wrong")
    assert denied.returncode == 1 and "401" in denied.stderr
    gone = linecrew("http://127.0.0.1:9", "actions")
    assert gone.returncode == 1 and "cannot reach the gateway" in gone.stderr
