"""A whole linecrew deployment spread over network namespaces, one process
per namespace: ``router``, ``ground-station``, ``gateway``, ``sim`` and one
``agent-<uav>`` per UAV (the companion computer), each named after its
process. The observer (chaos runner, tests) stays in the root namespace and
reaches the router and the gateway over the bridge.

Every process talks Zenoh over TCP to the router. A partition of a process
(:meth:`NetnsRun.cut`) drops TCP to and from the router's port in that
process's namespace, except with the observer: its Zenoh link is cut for
real, both ways, and nothing else. An agent keeps its MAVLink link (UDP to
``sim``): on a real UAV the autopilot is on board, wired to the companion
computer, so a radio partition cuts the agent from the ground, never from
its autopilot, and the agent can still abandon its tasks and land on its
own. The gateway keeps serving REST (and answers 503 while it cannot reach
the ground station). Cutting the router cuts every link at once, while the
observer still sees the simulator's truth. (The simulator cannot sit next
to each agent: one simulator process serves every UAV.)

:class:`NetnsRun` has the surface of :class:`~linecrew.launch.local_run.LocalRun`
that the chaos runner uses (``supervisor``, ``bus``, ``keys``, ``run_dir``,
``http()``), so :class:`~linecrew.chaos.faults.ProcessFaults` kills and
restarts its processes the same way: a restarted process comes back in its
own namespace.
"""

from __future__ import annotations

import contextlib
import datetime
import pathlib
import socket

import httpx
import msgspec

from linecrew.chaos.netns import Network, network
from linecrew.client import session
from linecrew.client.gateway import http_client
from linecrew.launch.local_run import RunOptions
from linecrew.launch.supervisor import Supervisor
from linecrew_runtime.bus import Bus, BusConfig
from proto.keys import KeySpace, Role
from proto.scenario import Scenario

ROUTER_PORT = 7447
GATEWAY_PORT = 8080
MAVLINK_BASE_PORT = 14550


class NetnsSupervisor(Supervisor):
    """A :class:`Supervisor` that starts each child in the namespace named after it."""

    def __init__(self, run_dir: pathlib.Path) -> None:
        super().__init__(run_dir)
        self.net: Network | None = None

    def command_prefix(self, name: str) -> list[str]:
        assert self.net is not None, "the network is not up"
        return self.net.exec_prefix(name)


