"""``linecrew ground-station``: run the ground station process."""

from __future__ import annotations

import asyncio
import logging
import sys
import time
from collections.abc import Callable

from ground_station.config import GsConfig
from ground_station.service import GroundStation
from ground_station.store import StoreUnavailable
from linecrew_runtime.bus import Bus
from linecrew_runtime.clock import mission_clock
from linecrew_runtime.process import Shutdown, common_parser, start
from linecrew_runtime.scenarios import ScenarioError, load
from proto.errors import Unavailable

log = logging.getLogger("linecrew.ground_station")

STORE_RETRY_S = 1.0
"""Wall seconds between two attempts to open a store that cannot write."""


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
        station = _when_store_writes(
            lambda: GroundStation(
                config, scenario, bus, clock=mission_clock(args.speedup), speedup=args.speedup
            ),
            config.store_wait_s,
            shutdown,
        )
        if station is None:
            return 1
        asyncio.run(station.run(shutdown))
    log.info("ground station stopped on %s", shutdown.signal_name or "request")
    return 0


def _when_store_writes(
    build: Callable[[], GroundStation], wait_s: float, shutdown: Shutdown
) -> GroundStation | None:
    """``build()``, retried once a second while the store cannot write (a
    disk read-only or full for a while, a volume not yet mounted) for up to
    ``wait_s``; None, said in the log, if it never could or on shutdown."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            return build()
        except StoreUnavailable as exc:
            if time.monotonic() >= deadline or shutdown.wait(STORE_RETRY_S):
                log.error("ground station cannot start: %s", exc)
                return None
            log.warning("the store cannot write yet; retrying", extra={"error": str(exc)})


if __name__ == "__main__":
    sys.exit(main())
