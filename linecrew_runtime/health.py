"""``linecrew health ROLE ID``: is this process alive on the bus?

Opens a short-lived Zenoh client (same settings as the processes:
``--connect`` / ``LINECREW_ZENOH_*``, ``--site`` / ``LINECREW_SITE``) and asks
the router for the liveliness token ``alive/{ROLE}/{ID}``. Exit 0 if it is
there, 1 if not, 2 if no router answers. Made for container healthchecks:

    python -m linecrew_runtime.health agent uav-1
"""

from __future__ import annotations

import argparse
import sys

from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.process import site_id
from proto.errors import LinecrewError, Unavailable
from proto.keys import KeySpace, Role


def parser() -> argparse.ArgumentParser:
    """The flags of ``linecrew health``."""
    p = argparse.ArgumentParser(prog="linecrew health", description=__doc__.split("\n")[0])
    p.add_argument("role", choices=[str(r) for r in Role], help="who declares the token")
    p.add_argument("ident", help="its id (gs, uav-1, sim, gateway, router, ...)")
    p.add_argument("--site", help="site id (key space root; else LINECREW_SITE, else default)")
    p.add_argument("--connect", action="append", help="zenoh endpoint (repeatable)")
    p.add_argument("--zenoh-config", help="a zenoh json5 config file applied first")
    p.add_argument("--timeout", type=float, default=2.0, help="seconds to wait for the router")
    return p


def main(argv: list[str] | None = None) -> int:
    """0 if the token is alive, 1 if not, 2 if the bus cannot be reached."""
    args = parser().parse_args(argv)
    try:
        key = KeySpace(site_id(args.site)).alive(Role(args.role), args.ident)
        config = BusConfig.from_env(
            connect=tuple(args.connect) if args.connect else None,
            config_file=args.zenoh_config,
            connect_attempt_ms=int(args.timeout * 1000),
        )
        bus = Bus.open(config, wait_s=args.timeout)
    except Unavailable as exc:
        print(f"unhealthy: {exc}", file=sys.stderr)
        return 2
    except (LinecrewError, ValueError) as exc:
        print(f"linecrew health: {exc}", file=sys.stderr)
        return 2
    with bus:
        alive = key in bus.alive(key, timeout_s=args.timeout)
    print(f"{'alive' if alive else 'not alive'}: {key}")
    return 0 if alive else 1


if __name__ == "__main__":
    sys.exit(main())