class NetnsRun:
    """A context manager: ``with NetnsRun(scenario, options) as run:``; raises
    :class:`~linecrew.chaos.netns.NetnsError` where namespaces are refused."""

    def __init__(self, scenario: Scenario, options: RunOptions) -> None:
        if options.secure or options.agents_per_process > 1:
            raise ValueError("a namespace run has one plain agent process per UAV")
        self.scenario = scenario
        self.options = options
        stamp = datetime.datetime.now(datetime.UTC).strftime("%Y%m%dT%H%M%SZ")
        self.run_dir = options.run_dir or pathlib.Path("runs") / stamp
        self.keys = KeySpace(scenario.site.id)
        self.uavs = [u.id for u in scenario.fleet.uavs]
        self.names = ["router", "ground-station", "gateway", "sim"]
        self.names += [f"agent-{u}" for u in self.uavs]
        self.supervisor = NetnsSupervisor(self.run_dir)
        self.net: Network | None = None
        self.bus: Bus | None = None
        self.endpoint = ""
        self.url = ""
        self.token = ""
        self.session_file: pathlib.Path | None = None
        self._stack = contextlib.ExitStack()

    def __enter__(self) -> NetnsRun:
        try:
            self.net = self.supervisor.net = self._stack.enter_context(network(self.names))
            self._start()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Stop every process (newest first), leave the bus, delete the namespaces."""
        if self.session_file is not None:
            session.unregister(self.url, self.session_file)
            self.session_file = None
        if self.bus is not None:
            self.bus.close()
            self.bus = None
        self.supervisor.stop_all()
        self._stack.close()

    # -- start ----------------------------------------------------------------------

    def address(self, name: str) -> str:
        """Process ``name``'s address on the bridge."""
        assert self.net is not None
        return self.net.hosts[name].address

    def _start(self) -> None:
        opts, sup = self.options, self.supervisor
        self.run_dir.mkdir(parents=True, exist_ok=True)
        scenario_file = self.run_dir / "scenario.json"
        scenario_file.write_bytes(msgspec.json.encode(self.scenario))
        scenario = ["--scenario", str(scenario_file)]
        self.endpoint = f"tcp/{self.address('router')}:{ROUTER_PORT}"
        lease = ["--lease-ms", str(opts.lease_ms)]
        common = ["--connect", self.endpoint, *lease, "--speedup", str(opts.speedup)]
        sim = self.address("sim")
        self.url = f"http://{self.address('gateway')}:{GATEWAY_PORT}"
        token_file = self.run_dir / "token"
        site = ["--site", self.keys.site]
        sup.start("router", "linecrew_runtime.bus.router", "--listen", self.endpoint, *site, *lease)
        self._wait("router")
        self.bus = Bus.open(BusConfig(connect=(self.endpoint,), lease_ms=opts.lease_ms))
        db = ["--db", str(self.run_dir / "gs.db")]
        sup.start("ground-station", "ground_station", *common, *scenario, *db)
        self._wait("ground-station")
        mavlink = ["--host", sim, "--base-port", str(MAVLINK_BASE_PORT)]
        warmup = ["--warmup-s", str(opts.warmup_s)] if opts.warmup_s is not None else []
        sup.start("sim", "sim_fleet", *common, *scenario, *mavlink, *warmup)
        self._wait("sim")
        http = ["--host", "0.0.0.0", "--port", str(GATEWAY_PORT), "--token-file", str(token_file)]
        sup.start("gateway", "ground_station.gateway", *common, *scenario, *http)
        self._wait("gateway")
        self.token = token_file.read_text().strip()
        if opts.register:
            entry = session.entry_for(
                self.url, self.token, self.run_dir, opts.speedup, self.scenario.name
            )
            self.session_file = session.register(entry, opts.session_file)
        for index, uav in enumerate(self.uavs):
            autopilot = f"udpout:{sim}:{MAVLINK_BASE_PORT + index}"
            where = ["--uav", uav, "--autopilot", autopilot]
            sup.start(f"agent-{uav}", "onboard_agent", *common, *scenario, *where)
        for uav in self.uavs:
            self._wait(f"agent-{uav}")

    def _wait(self, name: str) -> None:
        child = next(c for c in reversed(self.supervisor.children) if c.name == name)
        self.supervisor.wait_ready(child, lambda: self.healthy(name), self.options.start_timeout_s)

    # -- faults and health --------------------------------------------------------------

    def cut(self, name: str) -> None:
        """Partition process ``name``: its Zenoh link to the router is cut."""
        assert self.net is not None
        self.net.block_port(name, ROUTER_PORT)

    def heal(self, name: str) -> None:
        """Undo :meth:`cut`."""
        assert self.net is not None
        self.net.unblock(name)

    def healthy(self, name: str) -> bool:
        """The process's own health signal: the router accepts TCP, the gateway
        answers /healthz, the others hold their liveliness token."""
        if name == "router":
            with socket.socket() as sock:
                sock.settimeout(0.3)
                return sock.connect_ex((self.address("router"), ROUTER_PORT)) == 0
        if name == "gateway":
            return session.healthy(self.url)
        role, ident = {
            "ground-station": (Role.GROUND_STATION, "gs"),
            "sim": (Role.SIM, "sim"),
        }.get(name, (Role.AGENT, name.removeprefix("agent-")))
        return self.alive(role, ident)

    def alive(self, role: Role, ident: str) -> bool:
        """Whether the liveliness token of ``role/ident`` is present (seen by the observer)."""
        assert self.bus is not None
        key = self.keys.alive(role, ident)
        try:
            return key in self.bus.alive(key, timeout_s=0.5)
        except Exception:  # the router may be down: not alive
            return False

    def http(self, timeout_s: float = 10.0) -> httpx.Client:
        """A raw ``httpx.Client`` of this run's gateway (token set)."""
        return http_client(self.url, self.token, timeout_s=timeout_s)
