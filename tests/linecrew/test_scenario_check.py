"""``linecrew scenario check FILE`` validates without starting anything:
one summary line for a good file; for a bad one, lines naming the file, the
line and the field (real processes, real files)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import pytest

from linecrew_runtime import scenarios

PAPER_YAML = scenarios._HERE / "paper.yaml"
PAPER = PAPER_YAML.read_text()


def check(path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "linecrew.cli", "scenario", "check", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
        env=dict(os.environ),
    )


def line_of(text: str, needle: str, nth: int = 1) -> int:
    """The 1-based line of the ``nth`` occurrence of ``needle``."""
    lines = [i for i, line in enumerate(text.splitlines(), start=1) if needle in line]
    return lines[nth - 1]


def broken(tmp_path, text: str, name: str = "site.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_packaged_paper_scenario_is_valid_in_one_line():
    done = check(PAPER_YAML)
    assert done.returncode == 0, done.stderr
    [line] = done.stdout.splitlines()
    assert line.startswith(f"{PAPER_YAML}: valid scenario 'paper'")
    assert "3 towers" in line and "3 UAVs of 3 types" in line and "4 scripted actions" in line
    assert done.stderr == ""


def test_a_bad_value_names_file_line_and_field(tmp_path):
    text = PAPER.replace("battery_wh: 20.0", "battery_wh: -1", 1)
    path = broken(tmp_path, text)
    done = check(path)
    assert done.returncode == 1 and done.stdout == ""
    [line] = done.stderr.splitlines()
    expected = line_of(text, "battery_wh: -1")
    assert line.startswith(f"{path}:{expected}: $.fleet.types[0].battery_wh: "), line


def test_an_unknown_reference_names_its_line(tmp_path):
    text = PAPER.replace("type: safety, home_station", "type: blimp, home_station")
    done = check(broken(tmp_path, text))
    [line] = done.stderr.splitlines()
    assert f":{line_of(text, 'type: blimp')}: $.fleet.uavs[2].type: unknown type 'blimp'" in line


def test_a_yaml_syntax_error_gives_line_and_column(tmp_path):
    text = PAPER.replace("  towers:\n", "  towers: [\n", 1)
    path = broken(tmp_path, text)
    done = check(path)
    assert done.returncode == 1
    [line] = done.stderr.splitlines()
    match = re.match(rf"{re.escape(str(path))}:(\d+):(\d+): \$: YAML syntax: ", line)
    assert match, line
    assert int(match.group(1)) > line_of(text, "towers: [")  # where the parser gave up


def test_a_misspelt_field_is_not_silently_ignored(tmp_path):
    text = PAPER.replace("cruise_speed_mps: 2.0", "cruise_speed: 2.0", 1)
    done = check(broken(tmp_path, text))
    assert done.returncode == 1
    [line] = done.stderr.splitlines()
    assert (
        f":{line_of(text, 'cruise_speed: 2.0')}: $.fleet.types[0].cruise_speed: unknown field"
        in line
    )


def test_a_scripted_action_is_checked_as_the_ground_station_would(tmp_path):
    text = PAPER.replace("worker_id: W2, uavs: 1", "worker_id: W9, uavs: 1")
    done = check(broken(tmp_path, text))
    assert done.returncode == 1
    [line] = done.stderr.splitlines()
    assert f":{line_of(text, 'worker_id: W9')}: $.actions[2].action.worker_id: " in line
    assert "monitor-w2" in line and "W9" in line


@pytest.mark.parametrize("suffix", [".json"])
def test_json_scenarios_are_checked_too(tmp_path, suffix):
    import msgspec

    from linecrew_runtime.scenarios import load

    path = tmp_path / f"paper{suffix}"
    path.write_bytes(msgspec.json.encode(load("paper")))
    done = check(path)
    assert done.returncode == 0, done.stderr
    as_json = subprocess.run(
        [sys.executable, "-m", "linecrew.cli", "--json", "scenario", "check", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    result = json.loads(as_json.stdout)
    assert result["valid"] and result["summary"]["uavs"] == 3


def test_a_missing_file_is_named(tmp_path):
    done = check(tmp_path / "nope.yaml")
    assert done.returncode == 1
    assert (
        done.stderr.strip()
        == f"{tmp_path / 'nope.yaml'}: $: cannot read: No such file or directory"
    )
