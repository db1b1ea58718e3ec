"""The fault kinds an operator can inject, shared by ``linecrew sim fault``
(straight to the simulator) and ``linecrew fault`` (through the gateway)."""

from __future__ import annotations

import argparse
from collections.abc import Callable

import msgspec

from proto.geo import Point
from proto.sim import (
    BatteryFault,
    DrainFault,
    GpsFreeze,
    GripperFailure,
    KillVehicle,
    LinkDrop,
    MotorFailure,
    MoveWorker,
    SimFault,
)

# kind -> (help, positional arguments after the target, builder)
FAULT_KINDS: dict[str, tuple[str, list[str], Callable[[str, list[str]], SimFault]]] = {
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
    fault = FAULT_KINDS[kind][2](target, values)
    return msgspec.convert(msgspec.to_builtins(fault), type(fault))  # validates ranges


def add_fault_arguments(parser: argparse.ArgumentParser) -> None:
    """One subcommand per fault kind: ``KIND TARGET [VALUES...]``."""
    kinds = parser.add_subparsers(dest="kind", required=True)
    for kind, (help_, names, _) in FAULT_KINDS.items():
        sub = kinds.add_parser(kind, help=help_)
        sub.add_argument("target", help="worker id" if kind == "move-worker" else "UAV id")
        for name in names:
            sub.add_argument(name)


def fault_from_args(args: argparse.Namespace) -> SimFault:
    """The fault the parsed ``args`` describe (raises ``ValueError`` if invalid)."""
    values = [getattr(args, name) for name in FAULT_KINDS[args.kind][1]]
    try:
        return build_fault(args.kind, args.target, values)
    except msgspec.ValidationError as exc:
        raise ValueError(str(exc)) from exc
