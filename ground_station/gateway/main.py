"""``linecrew gateway``: the operator REST API process."""

from __future__ import annotations

import asyncio
import dataclasses
import logging
import sys

import uvicorn

from ground_station.gateway.app import create_app
from ground_station.gateway.gestures import Vocabulary
from ground_station.gateway.rpc import GsClient
from ground_station.gateway.settings import GatewaySettings, check_token, resolve_token
from ground_station.gateway.workers import WorkerPoses
from linecrew_runtime.bus import Bus
from linecrew_runtime.clock import mission_clock
from linecrew_runtime.process import common_parser, start
from linecrew_runtime.scenarios import ScenarioError, load
from proto.errors import Unavailable
from proto.keys import KeySpace, Role
from proto.telemetry import HumanPose

log = logging.getLogger("linecrew.gateway")

STREAMS_GRACE_S = 3
"""On SIGTERM, open requests (an event stream never ends by itself) get this
long before they are cut and the gateway exits."""


def main(argv: list[str] | None = None) -> int:
    """Serve HTTP until SIGINT/SIGTERM; exit 1 on a fatal start-up error."""
    parser = common_parser("linecrew gateway", "operator REST API of the ground station")
    parser.add_argument("--host", help="HTTP bind address (127.0.0.1)")
    parser.add_argument("--port", type=int, help="HTTP port (8080; 0: any free port)")
    parser.add_argument("--token", help="bearer token (else --token-file, LINECREW_TOKEN)")
    parser.add_argument("--token-file", help="file holding the token (created if missing)")
    parser.add_argument("--scenario", help="shipped scenario name or scenario file (paper)")
    parser.add_argument("--gestures", help="a YAML gesture vocabulary")
    parser.add_argument("--rpc-timeout", type=float, help="seconds before 503 (2)")
    parser.add_argument("--tls-cert", help="serve HTTPS with this certificate (PEM)")
    parser.add_argument("--tls-key", help="the key of --tls-cert (PEM)")
    args = parser.parse_args(argv)
    if bool(args.tls_cert) != bool(args.tls_key):
        parser.error("--tls-cert and --tls-key go together")
    bus_config = start(args, "gateway")
    try:
        settings = GatewaySettings.from_env(
            host=args.host,
            port=args.port,
            scenario=args.scenario,
            rpc_timeout_s=args.rpc_timeout,
            gestures=args.gestures,
        )
        token = check_token(resolve_token(args.token, args.token_file))
        scenario = load(settings.scenario, site=args.site)
        vocabulary = Vocabulary.load(settings.gestures)
        bus = Bus.open(bus_config)
    except (ValueError, ScenarioError, Unavailable, OSError) as exc:
        log.error("gateway cannot start: %s", exc)
        return 1
    settings = dataclasses.replace(settings, token=token, site=scenario.site.id)
    with bus:
        bus.declare_token(KeySpace(settings.site).alive(Role.GATEWAY, "gateway"))
        client = GsClient(bus, settings.site, settings.rpc_timeout_s)
        workers = WorkerPoses(scenario.site, mission_clock(args.speedup))
        bus.subscribe(client.keys.all_human_poses(), HumanPose, workers.on_pose)
        app = create_app(settings, client, scenario.site, vocabulary, workers)
        server = uvicorn.Server(
            uvicorn.Config(
                app,
                host=settings.host,
                port=settings.port,
                log_config=None,
                access_log=False,
                ssl_certfile=args.tls_cert,
                ssl_keyfile=args.tls_key,
                timeout_graceful_shutdown=STREAMS_GRACE_S,
            )
        )
        scheme = "https" if args.tls_cert else "http"
        log.info("gateway on %s://%s:%d", scheme, settings.host, settings.port)
        asyncio.run(server.serve())
    log.info("gateway stopped")
    return 0


if __name__ == "__main__":
    sys.exit(main())
