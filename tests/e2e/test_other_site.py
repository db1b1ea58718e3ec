"""A scenario of one's own, with its own site id, runs end to end; a
process told another site id refuses to start and names both."""

from __future__ import annotations

import subprocess
import sys

import msgspec
import pytest

from linecrew.scenarios import ScenarioError, load

PAPER = load("paper")


def own_scenario(path) -> str:
    site = msgspec.structs.replace(PAPER.site, id="line-7")
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
