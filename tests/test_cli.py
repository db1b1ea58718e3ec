"""The ``linecrew`` console script dispatches to each package's command."""

from __future__ import annotations

import json
import subprocess
import sys

from linecrew.cli import main


def test_unknown_command_exits_2_with_usage(capsys):
    assert main(["fly-to-the-moon"]) == 2
    assert "unknown command" in capsys.readouterr().err


def test_help_lists_commands(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "router" in out and "bench bus" in out


def test_bench_bus_prints_real_numbers():
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "linecrew.cli",
            "bench",
            "bus",
            "--samples",
            "5",
            "--repeats",
            "1",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    results = json.loads(out)
    at_10hz = results["pub->sub at 10 Hz"]
    assert at_10hz["received"] == at_10hz["sent"] == 5
    assert 0 < at_10hz["p50_ms"] <= at_10hz["p99_ms"]
    queries = results["query round trip"]
    assert (queries["queries"], queries["failed"]) == (20, 0)  # measured after warm-up
    killed = results["liveliness after SIGKILL"]
    assert 0 < killed["mean_ms"] < killed["lease_ms"]
    frozen = results["liveliness after SIGSTOP"]
    assert frozen["mean_ms"] > 0.5 * frozen["lease_ms"]


def test_submit_inspect_takes_points_with_a_negative_first_coordinate(capsys, monkeypatch):
    from linecrew.client.commands import submit_main

    monkeypatch.setenv("LINECREW_URL", "http://127.0.0.1:9")  # nothing listens there
    # no gateway runs here: parsing must get past the points and fail on the connection
    code = submit_main(["inspect", "-5,15,3", "0,7,3,5"])
    err = capsys.readouterr().err
    assert "unrecognized arguments" not in err and "expected one argument" not in err
    assert code != 0
