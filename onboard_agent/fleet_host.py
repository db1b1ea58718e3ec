"""``linecrew agents`` / ``python -m onboard_agent.fleet_host``: the agents of
many simulated UAVs in one process. SIMULATION ONLY: a real UAV runs its own
agent process (``linecrew agent``) on its own computer.

    python -m onboard_agent.fleet_host --uavs uav-1,uav-2,uav-3 \\
        --autopilot-base-port 14560 --scenario paper --connect tcp/127.0.0.1:7447

Each agent is what ``linecrew agent`` runs (:func:`run_agent`): its own Zenoh
session and liveliness token (the ground station sees every UAV on its own),
its own MAVLink link (the i-th UAV's autopilot on UDP port ``P + i``) and
its own behaviour tree, all on one asyncio loop, sharing the interpreter,
the imported modules and Zenoh's runtime threads. An agent that fails is
logged and the others fly on; SIGINT/SIGTERM stops them all. The exit code
is 1 if any agent failed, 2 for bad flags.

A host runs at a lower CPU priority (``HOST_NICE``): on a real fleet every
agent has a computer of its own; here a hundred share the ground station's
machine, and must not make the operator wait (``linecrew bench fleet``).
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import contextvars
import logging
import os
import sys
from collections.abc import Awaitable, Callable

from linecrew_runtime.bus import BusConfig
from linecrew_runtime.process import Shutdown, common_parser, start
from onboard_agent.agent import UnknownUav
from onboard_agent.config import AgentConfig
from onboard_agent.main import add_flight_arguments, settings
from onboard_agent.runtime import run_agent
from proto.errors import LinecrewError
from proto.scenario import Scenario

log = logging.getLogger(__name__)

HOST_NICE = 5
"""How much lower than the ground processes a host of simulated agents runs."""
_current_uav: contextvars.ContextVar[str] = contextvars.ContextVar("uav_id", default="")


class _UavTag(logging.Filter):
    """Names the UAV whose agent logged a record (unless the record does)."""

    def filter(self, record: logging.LogRecord) -> bool:
        uav_id = _current_uav.get()
        if uav_id and not hasattr(record, "uav_id"):
            record.uav_id = uav_id
        return True


def parser() -> argparse.ArgumentParser:
    """The flags of the multi-agent host."""
    p = common_parser(
        "linecrew agents",
        "SIMULATION ONLY: the onboard agents of many simulated UAVs in one process.",
    )
    p.add_argument(
        "--uavs", required=True, type=_ids, help="comma-separated UAV ids, e.g. uav-1,uav-2"
    )
    p.add_argument(
        "--autopilot-base-port",
        type=int,
        required=True,
        metavar="P",
        help="the i-th UAV's simulated autopilot is at udpout:HOST:P+i",
    )
    p.add_argument("--autopilot-host", default="127.0.0.1", help="the simulator's address")
    add_flight_arguments(p)
    return p


def _ids(text: str) -> list[str]:
    ids = [part.strip() for part in text.split(",") if part.strip()]
    if not ids or len(set(ids)) != len(ids):
        raise argparse.ArgumentTypeError("give distinct UAV ids separated by commas")
    return ids


async def host(
    autopilots: dict[str, str],
    scenario: Scenario,
    bus_config: BusConfig,
    config: AgentConfig,
    stop: Callable[[], Awaitable[None]],
    speedup: float = 1.0,
) -> list[str]:
    """Fly every UAV of ``autopilots`` (id -> pymavlink URL) until ``stop()``
    completes (it is called once per agent); returns the UAVs whose agent failed."""
    workers = len(autopilots) + 4  # bus opens and plan queries run in threads
    asyncio.get_running_loop().set_default_executor(
        concurrent.futures.ThreadPoolExecutor(workers, thread_name_prefix="agents")
    )

    async def fly(uav_id: str, url: str) -> bool:
        _current_uav.set(uav_id)  # this task's context only
        stopping = asyncio.ensure_future(stop())
        try:
            await run_agent(uav_id, scenario, url, bus_config, config, stopping, None, speedup)
        except Exception:
            log.exception("agent %s failed; the others fly on", uav_id)
            return False
        finally:
            stopping.cancel()
        return True

    flown = await asyncio.gather(*(fly(uav_id, url) for uav_id, url in autopilots.items()))
    return [uav_id for uav_id, ok in zip(autopilots, flown, strict=True) if not ok]


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit code."""
    args = parser().parse_args(sys.argv[1:] if argv is None else argv)
    os.nice(HOST_NICE)
    bus_config = start(args, "agents")
    for handler in logging.getLogger().handlers:
        handler.addFilter(_UavTag())
    try:
        config, scenario = settings(args)
        unknown = [u for u in args.uavs if scenario.fleet.type_of(u) is None]
        if unknown:
            raise UnknownUav(f"no UAV {', '.join(unknown)} in scenario {scenario.name!r}")
    except (ValueError, LinecrewError) as exc:
        log.error("cannot start: %s", exc)
        return 2
    base, address = args.autopilot_base_port, args.autopilot_host
    autopilots = {u: f"udpout:{address}:{base + i}" for i, u in enumerate(args.uavs)}
    shutdown = Shutdown().install()
    failed = asyncio.run(
        host(autopilots, scenario, bus_config, config, shutdown.wait_async, args.speedup)
    )
    log.info("%d agents stopped on %s", len(autopilots), shutdown.signal_name or "request")
    if failed:
        log.error("agents that failed: %s", ", ".join(failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
