"""The ``linecrew`` console script: one command, a subcommand per tool.

Each subcommand lives in the package that owns it and is imported only when
called, so ``linecrew router`` never loads the planner or FastAPI.
"""

from __future__ import annotations

import importlib
import sys

# name -> ("module:function", help). The function takes argv and returns an exit code.
COMMANDS: dict[str, tuple[str, str]] = {
    "router": ("ground_station.router:main", "run the ground site's Zenoh router"),
    "ground-station": ("ground_station.main:main", "run the mission manager and planner"),
    "sim": ("sim_fleet.main:main", "run the MAVLink fleet simulator and human tracker"),
    "agent": ("onboard_agent.main:main", "run one UAV's onboard agent (or: agent tree)"),
    "gateway": ("ground_station.gateway.main:main", "run the operator REST API"),
    "health": ("linecrew.health:main", "is a process's liveliness token up (healthchecks)"),
    "up": ("linecrew.launch.up:main", "run router, ground station, gateway, sim and agents"),
    "demo": ("linecrew.launch.demo:main", "the paper's scenario end to end"),
    "chaos": ("linecrew.chaos.main:main", "seeded partitions, kills, faults on a local fleet"),
    "submit": ("linecrew.client.commands:submit_main", "submit inspect / monitor / deliver"),
    "gesture": ("linecrew.client.commands:gesture_main", "submit a crew gesture"),
    "actions": ("linecrew.client.commands:actions_main", "list actions"),
    "cancel": ("linecrew.client.commands:cancel_main", "cancel an action"),
    "status": ("linecrew.client.commands:status_main", "fleet table"),
    "plan": ("linecrew.client.commands:plan_main", "live plan timeline, or plan a PROBLEM file"),
    "events": ("linecrew.client.commands:events_main", "follow ground-station events"),
    "fault": ("linecrew.client.commands:fault_main", "inject a simulator fault (gateway)"),
}
BENCHES: dict[str, tuple[str, str]] = {
    "bus": ("linecrew.bus.bench:main", "Zenoh bus latency, throughput, liveliness"),
    "ground-station": ("ground_station.bench:main", "event-to-plan latency, loss detection"),
    "sim": ("sim_fleet.bench:main", "simulator physics rate, telemetry rate, CPU"),
    "planner": ("ground_station.planner.cli:bench_main", "planner speed and plan quality"),
}


def _usage() -> str:
    lines = ["usage: linecrew COMMAND [ARGS...]", "", "commands:"]
    lines += [f"  {name:<16}{help_}" for name, (_, help_) in COMMANDS.items()]
    lines += [f"  bench {name:<10}{help_}" for name, (_, help_) in BENCHES.items()]
    lines += ["", "Run 'linecrew COMMAND --help' for a command's options."]
    return "\n".join(lines)


def _run(target: str, argv: list[str]) -> int:
    module_name, function_name = target.split(":")
    function = getattr(importlib.import_module(module_name), function_name)
    return int(function(argv) or 0)


def main(argv: list[str] | None = None) -> int:
    """Dispatch ``linecrew COMMAND ...``; exit code 2 for an unknown command."""
    args = sys.argv[1:] if argv is None else argv
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


if __name__ == "__main__":
    sys.exit(main())
