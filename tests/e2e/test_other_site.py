"""A scenario of one's own, with its own site id and a station on a roof,
runs end to end; a process told another site id refuses to start and names
both."""

from __future__ import annotations

import subprocess
import sys

import msgspec
import pytest

from linecrew_runtime.scenarios import ScenarioError, load

PAPER = load("paper")


def raised(station, z_m: float):
    """``station`` on a roof ``z_m`` above the site's ground."""
    return msgspec.structs.replace(
        station, position=msgspec.structs.replace(station.position, z_m=z_m)
    )


def own_scenario(path) -> str:
    """The paper's world as site ``line-7``, with uav-1's home station C1 on
    a 6 m roof: the delivery takes off from it and lands back on it."""
    stations = [raised(s, 6.0) if s.id == "C1" else s for s in PAPER.site.stations]
    site = msgspec.structs.replace(PAPER.site, id="line-7", stations=stations)
    first = [a for a in PAPER.actions if a.id in {"deliver-wrench", "inspect-towers"}]
    scenario = msgspec.structs.replace(PAPER, name="line-7", site=site, actions=first)
    path.write_bytes(msgspec.json.encode(scenario))
    return str(path)


def test_linecrew_demo_runs_a_site_that_is_not_default(tmp_path):
    scenario = own_scenario(tmp_path / "line7.json")
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "linecrew.cli",
            "demo",
            "--scenario",
            scenario,
            "--speedup",
            "10",
            "--run-dir",
            str(tmp_path / "run"),
        ],
        capture_output=True,
        text=True,
        timeout=400,
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "every action completed" in done.stdout


def test_a_site_flag_that_disagrees_with_the_scenario_is_a_startup_error(tmp_path):
    scenario = own_scenario(tmp_path / "line7.json")
    with pytest.raises(ScenarioError, match=r"'default'.*'line-7'"):
        load(scenario, site="default")
    assert load(scenario, site="line-7").site.id == "line-7"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "ground_station",
            "--scenario",
            scenario,
            "--site",
            "default",
            "--connect",
            "tcp/127.0.0.1:1",
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 1
    assert "line-7" in done.stderr and "default" in done.stderr
