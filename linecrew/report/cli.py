"""``linecrew report RUN_DIR`` and ``linecrew export RUN_DIR --format jsonl``."""

from __future__ import annotations

import argparse
import pathlib
import sys

from linecrew.report.data import RunDirError, load_run
from linecrew.report.export import jsonl
from linecrew.report.html import write_report

RUN_DIR_HELP = "a run directory of linecrew up / demo (runs/<UTC time>, or its --run-dir)"


def report_main(argv: list[str]) -> int:
    """Write the HTML report of a finished run; print its path."""
    parser = argparse.ArgumentParser(
        prog="linecrew report",
        description="Write RUN_DIR/report.html: one self-contained page (inline SVG) with "
        "the site map and every UAV's flown track, the executed timeline next to the "
        "first plan, battery curves and a table of actions with outcomes, reasons and times.",
    )
    parser.add_argument("run_dir", type=pathlib.Path, help=RUN_DIR_HELP)
    parser.add_argument("-o", "--output", type=pathlib.Path, help="elsewhere than RUN_DIR")
    args = parser.parse_args(argv)
    try:
        path = write_report(args.run_dir, args.output)
    except (RunDirError, OSError) as exc:
        print(f"linecrew report: {exc}", file=sys.stderr)
        return 1
    print(path)
    return 0


def export_main(argv: list[str]) -> int:
    """Print a run's actions, events and outcomes as JSON lines."""
    parser = argparse.ArgumentParser(
        prog="linecrew export",
        description="Print a run's actions (with their transitions), ground-station events "
        "and task outcomes as JSON lines, one object each, its kind in the field 'record'.",
    )
    parser.add_argument("run_dir", type=pathlib.Path, help=RUN_DIR_HELP)
    parser.add_argument("--format", choices=("jsonl",), default="jsonl", help="only jsonl")
    parser.add_argument("--json", action="store_true", help=argparse.SUPPRESS)  # it is JSON
    args = parser.parse_args(argv)
    try:
        run = load_run(args.run_dir)
    except (RunDirError, OSError) as exc:
        print(f"linecrew export: {exc}", file=sys.stderr)
        return 1
    for line in jsonl(run):
        sys.stdout.write(line + "\n")
    sys.stdout.flush()
    return 0
