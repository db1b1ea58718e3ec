"""``linecrew bench ground-station`` runs end to end and reports sane numbers."""

from __future__ import annotations

import json
import subprocess
import sys


def test_ground_station_bench_reports_latency_and_loss_detection():
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "linecrew.cli",
            "bench",
            "ground-station",
            "--uavs",
            "3",
            "--events",
            "3",
            "--link-timeout",
            "1.0",
            "--steady-s",
            "3",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=180,
        check=True,
    ).stdout
    results = json.loads(out)
    assert results["agents"] == 3 and results["events"] >= 1
    assert 0 < results["event_to_plan_p50_ms"] <= results["event_to_plan_p99_ms"]
    assert 0 < results["epochs_per_submit"] <= 1.0  # one epoch per real trigger at most
    assert results["steady_epochs_per_uav_min"] == 0  # nothing happens: no new epoch
    # Loss is declared after the timeout (less one 0.2 s telemetry period), then a replan.
    assert results["lost_after_s"] >= 1.0 - 0.25
    assert results["replanned_after_s"] >= results["lost_after_s"]
