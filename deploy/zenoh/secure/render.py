#!/usr/bin/env python3
"""Render linecrew's secured Zenoh profile: mutual TLS everywhere, and on the
router an access-control list keyed by the client certificate's common name.

    python3 deploy/zenoh/secure/render.py --tls-dir DIR --uavs N --out OUT_DIR

writes ``OUT_DIR/router.json5`` and ``OUT_DIR/client-{identity}.json5`` for
``gs``, ``gateway``, ``sim``, ``operator`` and ``uav-1`` .. ``uav-N`` (or
``--uav ID`` repeated), with certificate paths ``DIR/{name}.pem|key`` (as
given: relative paths are resolved from the working directory of the process
that loads the config). ``deploy/tls/gen-dev-ca.sh`` calls it with absolute
paths. The committed files next to this script are its output for
``--tls-dir deploy/tls/out --uavs 3`` (run from the repository root).

Only the standard library: it runs before any venv exists.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

SITE = "linecrew/*"  # every site; ids below are one key chunk each
SERVICES = ("gs", "gateway", "sim", "operator")

IN, OUT = ["ingress"], ["egress"]


def rule(rule_id: str, flows: list[str], messages: list[str], keys: list[str]) -> dict:
    return {
        "id": rule_id,
        "permission": "allow",
        "flows": flows,
        "messages": messages,
        "key_exprs": [f"{SITE}/{key}" for key in keys],
    }


def health(name: str, token: str) -> list[dict]:
    """``linecrew health ROLE ID`` (container healthchecks) runs with the
    process's own identity and asks for its own liveliness token."""
    return [
        rule(f"{name}-health", IN, ["liveliness_query"], [token]),
        rule(f"{name}-health-reply", OUT, ["liveliness_token"], [token]),
    ]


