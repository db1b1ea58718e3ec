"""The ``linecrew`` console script dispatches to each package's command."""

from __future__ import annotations

import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile

import pytest

from linecrew.cli import BENCHES, COMMANDS, main


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


# -- --json anywhere, help texts ------------------------------------------------------

PAPER_YAML = pathlib.Path(__file__).parents[1] / "linecrew_runtime" / "scenarios" / "paper.yaml"


def cli(*args: str, env: dict | None = None, cwd=None) -> subprocess.CompletedProcess:
    """``linecrew ARGS`` as a real process."""
    return subprocess.run(
        [sys.executable, "-m", "linecrew.cli", *args],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, **(env or {})},
        cwd=cwd,
    )


@pytest.mark.parametrize(
    "args",
    [
        ("--json", "scenario", "check", str(PAPER_YAML)),
        ("scenario", "--json", "check", str(PAPER_YAML)),
        ("scenario", "check", str(PAPER_YAML), "--json"),
    ],
)
def test_json_is_accepted_before_or_after_the_verb(args):
    done = cli(*args)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["valid"] is True


def test_json_after_a_sub_command_reaches_the_command(capsys):
    # no gateway listens on port 9: parsing must succeed and the call fail
    deliver = ["deliver", "wrench", "--from", "tp-wrench", "--to", "W1"]
    code = main(["submit", *deliver, "--json", "--url", "http://127.0.0.1:9"])
    err = capsys.readouterr().err
    assert code == 1 and "unrecognized arguments" not in err
    assert "cannot reach the gateway at http://127.0.0.1:9" in err


def test_hoisting_leaves_points_and_the_separator_alone():
    from linecrew.client.commands import hoist_globals

    argv = ["inspect", "1,2,3", "--json", "--url", "http://x", "--", "--json"]
    assert hoist_globals(argv) == [
        "--json",
        "--url",
        "http://x",
        "inspect",
        "1,2,3",
        "--",
        "--json",
    ]


MARKUP = re.compile(r"\[/?(bold|red|green|dim|italic|yellow|blue)?\]|``|:(class|mod|func|meth):`")
VERBS = [[v] for v in COMMANDS] + [["bench", b] for b in BENCHES]
VERBS += [["scenario", "check"], ["agent", "tree"], ["sim", "fault"]]


@pytest.mark.parametrize("verb", VERBS, ids=" ".join)
def test_every_verbs_help_renders_without_markup(verb, capsys):
    with pytest.raises(SystemExit) as done:
        main([*verb, "--help"])
    out = capsys.readouterr().out
    assert done.value.code == 0 and out.strip()
    assert not MARKUP.search(out), MARKUP.search(out).group(0)


def test_top_level_help_keeps_names_and_helps_apart(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert not MARKUP.search(out)
    for line in out.splitlines():
        if line.startswith("  "):
            assert re.match(r"  \S+( \S+)?  +\S", line), line  # two spaces at least


# -- which gateway ------------------------------------------------------------------


def test_outside_the_repo_without_a_run_the_cli_says_so_in_one_line(tmp_path):
    env = {"LINECREW_SESSION": "", "LINECREW_URL": "", "LINECREW_TOKEN": ""}
    done = cli("status", env=env, cwd=tmp_path)  # no .linecrew here nor above
    assert done.returncode == 1 and done.stdout == ""
    [line] = done.stderr.splitlines()
    assert "no linecrew run found" in line and str(tmp_path) in line and "--url" in line
    assert "8080" not in line


def test_a_session_file_of_dead_runs_is_an_error_not_a_guess(tmp_path):
    from linecrew.client import session

    path = tmp_path / "session.json"
    session.register(session.RunEntry(url="http://127.0.0.1:9", token="t", run_dir="/gone"), path)
    done = cli("actions", env={"LINECREW_SESSION": str(path), "LINECREW_URL": ""})
    assert done.returncode == 1
    [line] = done.stderr.splitlines()
    assert "no linecrew run is up" in line and str(path) in line


def test_the_session_file_keeps_runs_apart_and_forgets_dead_processes(tmp_path):
    from linecrew.client import session

    path = tmp_path / "s.json"
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    session.register(session.RunEntry(url="http://a", pid=int(dead.stdout)), path)
    session.register(session.RunEntry(url="http://b", pid=os.getpid()), path)
    session.register(session.RunEntry(url="http://c", pid=os.getpid()), path)
    assert [r.url for r in session.read_runs(path)] == ["http://b", "http://c"]
    session.unregister("http://b", path)
    assert [r.url for r in session.read_runs(path)] == ["http://c"]
    assert oct(path.stat().st_mode & 0o777) == "0o600"  # it holds tokens
    path.write_text(json.dumps({"url": "http://old", "token": "x"}))  # the old format
    assert session.read_runs(path) == [session.RunEntry(url="http://old", token="x")]


def test_tests_never_write_the_users_session_file(private_session_file):
    from linecrew.client.session import session_path

    assert session_path() == private_session_file
    assert str(private_session_file).startswith(tempfile.gettempdir())


# -- linecrew plan FILE -------------------------------------------------------------


def test_plan_takes_a_scenario_file_and_plans_it_from_its_start():
    done = cli("plan", str(PAPER_YAML), "--improve-ms", "0", env={"COLUMNS": "120"})
    assert done.returncode == 0, done.stderr
    assert "a scenario, planned from its start" in done.stderr
    assert all(u in done.stdout for u in ("uav-1", "uav-2", "uav-3"))
    assert "unplaced parts" in done.stdout


def test_plan_of_a_file_of_neither_format_names_both_and_their_examples(tmp_path):
    odd = tmp_path / "odd.yaml"
    odd.write_text("hello: world\n")
    done = cli("plan", str(odd))
    assert done.returncode == 2
    [line] = done.stderr.splitlines()
    assert "planning problem" in line and "scenario" in line
    assert "ground_station/planner/examples/paper.yaml" in line
    assert "linecrew_runtime/scenarios/paper.yaml" in line
