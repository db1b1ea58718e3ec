"""The ground site's Zenoh router: a zenoh-python session in router mode
that every other process connects to as a client. Declares the liveliness
token ``alive/router/{id}`` as its health signal.

Run: ``linecrew router --listen tcp/0.0.0.0:7447`` (or ``python -m linecrew_runtime.bus.router``).
"""

from __future__ import annotations

import logging
import sys

from linecrew_runtime.bus import DEFAULT_ROUTER, Bus
from linecrew_runtime.process import DEFAULT_SITE, Shutdown, common_parser, start
from proto.errors import Unavailable
from proto.keys import KeySpace, Role

log = logging.getLogger("linecrew.router")


def main(argv: list[str] | None = None) -> int:
    """Run the router until SIGINT/SIGTERM; exit 1 if it cannot listen."""
    parser = common_parser("linecrew router", "Zenoh router of the ground site")
    parser.add_argument("--id", default="router", help="router id (liveliness token name)")
    args = parser.parse_args(argv)
    if not args.listen:
        args.listen = [DEFAULT_ROUTER]
    config = start(args, "router", mode="router")
    shutdown = Shutdown().install()
    try:
        bus = Bus.open(config)
    except Unavailable as exc:
        log.error("router cannot start: %s", exc)
        return 1
    site = args.site or DEFAULT_SITE  # start() has read LINECREW_SITE into it
    with bus:
        bus.declare_token(KeySpace(site).alive(Role.ROUTER, args.id))
        log.info("router listening on %s", ", ".join(config.listen), extra={"site": site})
        shutdown.wait()
        log.info("router stopping on %s", shutdown.signal_name or "request")
    return 0


if __name__ == "__main__":
    sys.exit(main())
