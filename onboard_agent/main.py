"""``python -m onboard_agent`` / ``linecrew agent``: run the agent of one UAV,
or print its tree (``tree --format xml|ascii``).

    python -m onboard_agent --uav uav-1 --autopilot udpout:127.0.0.1:14560 \\
        --scenario paper --connect tcp/127.0.0.1:7447
    python -m onboard_agent tree --format xml > main_tree.xml   # open in Groot2
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys

from linecrew_runtime import scenarios
from linecrew_runtime.mavlink_keys import load_key
from linecrew_runtime.process import Shutdown, common_parser, start
from onboard_agent import export
from onboard_agent.config import AgentConfig
from onboard_agent.runtime import run_agent
from proto.errors import LinecrewError
from proto.scenario import Scenario

log = logging.getLogger(__name__)


def add_flight_arguments(p: argparse.ArgumentParser) -> None:
    """The flags of every agent, also of a :mod:`onboard_agent.fleet_host`."""
    p.add_argument(
        "--autopilot-system",
        type=int,
        help="the autopilot's MAVLink system id (default: the first autopilot heard)",
    )
    p.add_argument("--scenario", default="paper", help="scenario name or YAML/JSON file")
    p.add_argument("--tick-hz", type=float, help="behaviour-tree ticks per second (10)")
    p.add_argument("--link-timeout", type=float, help="agent_link_timeout_s (3.0)")


def settings(args: argparse.Namespace) -> tuple[AgentConfig, Scenario]:
    """The agent's configuration and scenario from the flags; raises
    ``ValueError`` or :class:`LinecrewError`."""
    config = AgentConfig.from_env(
        tick_hz=args.tick_hz,
        agent_link_timeout_s=args.link_timeout,
        autopilot_system=args.autopilot_system,
    )
    return config, scenarios.load(args.scenario, site=args.site)


def parser() -> argparse.ArgumentParser:
    """The flags of the agent process."""
    p = common_parser("linecrew agent", "Onboard agent: fly one UAV's plan.")
    p.add_argument("--uav", required=True, help="UAV id (as in the scenario's fleet)")
    p.add_argument(
        "--autopilot",
        required=True,
        help="pymavlink connection string, e.g. udpout:127.0.0.1:14560, tcp:host:5760",
    )
    p.add_argument(
        "--mavlink-key",
        metavar="FILE",
        help="sign the MAVLink link with this key file's passphrase and accept only "
        "packets signed with it (the autopilot must hold the same key)",
    )
    add_flight_arguments(p)
    return p


def tree_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="linecrew agent tree", description="Print the tree.")
    p.add_argument("--format", choices=export.FORMATS, default="xml")
    return p


def tree_command(argv: list[str]) -> int:
    """Print the Main Tree as BehaviorTree.CPP v4 XML or ASCII."""
    args = tree_parser().parse_args(argv)
    sys.stdout.write(export.render(export.exportable_tree(), args.format))
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["tree"]:
        return tree_command(argv[1:])
    args = parser().parse_args(argv)
    bus_config = start(args, "agent")
    try:
        config, scenario = settings(args)
        signing_key = load_key(args.mavlink_key) if args.mavlink_key else None
    except (ValueError, LinecrewError) as exc:
        log.error("cannot start: %s", exc)
        return 2
    shutdown = Shutdown().install()
    stop = shutdown.wait_async()
    try:
        asyncio.run(
            run_agent(
                args.uav,
                scenario,
                args.autopilot,
                bus_config,
                config,
                stop,
                scenario.site.id,
                args.speedup,
                signing_key,
            )
        )
    except LinecrewError as exc:
        log.error("agent failed: %s", exc)
        return 1
    log.info("stopped on %s", shutdown.signal_name or "request")
    return 0
