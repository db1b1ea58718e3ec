"""``linecrew demo`` ends with a run report; ``linecrew report RUN_DIR`` and
``linecrew export RUN_DIR --format jsonl`` read a finished run. A short
real demo (every process real, x10: a delivery and a two-point inspection)
is run once for the module."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import msgspec
import pytest

from linecrew.report.data import load_run
from linecrew_runtime.scenarios import load
from proto import InspectAction, Point, WaypointSpec
from proto.scenario import ScriptedAction

PAPER = load("paper")
UAVS = [u.id for u in PAPER.fleet.uavs]
SHORT = msgspec.structs.replace(
    PAPER,
    name="short",
    actions=[
        next(a for a in PAPER.actions if a.id == "deliver-wrench"),
        ScriptedAction(
            id="inspect-two",
            action=InspectAction(
                waypoints=[
                    WaypointSpec(position=Point(x_m=0, y_m=7, z_m=3), service_s=2),
                    WaypointSpec(position=Point(x_m=7, y_m=7, z_m=3), service_s=2),
                ]
            ),
        ),
    ],
)
SECTIONS = ("map", "timeline", "batteries", "actions")


def linecrew(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "linecrew.cli", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "COLUMNS": "120"},
    )


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """``linecrew demo`` of the short scenario; (its result, the run directory)."""
    where = tmp_path_factory.mktemp("report")
    scenario = where / "short.json"
    scenario.write_bytes(msgspec.json.encode(SHORT))
    run_dir = where / "run"
    done = linecrew(
        "demo", "--scenario", str(scenario), "--run-dir", str(run_dir), "--timeout", "240",
        timeout=400,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return done, run_dir


def sections(page: str) -> dict[str, str]:
    return dict(re.findall(r'<section id="([a-z]+)">(.*?)</section>', page, re.S))


def test_the_demo_writes_the_report_and_prints_its_path_last(demo):
    done, run_dir = demo
    last = done.stdout.strip().splitlines()[-1]
    assert last == f"report: {run_dir / 'report.html'}"
    assert (run_dir / "report.html").is_file()


def test_the_report_is_self_contained_with_an_svg_per_section_and_every_uav(demo):
    _, run_dir = demo
    again = linecrew("report", str(run_dir))
    assert again.returncode == 0, again.stderr
    assert again.stdout.strip() == str(run_dir / "report.html")
    page = (run_dir / "report.html").read_text()
    parts = sections(page)
    assert list(parts) == list(SECTIONS)
    for name, body in parts.items():
        assert "<svg" in body, f"no SVG in section {name}"
    for uav in UAVS:
        assert uav in parts["map"] and uav in parts["timeline"] and uav in parts["batteries"]
    # nothing fetched from anywhere: no script, link, image or URL but the SVG namespace
    assert not re.search(r"<script|<link|<img|src=|href=|url\(", page)
    assert set(re.findall(r"https?://[^\s\"'<]+", page)) == {"http://www.w3.org/2000/svg"}
    # the actions table: both actions, completed, with their times
    for action_id in ("deliver-wrench", "inspect-two"):
        row = re.search(rf"<tr><td>{action_id}</td>.*?</tr>", parts["actions"], re.S)
        assert row and "completed" in row.group(0), action_id


def test_the_report_draws_what_was_flown_and_what_was_planned(demo):
    _, run_dir = demo
    run = load_run(run_dir)
    tracks = run.tracks()
    flown = [s for s in run.executed() if s.action_id == "deliver-wrench"]
    assert {s.kind for s in flown} >= {"pick", "deliver"}, flown
    deliverer = flown[0].uav_id
    assert len(tracks[deliverer]) > 10  # it flew to the tool, then to the worker
    xs = [x for _, x, _ in tracks[deliverer]]
    assert max(xs) - min(xs) > 5
    assert all(s.result == "completed" for s in flown if s.kind == "deliver")
    epoch, planned, held = run.first_plan()
    assert epoch >= 1 and held == 2 and {s.action_id for s in planned} >= {"deliver-wrench"}
    page = (run_dir / "report.html").read_text()
    timeline = sections(page)["timeline"]
    assert "executed" in timeline and f"first plan (epoch {epoch}" in timeline
    assert "deliver-wrench.pick" in timeline or "deliver-wrench" in timeline
    batteries = [f for _, f in run.batteries()[deliverer]]
    assert min(batteries) < max(batteries) <= 1.0  # it used some battery


def test_export_prints_json_lines_with_the_completed_actions(demo):
    _, run_dir = demo
    done = linecrew("export", str(run_dir), "--format", "jsonl")
    assert done.returncode == 0, done.stderr
    lines = [json.loads(line) for line in done.stdout.splitlines()]
    actions = {r["action_id"]: r for r in lines if r["record"] == "action"}
    assert actions["deliver-wrench"]["state"] == "completed"
    assert actions["deliver-wrench"]["action"]["type"] == "deliver"
    assert [t["to"] for t in actions["deliver-wrench"]["transitions"]][-1] == "completed"
    events = [r for r in lines if r["record"] == "event"]
    assert events and [e["seq"] for e in events] == sorted(e["seq"] for e in events)
    assert any(e["kind"] == "action_state" and e["action_id"] == "inspect-two" for e in events)
    outcomes = [r for r in lines if r["record"] == "outcome"]
    assert any(o["task_id"].startswith("deliver-wrench") for o in outcomes)


def test_report_and_export_of_a_directory_that_is_no_run_say_so(tmp_path):
    for verb in ("report", "export"):
        done = linecrew(verb, str(tmp_path))
        assert done.returncode == 1
        [line] = done.stderr.splitlines()
        assert "is not a run directory" in line and str(tmp_path) in line
