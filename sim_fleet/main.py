"""``linecrew sim``: the fleet simulator process.

N simulated multirotors, each a MAVLink endpoint on ``base_port + i`` (like
ArduCopter SITL), the simulated human tracker, the charging stations' spot
controllers (:mod:`sim_fleet.spot_control`), fault injection (queries on
``sim/fault``) and the ground truth (queries on ``sim/state``), all on one
asyncio loop. Health: the ``alive/sim/{id}`` token.
"""

from __future__ import annotations

import asyncio
import logging
import sys

from linecrew_runtime.bus import Bus
from linecrew_runtime.clock import mission_clock
from linecrew_runtime.mavlink_keys import SigningKeyError, key_path, load_key
from linecrew_runtime.process import Shutdown, common_parser, start
from linecrew_runtime.scenarios import ScenarioError, load
from proto.errors import Unavailable
from proto.keys import KeySpace, Role
from proto.scenario import Scenario
from proto.sim import GetSimState, SimFault
from sim_fleet.faults import apply_fault
from sim_fleet.fleet import Fleet, FleetConfig
from sim_fleet.params import AutopilotParams
from sim_fleet.spot_control import SpotControl, SpotService
from sim_fleet.streams import TelemetryRates
from sim_fleet.tracker import HumanTracker
from sim_fleet.truth import sim_state

log = logging.getLogger("linecrew.sim")


async def serve(
    scenario: Scenario, fleet: Fleet, bus: Bus, shutdown: Shutdown, sim_id: str, pose_hz: float
) -> int:
    """Run the simulator until ``shutdown``; 1 if its ports cannot be bound."""
    try:
        await fleet.start()
    except OSError as exc:
        log.error("simulator cannot bind its MAVLink ports: %s", exc)
        return 1
    keys = KeySpace(scenario.site.id)
    world, speedup = fleet.world, fleet.config.speedup
    bus.serve(keys.sim("fault"), SimFault, lambda fault: apply_fault(world, fault, scenario.site))
    bus.serve(keys.sim("state"), GetSimState, lambda _request: sim_state(world, speedup))
    bus.declare_token(keys.alive(Role.SIM, sim_id))
    log.info(
        "simulating %d UAVs at x%g", len(fleet.endpoints), speedup, extra={"ports": fleet.ports}
    )
    tracker = HumanTracker(scenario.site, world, bus, mission_clock(speedup))
    control = SpotControl(world.spots, world.rules.dock_radius_m, owners=world.spot_owners)
    stations = SpotService(control, world, bus, keys)
    async with asyncio.TaskGroup() as group:
        running = group.create_task(fleet.run())
        poses = group.create_task(tracker.run(pose_hz))
        spot_feed = group.create_task(stations.run(pose_hz))
        await shutdown.wait_async()
        poses.cancel()
        spot_feed.cancel()
        fleet.stop()
        await running
    return 0


def signing_keys(directory: str | None, uav_ids: list[str]) -> dict[str, bytes]:
    """Every vehicle's MAVLink key from ``directory`` (none without one)."""
    if directory is None:
        return {}
    return {uav_id: load_key(key_path(directory, uav_id)) for uav_id in uav_ids}


def main(argv: list[str] | None = None) -> int:
    """Run until SIGINT/SIGTERM; exit 1 on a fatal start-up error.
    ``linecrew sim fault ...`` injects a fault into a running simulator."""
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["fault"]:
        from sim_fleet.fault_cli import main as fault_main

        return fault_main(argv[1:])
    parser = common_parser("linecrew sim", "MAVLink fleet simulator with a human tracker")
    parser.add_argument("--scenario", default="paper", help="shipped scenario name or file")
    parser.add_argument(
        "--base-port",
        type=int,
        default=14560,
        help="UDP port of the first vehicle (vehicle i: base + i)",
    )
    parser.add_argument("--host", default="127.0.0.1", help="address the endpoints bind to")
    parser.add_argument("--pose-hz", type=float, default=4.0, help="worker pose rate")
    parser.add_argument("--id", default="sim", help="liveliness token name")
    parser.add_argument(
        "--warmup-s",
        type=float,
        default=AutopilotParams.warmup_s,
        help="GPS/EKF warm-up before arming is allowed, in simulated seconds "
        "(scaled by --speedup like everything else; 0 skips it)",
    )
    parser.add_argument(
        "--stream-by-default",
        action="store_true",
        help="stream telemetry before any client asks (ArduCopter with SRx_ rates set)",
    )
    parser.add_argument(
        "--mavlink-keys",
        metavar="DIR",
        help="sign MAVLink with each vehicle's key DIR/{uav}.key and accept only signed "
        "packets (the secured profile writes them)",
    )
    args = parser.parse_args(argv)
    if args.warmup_s < 0:
        parser.error("--warmup-s must be >= 0")
    bus_config = start(args, "sim")
    shutdown = Shutdown().install()
    try:
        scenario = load(args.scenario, site=args.site)
        keys = signing_keys(args.mavlink_keys, [u.id for u in scenario.fleet.uavs])
        bus = Bus.open(bus_config, should_stop=shutdown.is_set)
    except (ScenarioError, SigningKeyError, Unavailable) as exc:
        log.error("simulator cannot start: %s", exc)
        return 1
    config = FleetConfig(
        speedup=args.speedup,
        base_port=args.base_port,
        host=args.host,
        params=AutopilotParams(warmup_s=args.warmup_s),
        rates=TelemetryRates(stream_by_default=args.stream_by_default),
        signing_keys=keys,
    )
    fleet = Fleet(scenario, config)
    with bus:
        code = asyncio.run(serve(scenario, fleet, bus, shutdown, args.id, args.pose_hz))
    log.info("simulator stopped on %s", shutdown.signal_name or "request")
    return code


if __name__ == "__main__":
    sys.exit(main())
