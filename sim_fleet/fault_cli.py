"""``linecrew sim fault KIND ...``: inject a fault into a running simulator."""

from __future__ import annotations

import argparse
import sys

from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.fault_kinds import add_fault_arguments, fault_from_args
from linecrew_runtime.process import site_id
from proto import errors
from proto.keys import KeySpace
from proto.sim import FaultApplied


def main(argv: list[str] | None = None) -> int:
    """Send one fault; print the acknowledgement; exit 1 on an error reply."""
    parser = argparse.ArgumentParser(prog="linecrew sim fault", description=__doc__)
    parser.add_argument("--connect", default=None, help="zenoh router endpoint")
    parser.add_argument("--site", help="site id (else LINECREW_SITE, else default)")
    parser.add_argument("--timeout", type=float, default=5.0)
    add_fault_arguments(parser)
    args = parser.parse_args(argv)
    try:
        fault = fault_from_args(args)
    except ValueError as exc:
        parser.error(str(exc))
    try:
        keys = KeySpace(site_id(args.site))
        config = BusConfig.from_env(connect=(args.connect,) if args.connect else None)
    except (ValueError, errors.LinecrewError) as exc:
        parser.error(str(exc))
    try:
        with Bus.open(config, wait_s=args.timeout) as bus:
            reply = bus.query(keys.sim("fault"), fault, FaultApplied, args.timeout)
    except errors.LinecrewError as exc:
        print(f"linecrew sim fault: {exc.code}: {exc}", file=sys.stderr)
        return 1
    print(f"{reply.target}: {reply.detail} (sim time {reply.sim_time_s:.1f} s)")
    return 0
