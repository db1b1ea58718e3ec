"""Everything of a linecrew deployment on this machine, as child processes:
router, ground station, gateway, simulator and one agent per UAV, on
loopback with free ports, started in dependency order and checked healthy.
Used by ``linecrew up``, ``linecrew demo`` and ``linecrew bench fleet``. With
``agents_per_process`` > 1 the simulated UAVs' agents run in groups, each
group in one :mod:`onboard_agent.fleet_host` (simulation only).

The run directory gets the scenario (``scenario.json``), what the run is
(``run.json``: speed-up, gateway, start), one log per process, the ground
station's store (``gs.db``) and what the UAVs reported (``flight.jsonl``,
see :mod:`linecrew.launch.flight_log`). While it runs, its gateway is
registered in the session file (:mod:`linecrew.client.session`)."""

from __future__ import annotations

import dataclasses
import datetime
import functools
import json
import logging
import pathlib
import time
from collections.abc import Callable

import httpx
import msgspec

from linecrew.client import session
from linecrew.client.gateway import Gateway, http_client
from linecrew.launch import secure
from linecrew.launch.flight_log import FlightLog
from linecrew.launch.ports import free_udp_block
from linecrew.launch.supervisor import Child, Supervisor
from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.bus.router_process import free_port, port_open
from proto.errors import LinecrewError
from proto.keys import KeySpace, Role
from proto.rpc import FleetReply, GetFleet
from proto.scenario import Scenario

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True, kw_only=True)
class RunOptions:
    """What to start and how."""

    speedup: float = 1.0  # mission seconds per wall second, for every process
    gateway_port: int = 0  # 0: a free port
    run_dir: pathlib.Path | None = None  # default runs/<UTC time>
    lease_ms: int = 500  # zenoh lease of every process
    start_timeout_s: float = 60.0  # per process
    secure: bool = False  # mutual TLS and access control (``secure``)
    session_file: pathlib.Path | None = None  # default: $LINECREW_SESSION or .linecrew/
    register: bool = True  # list the run in the session file while it is up
    warmup_s: float | None = None  # the simulated autopilots' GPS/EKF warm-up (mission s)
    agents_per_process: int = 1  # >1: simulated UAVs' agents share hosts (fleet_host)

    def __post_init__(self) -> None:
        if self.agents_per_process < 1:
            raise ValueError("agents_per_process must be at least 1")
        if self.secure and self.agents_per_process > 1:
            raise ValueError("a secure run keeps one agent process per UAV (own identity)")


