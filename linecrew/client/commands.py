"""The operator commands of ``linecrew``: submit, gesture, actions, cancel,
control, status, plan, events, fault. All go through the gateway over HTTP (which one:
:mod:`linecrew.client.session`); ``--json``, anywhere on the command line,
prints the raw answer instead of a table."""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
from collections.abc import Callable
from typing import Any

import msgspec
from rich.console import Console

from linecrew.client.gateway import Gateway, GatewayError
from linecrew.client.render import (
    actions_table,
    fleet_table,
    plan_quality,
    plan_tasks,
    plan_timeline,
)
from linecrew.client.session import NoRunError, Target, resolve
from linecrew_runtime.fault_kinds import add_fault_arguments, fault_from_args
from proto.rpc import Command

GLOBAL_VALUED = ("--url", "--token")
"""Options of every operator command that take a value (hoisted like ``--json``)."""


def _parser(prog: str, description: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=f"linecrew {prog}", description=description)
    parser.add_argument(
        "--url", help="gateway URL (else LINECREW_URL, else the live run of the session file)"
    )
    parser.add_argument("--token", help="bearer token (else LINECREW_TOKEN or the session file)")
    parser.add_argument("--json", action="store_true", help="print JSON (anywhere on the line)")
    return parser


def hoist_globals(argv: list[str]) -> list[str]:
    """Move ``--json``, ``--url X`` and ``--token X`` to the front, wherever
    they are (before a ``--``), so that they work after a sub-command too."""
    front: list[str] = []
    rest: list[str] = []
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg == "--":
            rest += argv[i:]
            break
        if arg == "--json" or arg.startswith(tuple(f"{o}=" for o in GLOBAL_VALUED)):
            front.append(arg)
        elif arg in GLOBAL_VALUED and i + 1 < len(argv):
            front += [arg, argv[i + 1]]
            i += 1
        else:
            rest.append(arg)
        i += 1
    return front + rest


