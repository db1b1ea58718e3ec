"""CLI entry points, called as the ``linecrew`` console script will."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from linecrew.planner_tools.cli import bench_main, plan_main

EXAMPLE = Path(__file__).parents[3] / "ground_station" / "planner" / "examples" / "paper.yaml"


def test_plan_writes_a_valid_plan_and_validate_accepts_it(tmp_path: Path, capsys) -> None:
    out = tmp_path / "plan.json"
    assert plan_main([str(EXAMPLE), "-o", str(out), "--improve-ms", "50"]) == 0
    text = capsys.readouterr().out
    assert "makespan" in text and "uav1" in text
    doc = json.loads(out.read_text())
    assert {u["uav_id"] for u in doc["uavs"]} == {"uav1", "uav2", "uav3"}
    assert plan_main(["--validate", str(EXAMPLE), str(out)]) == 0
    assert "valid" in capsys.readouterr().out


def test_validate_reports_a_broken_plan(tmp_path: Path, capsys) -> None:
    out = tmp_path / "plan.json"
    assert plan_main([str(EXAMPLE), "-o", str(out), "--improve-ms", "0"]) == 0
    doc = json.loads(out.read_text())
    doc["uavs"][1]["steps"][0]["energy_after_wh"] = 1000.0
    out.write_text(json.dumps(doc))
    capsys.readouterr()
    assert plan_main(["--validate", str(EXAMPLE), str(out)]) == 1
    assert "energy_mismatch" in capsys.readouterr().out


def test_bad_problem_exits_2_naming_the_field(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(EXAMPLE.read_text().replace("home_station: H1", "home_station: H9"))
    assert plan_main([str(bad)]) == 2
    assert "$.uavs[0].home_station" in capsys.readouterr().err
    assert plan_main([str(tmp_path / "missing.yaml")]) == 2


def test_json_problem_is_accepted(tmp_path: Path) -> None:
    import yaml

    problem = tmp_path / "p.json"
    problem.write_text(json.dumps(yaml.safe_load(EXAMPLE.read_text())))
    assert plan_main([str(problem), "--improve-ms", "0"]) == 0


def test_bench_json(capsys) -> None:
    args = ["planner", "--sizes", "3x4", "--seeds", "0", "--improve-ms", "20", "--events", "5"]
    assert bench_main([*args, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    (row,) = doc["summary"]
    assert row["size"] == "3x4" and row["violations"] == 0


def test_bench_rejects_bad_sizes() -> None:
    with pytest.raises(SystemExit):
        bench_main(["planner", "--sizes", "many"])
