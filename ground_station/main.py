"""``linecrew ground-station``: run the ground station process."""

from __future__ import annotations

import asyncio
import logging
import sys

from ground_station.config import GsConfig
from ground_station.service import GroundStation
from ground_station.store import StoreUnavailable
from linecrew_runtime.bus import Bus
from linecrew_runtime.clock import mission_clock
from linecrew_runtime.process import Shutdown, common_parser, start
from linecrew_runtime.scenarios import ScenarioError, load
from proto.errors import Unavailable

log = logging.getLogger("linecrew.ground_station")


def main(argv: list[str] | None = None) -> int:
    """Run until SIGINT/SIGTERM; exit 1 on a fatal start-up error."""
    parser = common_parser("linecrew ground-station", "mission manager, planner, watchdog")
    parser.add_argument("--scenario", help="shipped scenario name or scenario file")
    parser.add_argument("--db", dest="db_path", help="SQLite store path")
    parser.add_argument("--gs-id", help="liveliness token name")
    parser.add_argument(
        "--link-timeout",
        dest="link_timeout_s",
        type=float,
        help="seconds of silence before a UAV is lost (default 5)",
    )
    args = parser.parse_args(argv)
    bus_config = start(args, "ground-station")
    shutdown = Shutdown().install()
    try:
        config = GsConfig.from_env(
            scenario=args.scenario,
            db_path=args.db_path,
            gs_id=args.gs_id,
            link_timeout_s=args.link_timeout_s,
        )
        scenario = load(config.scenario, site=args.site)
        bus = Bus.open(bus_config, should_stop=shutdown.is_set)
    except (ValueError, ScenarioError, Unavailable) as exc:
        log.error("ground station cannot start: %s", exc)
        return 1
    with bus:
        try:
            station = GroundStation(
                config, scenario, bus, clock=mission_clock(args.speedup), speedup=args.speedup
            )
        except StoreUnavailable as exc:
            log.error("ground station cannot start: %s", exc)
            return 1
        asyncio.run(station.run(shutdown))
    log.info("ground station stopped on %s", shutdown.signal_name or "request")
    return 0


if __name__ == "__main__":
    sys.exit(main())
