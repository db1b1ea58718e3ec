"""``linecrew sim fault KIND ...``: inject a fault into a running simulator."""

from __future__ import annotations

import argparse
import sys

import msgspec

from linecrew.bus import Bus, BusConfig
from proto import errors
from proto.geo import Point
from proto.keys import KeySpace
from proto.sim import (
    BatteryFault,
    DrainFault,
    FaultApplied,
    GpsFreeze,
    GripperFailure,
    KillVehicle,
    LinkDrop,
    MotorFailure,
    MoveWorker,
    SimFault,
)

# kind -> (help, positional arguments after the target, builder)
_KINDS = {
    "battery": (
        "set the battery to FRACTION (0..1)",
        ["fraction"],
        lambda t, a: BatteryFault(uav_id=t, fraction=float(a[0])),
    ),
    "drain": (
        "multiply power draw by FACTOR",
        ["factor"],
        lambda t, a: DrainFault(uav_id=t, multiplier=float(a[0])),
    ),
    "motor": ("motors fail (it falls)", [], lambda t, a: MotorFailure(uav_id=t)),
    "kill": ("silent and falling", [], lambda t, a: KillVehicle(uav_id=t)),
    "link": (
        "MAVLink silent for SECONDS",
        ["seconds"],
        lambda t, a: LinkDrop(uav_id=t, duration_s=float(a[0])),
    ),
    "gps": (
        "position frozen for SECONDS",
        ["seconds"],
        lambda t, a: GpsFreeze(uav_id=t, duration_s=float(a[0])),
    ),
    "gripper": ("gripper fails", [], lambda t, a: GripperFailure(uav_id=t)),
    "gripper-repair": (
        "gripper works again",
        [],
        lambda t, a: GripperFailure(uav_id=t, failed=False),
    ),
    "move-worker": (
        "put a worker at X Y Z",
        ["x", "y", "z"],
        lambda t, a: MoveWorker(
            worker_id=t, position=Point(x_m=float(a[0]), y_m=float(a[1]), z_m=float(a[2]))
        ),
    ),
}


def build_fault(kind: str, target: str, values: list[str]) -> SimFault:
    """The fault command for ``kind`` (raises ``ValueError`` for bad values)."""
    fault = _KINDS[kind][2](target, values)
    return msgspec.convert(msgspec.to_builtins(fault), type(fault))  # validates ranges


def main(argv: list[str] | None = None) -> int:
    """Send one fault; print the acknowledgement; exit 1 on an error reply."""
    parser = argparse.ArgumentParser(prog="linecrew sim fault", description=__doc__)
    parser.add_argument("--connect", default=None, help="zenoh router endpoint")
    parser.add_argument("--site", default="default")
    parser.add_argument("--timeout", type=float, default=5.0)
    kinds = parser.add_subparsers(dest="kind", required=True)
    for kind, (help_, names, _) in _KINDS.items():
        sub = kinds.add_parser(kind, help=help_)
        sub.add_argument("target", help="worker id" if kind == "move-worker" else "UAV id")
        for name in names:
            sub.add_argument(name)
    args = parser.parse_args(argv)
    values = [getattr(args, name) for name in _KINDS[args.kind][1]]
    try:
        fault = build_fault(args.kind, args.target, values)
    except (ValueError, msgspec.ValidationError) as exc:
        parser.error(str(exc))
    config = BusConfig.from_env(connect=(args.connect,) if args.connect else None)
    try:
        with Bus.open(config, wait_s=args.timeout) as bus:
            reply = bus.query(KeySpace(args.site).sim("fault"), fault, FaultApplied, args.timeout)
    except errors.LinecrewError as exc:
        print(f"linecrew sim fault: {exc.code}: {exc}", file=sys.stderr)
        return 1
    print(f"{reply.target}: {reply.detail} (sim time {reply.sim_time_s:.1f} s)")
    return 0
