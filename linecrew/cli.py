"""The ``linecrew`` console script: one command, a subcommand per tool.

Each subcommand lives in the package that owns it and is imported only when
called, so ``linecrew router`` never loads the planner or FastAPI. ``--json``
may also come before the command (``linecrew --json status``). Output cut
short by its reader (``linecrew events | head``) ends the command quietly.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import re
import sys
from collections.abc import Iterator

# name -> ("module:function", help). The function takes argv and returns an exit code.
COMMANDS: dict[str, tuple[str, str]] = {
    "router": ("linecrew_runtime.bus.router:main", "run the ground site's Zenoh router"),
    "ground-station": ("ground_station.main:main", "run the mission manager and planner"),
    "sim": ("sim_fleet.main:main", "run the MAVLink fleet simulator and human tracker"),
    "agent": ("onboard_agent.main:main", "run one UAV's onboard agent (or: agent tree)"),
    "agents": ("onboard_agent.fleet_host:main", "simulation only: many UAVs' agents, one process"),
    "gateway": ("ground_station.gateway.main:main", "run the operator REST API"),
    "health": ("linecrew_runtime.health:main", "is a process's liveliness token up (healthchecks)"),
    "up": ("linecrew.launch.up:main", "run router, ground station, gateway, sim and agents"),
    "demo": ("linecrew.launch.demo:main", "the paper's scenario end to end"),
    "chaos": ("linecrew.chaos.main:main", "seeded partitions, kills, faults on a local fleet"),
    "submit": ("linecrew.client.commands:submit_main", "submit inspect / monitor / deliver"),
    "gesture": ("linecrew.client.commands:gesture_main", "submit a crew gesture"),
    "actions": ("linecrew.client.commands:actions_main", "list actions"),
    "cancel": ("linecrew.client.commands:cancel_main", "cancel an action"),
    "control": ("linecrew.client.commands:control_main", "hold / return / land / resume a UAV"),
    "status": ("linecrew.client.commands:status_main", "fleet table"),
    "plan": ("linecrew.client.commands:plan_main", "live plan timeline, or plan a PROBLEM file"),
    "events": ("linecrew.client.commands:events_main", "follow ground-station events"),
    "fault": ("linecrew.client.commands:fault_main", "inject a simulator fault (gateway)"),
    "scenario": ("linecrew.client.scenario_check:main", "scenario check FILE: validate a scenario"),
    "report": ("linecrew.report.cli:report_main", "write RUN_DIR/report.html of a finished run"),
    "export": ("linecrew.report.cli:export_main", "print a run's events and actions as JSON lines"),
}
BENCHES: dict[str, tuple[str, str]] = {
    "bus": ("linecrew.bench.bus:main", "Zenoh bus latency, throughput, liveliness"),
    "ground-station": (
        "linecrew.bench.ground_station:main",
        "event-to-plan latency, loss detection",
    ),
    "sim": ("linecrew.bench.sim:main", "simulator physics rate, telemetry rate, CPU"),
    "planner": ("linecrew.planner_tools.cli:bench_main", "planner speed and plan quality"),
    "live-plan": ("linecrew.bench.live_plan:main", "the live plan against the offline one"),
    "fleet": ("linecrew.bench.fleet:main", "start-up, CPU, RSS, latencies of N UAVs"),
}


def _usage() -> str:
    names = [*COMMANDS, *(f"bench {name}" for name in BENCHES)]
    helps = [h for _, h in COMMANDS.values()] + [h for _, h in BENCHES.values()]
    width = max(map(len, names)) + 2
    lines = ["usage: linecrew [--json] COMMAND [ARGS...]", "", "commands:"]
    lines += [f"  {name:<{width}}{help_}" for name, help_ in zip(names, helps, strict=True)]
    lines += ["", "Run 'linecrew COMMAND --help' for a command's options."]
    return "\n".join(lines)


SOURCE_MARKUP = (
    (re.compile(r"``([^`]+)``"), r"\1"),  # reStructuredText literals
    (re.compile(r":(?:class|mod|func|meth|attr|data):`~?(?:[\w.]+\.)?(\w+)`"), r"\1"),  # roles
    (re.compile(r"\[/?(?:bold|dim|italic|red|green|yellow|blue|cyan|magenta)?\]"), ""),  # rich
)


def plain(text: str) -> str:
    """``text`` without the markup of docstrings (reST) and of rich."""
    for pattern, replacement in SOURCE_MARKUP:
        text = pattern.sub(replacement, text)
    return text


@contextlib.contextmanager
def _plain_help() -> Iterator[None]:
    """Every command's ``--help`` as plain text: many describe themselves with
    their module docstring, written for the API docs."""
    original = argparse.ArgumentParser.format_help

    def format_help(self: argparse.ArgumentParser) -> str:
        return plain(original(self))

    argparse.ArgumentParser.format_help = format_help  # type: ignore[method-assign]
    try:
        yield
    finally:
        argparse.ArgumentParser.format_help = original  # type: ignore[method-assign]


def _run(target: str, argv: list[str]) -> int:
    module_name, function_name = target.split(":")
    function = getattr(importlib.import_module(module_name), function_name)
    helping = _plain_help() if {"-h", "--help"} & set(argv) else contextlib.nullcontext()
    try:
        with helping:
            return int(function(argv) or 0)
    except BrokenPipeError:
        # the reader went away (``| head``): nothing more to say, and no
        # traceback when Python flushes stdout at exit
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0


def main(argv: list[str] | None = None) -> int:
    """Dispatch ``linecrew COMMAND ...``; exit code 2 for an unknown command."""
    args = sys.argv[1:] if argv is None else argv
    at = _verb_index(args)
    if at and at < len(args):  # ``linecrew --json status``: give --json to the command
        verb = 2 if args[at] == "bench" else 1
        args = [*args[at : at + verb], "--json", *args[at + verb :]]
    if not args or args[0] in {"-h", "--help", "help"}:
        print(_usage())
        return 0 if args else 2
    name, rest = args[0], args[1:]
    if name == "bench":
        table, name, rest = BENCHES, (rest[0] if rest else ""), rest[1:]
    else:
        table = COMMANDS
    if name not in table:
        print(f"linecrew: unknown command {' '.join(args[:2])!r}\n\n{_usage()}", file=sys.stderr)
        return 2
    return _run(table[name][0], rest)


def _verb_index(args: list[str]) -> int:
    """Where the command name is (after any leading ``--json``)."""
    at = 0
    while at < len(args) and args[at] == "--json":
        at += 1
    return at


if __name__ == "__main__":
    sys.exit(main())