def service_rules(name: str) -> list[dict]:
    """What each ground-side process does on the bus (see the module docstrings
    of ground_station/service.py, ground_station/gateway, sim_fleet/main.py)."""
    uav_in = ["uav/*/telemetry", "uav/*/status", "uav/*/outcome"]
    if name == "gs":
        return [
            # RPC for the gateway/operator; plan resync queries from agents
            rule("gs-serve", IN, ["declare_queryable", "reply"], ["gs/rpc/*", "uav/*/plan"]),
            rule("gs-serve-q", OUT, ["query"], ["gs/rpc/*", "uav/*/plan"]),
            # what agents send
            rule("gs-sub", IN, ["declare_subscriber"], uav_in),
            rule("gs-sub-data", OUT, ["put", "delete"], uav_in),
            # plans to agents, the event stream
            rule("gs-pub", IN, ["put", "delete"], ["uav/*/plan", "gs/events", "gs/traffic"]),
            rule(
                "gs-pub-interest",
                OUT,
                ["declare_subscriber"],
                ["uav/*/plan", "gs/events", "gs/traffic"],
            ),
            # agents' health; its own token
            rule(
                "gs-watch",
                IN,
                ["declare_liveliness_subscriber", "liveliness_query"],
                ["alive/agent/*"],
            ),
            rule("gs-watch-tokens", OUT, ["liveliness_token"], ["alive/agent/*"]),
            rule("gs-token", IN, ["liveliness_token"], ["alive/gs/*"]),
            *health("gs", "alive/gs/*"),
        ]
    if name == "gateway":
        return [
            rule("gateway-call", IN, ["query"], ["gs/rpc/*", "sim/fault"]),
            rule("gateway-call-replies", OUT, ["reply"], ["gs/rpc/*", "sim/fault"]),
            # the event stream, and the workers' poses for the console's map
            rule("gateway-events", IN, ["declare_subscriber"], ["gs/events", "human/*/pose"]),
            rule("gateway-events-data", OUT, ["put", "delete"], ["gs/events", "human/*/pose"]),
            rule(
                "gateway-gs-alive",
                IN,
                ["liveliness_query", "declare_liveliness_subscriber"],
                ["alive/gs/*"],
            ),
            rule("gateway-gs-alive-tokens", OUT, ["liveliness_token"], ["alive/gs/*"]),
            rule("gateway-token", IN, ["liveliness_token"], ["alive/gateway/*"]),
            *health("gateway", "alive/gateway/*"),
        ]
    if name == "sim":
        return [
            rule("sim-serve", IN, ["declare_queryable", "reply"], ["sim/fault", "sim/state"]),
            rule("sim-serve-q", OUT, ["query"], ["sim/fault", "sim/state"]),
            rule("sim-poses", IN, ["put", "delete"], ["human/*/pose", "station/*/spots"]),
            rule(
                "sim-poses-interest",
                OUT,
                ["declare_subscriber"],
                ["human/*/pose", "station/*/spots"],
            ),
            # the stations' spot controllers hear claims from every UAV
            rule("sim-claims", IN, ["declare_subscriber"], ["uav/*/spot"]),
            rule("sim-claims-data", OUT, ["put", "delete"], ["uav/*/spot"]),
            rule("sim-token", IN, ["liveliness_token"], ["alive/sim/*"]),
            *health("sim", "alive/sim/*"),
        ]
    if name == "operator":
        # CLI tools, `linecrew up/demo`'s watcher, benchmarks: read and ask, never publish
        # as a fleet member (no put, no token, no queryable); it reads the events and
        # the UAVs' reports (the run's flight log)
        calls = ["gs/rpc/*", "sim/fault", "sim/state"]
        feeds = ["gs/events", "uav/*/telemetry", "uav/*/status", "uav/*/outcome"]
        return [
            rule("operator-call", IN, ["query"], calls),
            rule("operator-call-replies", OUT, ["reply"], calls),
            rule("operator-events", IN, ["declare_subscriber"], feeds),
            rule("operator-events-data", OUT, ["put", "delete"], feeds),
            rule(
                "operator-alive",
                IN,
                ["liveliness_query", "declare_liveliness_subscriber"],
                ["alive/**"],
            ),
            rule("operator-alive-tokens", OUT, ["liveliness_token"], ["alive/**"]),
        ]
    raise ValueError(name)


def agent_rules(uav: str) -> list[dict]:
    """An onboard agent (onboard_agent/comms.py): publishes its own telemetry,
    status, outcomes and spot claims; reads its own plan (subscription and
    resync query), the workers' poses, the stations' spots, the ground
    station's traffic report and the ground stations' tokens; declares its
    token."""
    own_out = [
        f"uav/{uav}/telemetry",
        f"uav/{uav}/status",
        f"uav/{uav}/outcome",
        f"uav/{uav}/spot",
    ]
    plan = f"uav/{uav}/plan"
    feeds = ["human/*/pose", "station/*/spots", "gs/traffic"]
    # The router tells a client which subscribers match what it publishes, and
    # a client stops sending puts when it knows of none: "*-interest" rules let
    # those declarations out (measured: without them publications stop after
    # the first). The ground station subscribes with wildcards (uav/*/status),
    # and a declaration passes only when a rule's key expression includes it
    # whole, so the rule names the wildcard: metadata, never data. Queries need
    # no such rule.
    return [
        rule(f"{uav}-pub", IN, ["put", "delete"], own_out),
        rule(
            f"{uav}-pub-interest",
            OUT,
            ["declare_subscriber"],
            ["uav/*/telemetry", "uav/*/status", "uav/*/outcome", "uav/*/spot"],
        ),
        rule(f"{uav}-sub", IN, ["declare_subscriber"], [plan, *feeds]),
        rule(f"{uav}-sub-data", OUT, ["put", "delete"], [plan, *feeds]),
        rule(f"{uav}-plan-query", IN, ["query"], [plan]),
        rule(f"{uav}-plan-reply", OUT, ["reply"], [plan]),
        rule(f"{uav}-gs-alive", IN, ["declare_liveliness_subscriber"], ["alive/gs/*"]),
        rule(f"{uav}-gs-alive-tokens", OUT, ["liveliness_token"], ["alive/gs/*"]),
        rule(f"{uav}-token", IN, ["liveliness_token"], [f"alive/agent/{uav}"]),
        *health(uav, f"alive/agent/{uav}"),
    ]