class LocalRun:
    """A context manager: ``with LocalRun(scenario, options) as run:``."""

    def __init__(self, scenario: Scenario, options: RunOptions) -> None:
        self.scenario = scenario
        self.options = options
        stamp = datetime.datetime.now(datetime.UTC).strftime("%Y%m%dT%H%M%SZ")
        self.run_dir = options.run_dir or pathlib.Path("runs") / stamp
        self.keys = KeySpace(scenario.site.id)
        self.supervisor = Supervisor(self.run_dir)
        self.endpoint = ""
        self.url = ""
        self.token = ""
        self.ca_file: str | None = None  # the site CA, when the gateway serves HTTPS
        self.mavlink_ports: dict[str, int] = {}  # UAV id -> its simulated autopilot's UDP port
        self.bus: Bus | None = None
        self.flight_log: FlightLog | None = None
        self.session_file: pathlib.Path | None = None  # where the run is registered

    def __enter__(self) -> LocalRun:
        try:
            self._start()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Stop every process (newest first) and leave the bus."""
        if self.session_file is not None:
            session.unregister(self.url, self.session_file)
            self.session_file = None
        if self.flight_log is not None:
            self.flight_log.close()
            self.flight_log = None
        if self.bus is not None:
            self.bus.close()
            self.bus = None
        self.supervisor.stop_all()

    def _start(self) -> None:
        opts, keys = self.options, self.keys
        self.run_dir.mkdir(parents=True, exist_ok=True)
        scenario_file = self.run_dir / "scenario.json"
        scenario_file.write_bytes(msgspec.json.encode(self.scenario))
        started_s = time.time()
        uavs = [u.id for u in self.scenario.fleet.uavs]
        router_port = free_port()
        profile = secure.prepare(self.run_dir / "tls", uavs) if opts.secure else None
        self.endpoint = f"{'tls/localhost' if profile else 'tcp/127.0.0.1'}:{router_port}"

        def common(identity: str) -> list[str]:
            config = ["--zenoh-config", profile.client_config(identity)] if profile else []
            return [
                *config,
                "--connect",
                self.endpoint,
                "--lease-ms",
                str(opts.lease_ms),
                "--speedup",
                str(opts.speedup),
            ]

        sup, wait = self.supervisor, opts.start_timeout_s

        router = sup.start(
            "router",
            "linecrew_runtime.bus.router",
            *(["--zenoh-config", profile.router_config()] if profile else []),
            "--listen",
            self.endpoint.replace("localhost", "127.0.0.1"),
            "--site",
            keys.site,
            "--lease-ms",
            str(opts.lease_ms),
        )
        sup.wait_ready(router, lambda: port_open(router_port), wait)
        self.bus = Bus.open(
            BusConfig(
                connect=(self.endpoint,),
                lease_ms=opts.lease_ms,
                config_file=profile.client_config("operator") if profile else None,
            )
        )
        self.flight_log = FlightLog(self.bus, keys, self.run_dir / "flight.jsonl")

        gs = sup.start(
            "ground-station",
            "ground_station",
            *common("gs"),
            "--scenario",
            str(scenario_file),
            "--db",
            str(self.run_dir / "gs.db"),
        )
        sup.wait_ready(gs, lambda: self._alive(Role.GROUND_STATION, "gs"), wait)

        base_port = free_udp_block(len(uavs))
        self.mavlink_ports = {uav_id: base_port + i for i, uav_id in enumerate(uavs)}
        sim = sup.start(
            "sim",
            "sim_fleet",
            *common("sim"),
            "--scenario",
            str(scenario_file),
            "--base-port",
            str(base_port),
            *(["--warmup-s", str(opts.warmup_s)] if opts.warmup_s is not None else []),
            *(["--mavlink-keys", profile.mavlink_keys()] if profile else []),
        )
        sup.wait_ready(sim, lambda: self._alive(Role.SIM, "sim"), wait)

        gateway_port = opts.gateway_port or free_port()
        cert, key = profile.https() if profile else ("", "")
        https = ["--tls-cert", cert, "--tls-key", key] if profile else []
        self.ca_file = profile.ca() if profile else None
        self.url = f"{'https://localhost' if profile else 'http://127.0.0.1'}:{gateway_port}"
        token_file = self.run_dir / "token"
        gateway = sup.start(
            "gateway",
            "ground_station.gateway",
            *common("gateway"),
            "--scenario",
            str(scenario_file),
            "--port",
            str(gateway_port),
            "--token-file",
            str(token_file),
            *https,
        )
        sup.wait_ready(gateway, self._gateway_healthy, wait)
        self.token = token_file.read_text().strip()
        self._describe(started_s)
        if opts.register:
            entry = session.entry_for(
                self.url, self.token, self.run_dir, opts.speedup, self.scenario.name, self.ca_file
            )
            self.session_file = session.register(entry, opts.session_file)

        self._start_agents(uavs, base_port, common, profile)
        sup.wait_ready(gs, lambda: self.fleet_heard(uavs), wait)
        log.info("all processes healthy", extra={"run_dir": str(self.run_dir)})

    def _start_agents(
        self,
        uavs: list[str],
        base_port: int,
        common: Callable[[str], list[str]],
        profile: secure.SecureProfile | None,
    ) -> None:
        """Every agent process (one per UAV, or hosts of ``agents_per_process``)
        at once; then wait until every UAV's token is up."""
        per, scenario_file = self.options.agents_per_process, str(self.run_dir / "scenario.json")
        groups: list[tuple[Child, list[str]]] = []
        for number, first in enumerate(range(0, len(uavs), per), start=1):
            group = uavs[first : first + per]
            port = base_port + first
            name, module, args = self._agent_process(number, group, port, common, profile)
            child = self.supervisor.start(name, module, *args, "--scenario", scenario_file)
            groups.append((child, group))
        for child, group in groups:
            self.supervisor.wait_ready(
                child, functools.partial(self.agents_alive, group), self.options.start_timeout_s
            )

    def _agent_process(
        self,
        number: int,
        group: list[str],
        port: int,
        common: Callable[[str], list[str]],
        profile: secure.SecureProfile | None,
    ) -> tuple[str, str, list[str]]:
        """Name, module and flags of agent process ``number`` (from 1), for
        ``group``'s UAVs, the first of whose autopilots is on UDP ``port``."""
        if self.options.agents_per_process > 1:
            where = ["--uavs", ",".join(group), "--autopilot-base-port", str(port)]
            return f"agents-{number}", "onboard_agent.fleet_host", [*common("agents"), *where]
        [uav_id] = group
        key = ["--mavlink-key", profile.mavlink_key(uav_id)] if profile else []
        where = ["--uav", uav_id, "--autopilot", f"udpout:127.0.0.1:{port}"]
        return f"agent-{uav_id}", "onboard_agent", [*common(uav_id), *where, *key]

    def agents_alive(self, uavs: list[str]) -> bool:
        """Whether the liveliness tokens of all ``uavs``' agents are up."""
        assert self.bus is not None
        key = self.keys.all_alive(Role.AGENT)
        return {self.keys.alive(Role.AGENT, u) for u in uavs} <= self.bus.alive(key, 0.5)

    def fleet_heard(self, uavs: list[str]) -> bool:
        """Whether the ground station has heard every UAV's agent and (unless
        the autopilots warm up on purpose: no position, not ready yet) its
        telemetry and readiness: work asked for as soon as the run is up is
        planned on the whole fleet, not on the UAVs heard first."""
        assert self.bus is not None
        try:
            reply = self.bus.query(self.keys.rpc("fleet"), GetFleet(), FleetReply, 2.0)
        except LinecrewError:
            return False
        warming = self.options.warmup_s is not None
        heard = {
            u.uav_id
            for u in reply.uavs
            if u.status is not None and (warming or (u.telemetry is not None and u.status.ready))
        }
        return set(uavs) <= heard

    def _describe(self, started_s: float) -> None:
        """``run.json``: what ``linecrew report`` needs to know of the run."""
        about = {
            "scenario": self.scenario.name,
            "site": self.keys.site,
            "speedup": self.options.speedup,
            "started_s": started_s,  # UNIX seconds
            "started_mission_s": started_s * self.options.speedup,
            "gateway": self.url,
            "uavs": [u.id for u in self.scenario.fleet.uavs],
        }
        (self.run_dir / "run.json").write_text(json.dumps(about, indent=1))

    def _alive(self, role: Role, ident: str) -> bool:
        assert self.bus is not None
        key = self.keys.alive(role, ident)
        return key in self.bus.alive(key, timeout_s=0.5)

    def _gateway_healthy(self) -> bool:
        return session.healthy(self.url, ca_file=self.ca_file)

    def gateway(self) -> Gateway:
        """A client of this run's gateway."""
        return Gateway(self.url, self.token, ca_file=self.ca_file)

    def http(self, timeout_s: float = 10.0) -> httpx.Client:
        """A raw ``httpx.Client`` of this run's gateway (token and CA set)."""
        return http_client(self.url, self.token, ca_file=self.ca_file, timeout_s=timeout_s)
