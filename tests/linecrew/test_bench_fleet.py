"""``linecrew bench fleet`` on a tiny fleet: it runs the whole stack, measures
every process kind and prints a table of every metric (and JSON)."""

from __future__ import annotations

import json
import subprocess
import sys

from linecrew.bench.fleet import table

ROWS = [
    "agent processes",
    "start-up s",
    "cpu % router",
    "cpu % gs",
    "cpu % gateway",
    "cpu % sim",
    "cpu % agents",
    "rss MB agents",
    "agent cpu %/UAV",
    "agent rss MB/UAV",
    "false lost",
    "submit 5xx",
    "submit p99 ms",
    "event->plan p99 ms",
]


def test_bench_fleet_measures_a_tiny_fleet(tmp_path):
    flags = ["--uavs", "3", "--agents-per-process", "2", "--duration", "2", "--submits", "2"]
    command = [sys.executable, "-m", "linecrew.cli", "--json", "bench", "fleet", *flags]
    done = subprocess.run(
        [*command, "--run-dir", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    [result] = json.loads(done.stdout)
    assert result["uavs"] == 3 and result["agent_processes"] == 2  # a host of 2, a host of 1
    assert result["false_lost"] == 0 and result["submit_5xx"] == 0
    assert all(result["rss_mb"][kind] > 0 for kind in ("router", "gs", "gateway", "sim"))
    assert result["event_to_plan"]["n"] >= 1, result
    assert {p.name for p in (tmp_path / "uavs-3").iterdir()} >= {"agents-1.log", "agents-2.log"}
    lines = table([result]).splitlines()
    assert lines[0].split() == ["UAVs", "3"]
    names = [line.rsplit(None, 1)[0].strip() for line in lines[1:]]
    assert set(ROWS) <= set(names)
