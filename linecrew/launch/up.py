"""``linecrew up``: the whole fleet on this machine until Ctrl-C.

Starts router, ground station, gateway, simulator and one agent per UAV
(see :class:`LocalRun`), prints the URLs and the token, then streams the
ground station's events one line each. SIGINT/SIGTERM stops everything.
"""

from __future__ import annotations

import argparse
import pathlib
import shlex
import sys

from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew.launch.secure import SecureProfileError
from linecrew.launch.supervisor import StartError
from linecrew_runtime.logs import configure_logging
from linecrew_runtime.process import Shutdown
from linecrew_runtime.scenarios import ScenarioError, builtin_names, load, with_fleet_size
from proto.events import GsEvent
from proto.scenario import Scenario

HELP = """\
The whole fleet on this machine until Ctrl-C: router, ground station,
gateway, simulator and one agent per UAV. Prints the gateway URL, the token
(and the two export lines for curl), the run directory, then one line per
ground-station event. The CLI finds the run by itself while it is up (the
session file: $LINECREW_SESSION or .linecrew/session.json). Ctrl-C or
SIGTERM stops everything.
"""


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """Flags shared by ``up`` and ``demo``."""
    parser.add_argument(
        "--scenario", default="paper", help=f"scenario file or one of: {', '.join(builtin_names())}"
    )
    parser.add_argument("--uavs", type=int, help="resize the fleet to N UAVs")
    parser.add_argument("--speedup", type=float, default=1.0, help="mission seconds per second")
    parser.add_argument("--port", type=int, default=0, help="gateway port (default: free)")
    parser.add_argument(
        "--run-dir", type=pathlib.Path, help="logs, store and flight log (default runs/<UTC time>)"
    )
    parser.add_argument(
        "--secure",
        action="store_true",
        help="mutual TLS and access control on the bus (dev certificates in the run directory)",
    )
    parser.add_argument(
        "--agents-per-process",
        type=_at_least_one,
        default=1,
        metavar="N",
        help="host the simulated UAVs' agents N to a process (default 1: one process per UAV)",
    )
    parser.add_argument(
        "--log-level", default="warning", help="of every process: debug, info, warning, error"
    )


def _at_least_one(text: str) -> int:
    number = int(text)
    if number < 1:
        raise argparse.ArgumentTypeError("must be at least 1")
    return number


def scenario_from(args: argparse.Namespace) -> Scenario:
    """The scenario the flags ask for."""
    scenario = load(args.scenario)
    if args.uavs and args.uavs != len(scenario.fleet.uavs):
        scenario = with_fleet_size(scenario, args.uavs)
    return scenario


def options_from(args: argparse.Namespace) -> RunOptions:
    """Run options from the flags; a secure run keeps one agent process per
    UAV (each its own bus identity)."""
    if args.secure and args.agents_per_process > 1:
        raise SecureProfileError("--secure runs one agent process per UAV")
    return RunOptions(
        speedup=args.speedup,
        gateway_port=args.port,
        run_dir=args.run_dir,
        secure=args.secure,
        agents_per_process=args.agents_per_process,
    )


def export_lines(url: str, token: str) -> str:
    """The shell lines that let ``curl`` (and the CLI) reach this gateway."""
    return f"export LINECREW_URL={shlex.quote(url)}\nexport LINECREW_TOKEN={shlex.quote(token)}"


def event_line(event: GsEvent) -> str:
    """One compact line per ground-station event."""
    who = event.uav_id or event.action_id or ""
    epoch = f" e{event.epoch}" if event.epoch is not None else ""
    return f"{event.seq:>5} {event.kind:<15} {who:<16}{epoch} {event.detail}"


def main(argv: list[str] | None = None) -> int:
    """Run until SIGINT/SIGTERM or until a process dies (exit 1)."""
    parser = argparse.ArgumentParser(
        prog="linecrew up",
        description=HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_run_arguments(parser)
    args = parser.parse_args(argv)
    configure_logging(args.log_level, "plain", "up")
    shutdown = Shutdown().install()
    try:
        scenario = scenario_from(args)
        with LocalRun(scenario, options_from(args)) as run:
            print(
                f"linecrew is up: {len(scenario.fleet.uavs)} UAVs, scenario {scenario.name}, "
                f"x{args.speedup:g}\n"
                f"  gateway   {run.url}   (API docs {run.url}/docs)\n"
                f"  token     {run.token}\n"
                f"  zenoh     {run.endpoint}\n"
                f"  logs      {run.run_dir}/\n"
                f"  try       linecrew status   (the CLI finds this run by itself)\n"
                f"for curl (and the CLI from anywhere):\n"
                f"{export_lines(run.url, run.token)}\n"
                f"Ctrl-C stops everything.",
                flush=True,
            )
            assert run.bus is not None
            run.bus.subscribe(
                run.keys.events(), GsEvent, lambda _k, e: print(event_line(e), flush=True)
            )
            while not shutdown.wait(0.5):
                if dead := run.supervisor.dead():
                    for child in dead:
                        print(
                            f"{child.name} exited ({child.popen.returncode}); "
                            f"log {child.log_path}:\n{child.tail()}",
                            file=sys.stderr,
                        )
                    return 1
            print("stopping...", flush=True)
    except (ScenarioError, StartError, SecureProfileError) as exc:
        print(f"linecrew up: {exc}", file=sys.stderr)
        return 1
    return 0