def access_control(uavs: list[str]) -> dict:
    rules: list[dict] = []
    subjects: list[dict] = []
    policies: list[dict] = []
    for name in [*SERVICES, *uavs]:
        own = agent_rules(name) if name in uavs else service_rules(name)
        rules += own
        subjects.append({"id": name, "cert_common_names": [name]})
        policies.append({"id": name, "subjects": [name], "rules": [r["id"] for r in own]})
    return {
        "enabled": True,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    }


def tls(tls_dir: str, name: str, side: str) -> dict:
    base = f"{tls_dir.rstrip('/')}/{name}"
    return {
        "root_ca_certificate": f"{tls_dir.rstrip('/')}/ca.pem",
        f"{side}_certificate": f"{base}.pem",
        f"{side}_private_key": f"{base}.key",
        "enable_mtls": True,
        **({"verify_name_on_connect": True} if side == "connect" else {}),
        **({"close_link_on_expiration": True} if side == "listen" else {}),
    }


def dump(value: object, indent: str = "") -> str:
    """JSON (valid JSON5), with every flat object or list on one line."""
    flat = json.dumps(value)
    if len(indent) + len(flat) <= 100 or not isinstance(value, dict | list):
        return flat
    inner = indent + "  "
    if isinstance(value, dict):
        items = [f"{inner}{json.dumps(k)}: {dump(v, inner)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + f"\n{indent}}}"
    items = [f"{inner}{dump(v, inner)}" for v in value]
    return "[\n" + ",\n".join(items) + f"\n{indent}]"


HEADER = """\
// linecrew secured Zenoh profile: {what}.
// Generated by deploy/zenoh/secure/render.py ({args}); edit the generator,
// not this file. Endpoints come from the command line (`--listen` /
// `--connect tls/HOST:7447`): linecrew's BusConfig sets them after loading
// this file.
"""


def render(tls_dir: str, uavs: list[str], args: str) -> dict[str, str]:
    files: dict[str, str] = {}
    only_tls = {"protocols": ["tls"]}
    router = {
        "transport": {"link": {**only_tls, "tls": tls(tls_dir, "router", "listen")}},
        "access_control": access_control(uavs),
    }
    what = f"router (mutual TLS, access control for {', '.join([*SERVICES, *uavs])})"
    files["router.json5"] = HEADER.format(what=what, args=args) + dump(router)
    for name in [*SERVICES, *uavs]:
        client = {"transport": {"link": {**only_tls, "tls": tls(tls_dir, name, "connect")}}}
        what = f"client `{name}` (certificate CN={name})"
        text = HEADER.format(what=what, args=args) + dump(client)
        files[f"client-{name}.json5"] = text
    return {name: text + "\n" for name, text in files.items()}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tls-dir", required=True, help="where ca.pem and the certs are")
    parser.add_argument("--uavs", type=int, help="agents uav-1 .. uav-N")
    parser.add_argument("--uav", action="append", default=[], help="an agent id (repeatable)")
    parser.add_argument("--out", required=True, help="directory to write the configs to")
    args = parser.parse_args(argv)
    uavs = [*(f"uav-{i}" for i in range(1, (args.uavs or 0) + 1)), *args.uav]
    if not uavs:
        parser.error("give --uavs N or --uav ID")
    chosen = (
        f"--uavs {args.uavs}"
        if args.uavs and not args.uav
        else " ".join(f"--uav {uav}" for uav in uavs)
    )
    summary = f"--tls-dir {args.tls_dir} {chosen}"
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, text in render(args.tls_dir, uavs, summary).items():
        (out / name).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