def _parse(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    return parser.parse_args(hoist_globals(argv))


def _target(args: argparse.Namespace) -> Target | None:
    """The gateway to talk to, or None after a one-line error on stderr."""
    try:
        return resolve(args.url, args.token)
    except NoRunError as exc:
        print(f"linecrew: {exc}", file=sys.stderr)
        return None


def _run(args: argparse.Namespace, work: Callable[[Gateway], Any], show: Callable[[Any], Any]):
    target = _target(args)
    if target is None:
        return 1
    try:
        result = work(target.gateway())
    except GatewayError as exc:
        print(f"linecrew: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        Console().print(show(result))
    return 0


POINT = re.compile(r"-?[\d.]+(,-?[\d.]+){2,3}")
"""X,Y,Z[,SERVICE_S] on the command line."""


def _point(text: str) -> dict[str, object]:
    try:
        x, y, z, *rest = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected X,Y,Z[,SERVICE_S]") from None
    return {"position": {"x_m": x, "y_m": y, "z_m": z}, "service_s": rest[0] if rest else 0.0}


def _negative_points(argv: list[str]) -> list[str]:
    """``inspect -5,15,3`` reads the point as an option; put ``--`` after
    ``inspect`` so that points with a negative first coordinate are points
    (only when no option follows, which ``--`` would swallow)."""
    if "inspect" not in argv or "--" in argv:
        return argv
    at = argv.index("inspect") + 1
    rest = argv[at:]
    if any(POINT.fullmatch(a) and a.startswith("-") for a in rest) and not any(
        a.startswith("-") and not POINT.fullmatch(a) for a in rest
    ):
        return [*argv[:at], "--", *rest]
    return argv


def submit_main(argv: list[str]) -> int:
    """``linecrew submit inspect|monitor|deliver ...``"""
    parser = _parser("submit", "submit an action")
    parser.add_argument("--priority", type=float, default=1.0)
    parser.add_argument("--request-id", help="idempotency key (retries are safe)")
    kinds = parser.add_subparsers(dest="kind", required=True)
    inspect = kinds.add_parser("inspect", help="inspect waypoints")
    inspect.add_argument("waypoints", nargs="+", type=_point, metavar="X,Y,Z[,SERVICE_S]")
    monitor = kinds.add_parser("monitor", help="monitor a worker")
    monitor.add_argument("worker")
    monitor.add_argument("--uavs", type=int, default=1)
    monitor.add_argument("--duration", type=float, required=True, help="seconds")
    monitor.add_argument("--standoff", type=float, default=5.0, help="metres")
    monitor.add_argument(
        "--bearing",
        type=float,
        help="degrees from +x (east) of slot 0 (default: the ground station picks one clear "
        "of the worker's other monitors)",
    )
    deliver = kinds.add_parser("deliver", help="deliver a tool to a worker")
    deliver.add_argument("tool")
    deliver.add_argument("--from", dest="station", required=True, help="tool station id")
    deliver.add_argument("--to", dest="worker", required=True, help="worker id")
    args = parser.parse_args(_negative_points(hoist_globals(argv)))
    body: dict[str, Any] = {"type": args.kind, "priority": args.priority}
    match args.kind:
        case "inspect":
            body["waypoints"] = args.waypoints
        case "monitor":
            body |= {
                "worker_id": args.worker,
                "uavs": args.uavs,
                "duration_s": args.duration,
                "standoff_m": args.standoff,
            }
            if args.bearing is not None:
                body["bearing_deg"] = args.bearing
        case "deliver":
            body |= {"tool": args.tool, "tool_station_id": args.station, "worker_id": args.worker}
    if args.request_id:
        body["request_id"] = args.request_id
    return _run(
        args, lambda g: g.call("POST", "/v1/actions", json=body), lambda r: actions_table([r])
    )


def gesture_main(argv: list[str]) -> int:
    """``linecrew gesture NAME TARGET``"""
    parser = _parser("gesture", "submit a crew gesture (e.g. bring-wrench W1)")
    parser.add_argument("gesture")
    parser.add_argument("target", help="tower, line or worker id")
    args = _parse(parser, argv)
    body = {"gesture": args.gesture, "target": args.target}
    return _run(
        args, lambda g: g.call("POST", "/v1/gestures", json=body), lambda r: actions_table([r])
    )


def actions_main(argv: list[str]) -> int:
    """``linecrew actions [--state S,...]``"""
    parser = _parser("actions", "list actions")
    parser.add_argument("--state", help="comma-separated states")
    args = _parse(parser, argv)
    params = {"state": args.state} if args.state else {}
    return _run(args, lambda g: g.call("GET", "/v1/actions", params=params), actions_table)


def cancel_main(argv: list[str]) -> int:
    """``linecrew cancel ACTION_ID``"""
    parser = _parser("cancel", "cancel an action")
    parser.add_argument("action_id")
    args = _parse(parser, argv)
    return _run(
        args,
        lambda g: g.call("DELETE", f"/v1/actions/{args.action_id}"),
        lambda r: actions_table([r]),
    )


def control_main(argv: list[str]) -> int:
    """``linecrew control UAV|all hold|return|land|resume``"""
    parser = _parser("control", "take a UAV (or all) out of the plan, or give it back")
    parser.add_argument("uav", help="a UAV id, or 'all' (hold all: a fleet stop)")
    parser.add_argument("command", choices=[str(c) for c in Command])
    args = _parse(parser, argv)
    path = "/v1/fleet/control" if args.uav == "all" else f"/v1/uavs/{args.uav}/control"
    return _run(args, lambda g: g.call("POST", path, json={"command": args.command}), fleet_table)


def status_main(argv: list[str]) -> int:
    """``linecrew status``: the fleet."""
    args = _parse(_parser("status", "fleet table"), argv)
    return _run(args, lambda g: g.call("GET", "/v1/fleet"), fleet_table)


def plan_main(argv: list[str]) -> int:
    """``linecrew plan``: the live plan as a timeline and a table of task
    times. With a file (``linecrew plan FILE ...``: a planning problem or a
    scenario) it runs the offline planner instead."""
    if (argv and not argv[0].startswith("-")) or "--validate" in argv:
        from linecrew.client.offline_plan import main as offline

        return offline(argv)
    parser = _parser(
        "plan",
        "the live plan of every UAV, times in mission seconds from now "
        "(or: linecrew plan FILE, FILE a planning problem or a scenario, to plan offline)",
    )
    parser.epilog = (
        "offline: linecrew plan FILE [-o PLAN.json] [--improve-ms N] [--mode complete|paper]; "
        "FILE is a planning problem (example: ground_station/planner/examples/paper.yaml) or a "
        "scenario (example: linecrew_runtime/scenarios/paper.yaml); "
        "linecrew plan --validate PROBLEM PLAN checks a plan."
    )
    parser.add_argument(
        "--speedup",
        type=float,
        help="the run's mission speed-up (default: the session file's, else the fleet's clock)",
    )
    args = _parse(parser, argv)
    target = _target(args)
    if target is None:
        return 1
    gateway = target.gateway()
    try:
        plans = gateway.call("GET", "/v1/plan")
        fleet = [] if args.json else gateway.call("GET", "/v1/fleet")
        quality = {} if args.json else gateway.call("GET", "/v1/plan/quality")
    except GatewayError as exc:
        print(f"linecrew: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(plans, indent=2))
        return 0
    speedup = args.speedup or (target.run.speedup if target.run else None)
    now, clock = mission_now(fleet, speedup)
    console = Console()
    console.print(plan_timeline(plans, now, clock))
    console.print(plan_tasks(plans, now))
    console.print(plan_quality(quality))
    return 0


def mission_now(fleet: list[dict[str, Any]], speedup: float | None) -> tuple[float, str]:
    """The run's mission clock now, and how it was found: from a known
    speed-up (mission s = UNIX s x K), else from the freshest telemetry
    stamp (mission seconds, at most a telemetry period old), else UNIX time."""
    if speedup:
        return time.time() * speedup, f"x{speedup:g}"
    stamps = [u["telemetry"]["stamp_s"] for u in fleet if u.get("telemetry")]
    if stamps:
        now = max(stamps)
        return now, f"x{now / time.time():.3g} from telemetry"
    return time.time(), "x1 (no telemetry; give --speedup)"


def events_main(argv: list[str]) -> int:
    """``linecrew events [--after SEQ]``: follow the event stream."""
    parser = _parser("events", "follow ground-station events (Ctrl-C to stop)")
    parser.add_argument("--after", type=int, help="replay events after this sequence number")
    args = _parse(parser, argv)
    target = _target(args)
    if target is None:
        return 1
    try:
        for event in target.gateway().events(args.after):
            if args.json:
                print(json.dumps(event), flush=True)
            else:
                who = event.get("uav_id") or event.get("action_id") or ""
                print(
                    f"{event['seq']:>6} {event['kind']:<16} {who:<16} {event['detail']}", flush=True
                )
    except GatewayError as exc:
        print(f"linecrew: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        pass
    return 0


def fault_main(argv: list[str]) -> int:
    """``linecrew fault KIND TARGET [VALUES]`` through the gateway (simulation only)."""
    parser = _parser("fault", "inject a simulator fault through the gateway")
    add_fault_arguments(parser)
    args = _parse(parser, argv)
    try:
        fault = msgspec.to_builtins(fault_from_args(args))
    except ValueError as exc:
        parser.error(str(exc))
    return _run(
        args,
        lambda g: g.call("POST", "/v1/sim/faults", json=fault),
        lambda r: f"{r['target']}: {r['detail']}",
    )
