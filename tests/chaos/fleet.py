"""A whole linecrew deployment spread over network namespaces.

Placement (why the agent's partition cuts only Zenoh):

- ``ground``: router, ground station, gateway (the ground site);
- ``sim``: the simulator, i.e. the airframes and their autopilots;
- ``uav-N``: one namespace per onboard agent (the companion computer).

An agent talks MAVLink to its autopilot over UDP to ``sim`` and Zenoh over
TCP to the router in ``ground``. On a real UAV the autopilot is on board,
wired to the companion computer: a radio partition cuts the agent from the
ground, never from its own autopilot. So a partition of an agent is an nft
rule in the agent's namespace dropping TCP to and from the router's port
(:meth:`Network.block_tcp_port`): Zenoh is cut, MAVLink keeps flowing and
the agent can still abandon its tasks and land, which is the behaviour under
test. Setting its bridge port down would also cut the autopilot, a
different failure (covered by the simulator's ``link`` fault). The
simulator cannot move next to the agent instead: one simulator process
serves every UAV.

The test process sits in the root namespace, plugged into the same switch,
and reaches the gateway and the router over the bridge.
"""

from __future__ import annotations

import os
import pathlib
import socket
import subprocess
import sys

import httpx
import msgspec

from linecrew.bus import Bus, BusConfig
from linecrew.launch.supervisor import Child, Supervisor, _die_with_parent
from proto.keys import KeySpace, Role
from proto.scenario import Scenario
from tests.chaos.netns import Network

ROUTER_PORT = 7447
GATEWAY_PORT = 8080
MAVLINK_BASE_PORT = 14550
TOKEN = "chaos-test-token"
START_TIMEOUT_S = 60.0


class NetnsSupervisor(Supervisor):
    """A :class:`Supervisor` whose children run inside a namespace."""

    def start_in(self, prefix: list[str], name: str, module: str, *args: str) -> Child:
        """``prefix python -m module args...`` logging to ``run_dir/name.log``."""
        log_path = self.run_dir / f"{name}.log"
        with open(log_path, "ab") as log_file:
            popen = subprocess.Popen(
                [*prefix, sys.executable, "-m", module, *args],
                stdout=log_file,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                env=dict(os.environ, PYTHONUNBUFFERED="1"),
                start_new_session=True,
                preexec_fn=_die_with_parent,
            )
        child = Child(name, popen, log_path)
        self.children.append(child)
        return child


class NetnsFleet:
    """Start, kill and restart the processes of one deployment in ``net``."""

    def __init__(
        self, net: Network, scenario: Scenario, run_dir: pathlib.Path, speedup: float
    ) -> None:
        self.net = net
        self.scenario = scenario
        self.run_dir = run_dir
        self.speedup = speedup
        self.keys = KeySpace(scenario.site.id)
        self.uavs = [u.id for u in scenario.fleet.uavs]
        self.ground = net.hosts["ground"].address
        self.endpoint = f"tcp/{self.ground}:{ROUTER_PORT}"
        self.url = f"http://{self.ground}:{GATEWAY_PORT}"
        self.sup = NetnsSupervisor(run_dir)
        self.bus: Bus | None = None
        self._commands: dict[str, tuple[str, list[str], str]] = {}
        run_dir.mkdir(parents=True, exist_ok=True)
        self.scenario_file = run_dir / "scenario.json"
        self.scenario_file.write_bytes(msgspec.json.encode(scenario))

    # -- lifecycle ------------------------------------------------------------------

    def start(self) -> None:
        """Router, ground station, simulator, gateway, agents; each checked healthy."""
        common = ["--connect", self.endpoint, "--lease-ms", "500", "--speedup", str(self.speedup)]
        scenario = ["--scenario", str(self.scenario_file)]
        sim = self.net.hosts["sim"].address
        self._define("router", "ground", "ground_station.router")
        self._commands["router"] = (
            "ground",
            ["--listen", self.endpoint, "--site", self.keys.site, "--lease-ms", "500"],
            "ground_station.router",
        )
        self._define(
            "ground-station",
            "ground",
            "ground_station",
            *common,
            *scenario,
            "--db",
            str(self.run_dir / "gs.db"),
        )
        self._define(
            "sim",
            "sim",
            "sim_fleet",
            *common,
            *scenario,
            "--host",
            sim,
            "--base-port",
            str(MAVLINK_BASE_PORT),
        )
        self._define(
            "gateway",
            "ground",
            "ground_station.gateway",
            *common,
            *scenario,
            "--host",
            "0.0.0.0",
            "--port",
            str(GATEWAY_PORT),
            "--token",
            TOKEN,
        )
        for index, uav in enumerate(self.uavs):
            self._define(
                f"agent-{uav}",
                uav,
                "onboard_agent",
                *common,
                *scenario,
                "--uav",
                uav,
                "--autopilot",
                f"udpout:{sim}:{MAVLINK_BASE_PORT + index}",
            )
        self.launch("router")
        self.bus = Bus.open(BusConfig(connect=(self.endpoint,), lease_ms=500))
        for name in ["ground-station", "sim", "gateway", *[f"agent-{u}" for u in self.uavs]]:
            self.launch(name)

    def close(self) -> None:
        """Leave the bus, stop every process."""
        if self.bus is not None:
            self.bus.close()
            self.bus = None
        self.sup.stop_all()

    def _define(self, name: str, host: str, module: str, *args: str) -> None:
        self._commands[name] = (host, list(args), module)

    # -- processes ---------------------------------------------------------------------

    def launch(self, name: str) -> Child:
        """Start (or restart) ``name`` and wait until it is healthy."""
        host, args, module = self._commands[name]
        child = self.sup.start_in(self.net.exec_prefix(host), name, module, *args)
        self.sup.wait_ready(child, lambda: self.healthy(name), START_TIMEOUT_S)
        return child

    def kill(self, name: str) -> None:
        """``kill -9`` the newest process called ``name`` and reap it."""
        child = next(c for c in reversed(self.sup.children) if c.name == name)
        child.popen.kill()
        child.popen.wait()

    def healthy(self, name: str) -> bool:
        """The process's own health signal: the router accepts TCP, the gateway
        answers /healthz, the others hold their liveliness token."""
        if name == "router":
            with socket.socket() as sock:
                sock.settimeout(0.3)
                return sock.connect_ex((self.ground, ROUTER_PORT)) == 0
        if name == "gateway":
            try:
                return httpx.get(f"{self.url}/healthz", timeout=1.0).status_code == 200
            except httpx.HTTPError:
                return False
        role, ident = {
            "ground-station": (Role.GROUND_STATION, "gs"),
            "sim": (Role.SIM, "sim"),
        }.get(name, (Role.AGENT, name.removeprefix("agent-")))
        return self.alive(role, ident)

    def alive(self, role: Role, ident: str) -> bool:
        """Whether the liveliness token of ``role/ident`` is present."""
        assert self.bus is not None
        key = self.keys.alive(role, ident)
        try:
            return key in self.bus.alive(key, timeout_s=0.5)
        except Exception:  # the router may be down: not alive
            return False

    def gateway(self) -> httpx.Client:
        """An authenticated REST client."""
        return httpx.Client(
            base_url=self.url, headers={"Authorization": f"Bearer {TOKEN}"}, timeout=4.0
        )
