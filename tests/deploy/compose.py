"""Drive the repository's docker-compose.yml from tests: build the image,
bring a uniquely named project up and down, cut and restore containers'
links, kill and restart them, and talk to the published gateway."""

from __future__ import annotations

import json
import os
import pathlib
import secrets
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

import httpx

ROOT = pathlib.Path(__file__).resolve().parents[2]
COMPOSE_FILE = ROOT / "docker-compose.yml"
IMAGE = "linecrew:dev"
AGENTS = ("uav-1", "uav-2", "uav-3")


def run(args: list[str], timeout_s: float = 120.0, **kwargs: Any) -> subprocess.CompletedProcess:
    """Run a command, capture its output, raise with that output if it fails."""
    done = subprocess.run(
        args, capture_output=True, text=True, timeout=timeout_s, check=False, **kwargs
    )
    if done.returncode != 0:
        raise AssertionError(
            f"{' '.join(args)} exited {done.returncode}\n{done.stdout}\n{done.stderr}"
        )
    return done


def docker_unavailable() -> str:
    """Why Docker cannot be used here, or "" if a daemon answers."""
    if shutil.which("docker") is None:
        return "no docker command"
    try:
        done = subprocess.run(
            ["docker", "info", "--format", "{{.ServerVersion}}"],
            capture_output=True,
            text=True,
            timeout=30,
            check=False,
        )
    except subprocess.TimeoutExpired:
        return "the Docker daemon does not answer"
    if done.returncode != 0:
        return f"no Docker daemon reachable: {done.stderr.strip()}"
    return ""


def compose_command() -> list[str]:
    """``docker compose`` if the v2 plugin is there, else ``docker-compose``."""
    plugin = subprocess.run(
        ["docker", "compose", "version"], capture_output=True, timeout=30, check=False
    )
    if plugin.returncode == 0:
        return ["docker", "compose"]
    if shutil.which("docker-compose"):
        return ["docker-compose"]
    raise AssertionError("neither `docker compose` nor `docker-compose` is installed")


def build_image() -> float:
    """Build the base image (if missing) and linecrew:dev; the wall seconds taken."""
    started = time.monotonic()
    env = dict(os.environ, PYTHON=sys.executable, LINECREW_IMAGE=IMAGE)
    run(["bash", str(ROOT / "deploy" / "build-image.sh")], timeout_s=1200, env=env, cwd=ROOT)
    return time.monotonic() - started


def poll(predicate: Callable[[], Any], timeout_s: float, what: str, period_s: float = 0.5) -> Any:
    """Call ``predicate`` every ``period_s`` until it returns something
    truthy (returned); fail after ``timeout_s``. Gateway errors count as no."""
    deadline = time.monotonic() + timeout_s
    last_error: Exception | None = None
    while True:
        try:
            value = predicate()
        except (httpx.HTTPError, GatewayDown) as exc:
            value, last_error = None, exc
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout_s} s waiting for {what} ({last_error})")
        time.sleep(period_s)


class GatewayDown(Exception):
    """The gateway answered 5xx (the ground station is not reachable)."""


class Stack:
    """One compose project of the repository's docker-compose.yml."""

    def __init__(self, compose: list[str], speedup: float) -> None:
        self.project = f"linecrew-test-{os.getpid()}-{secrets.token_hex(3)}"
        self.compose = compose
        self.speedup = speedup
        self.token = secrets.token_hex(16)
        # Nothing of the developer's LINECREW_* settings leaks into the stack.
        env = {k: v for k, v in os.environ.items() if not k.startswith("LINECREW_")}
        env.update(
            LINECREW_IMAGE=IMAGE,
            LINECREW_TOKEN=self.token,
            LINECREW_SPEEDUP=str(speedup),
            LINECREW_GATEWAY_PORT="",  # an ephemeral host port: no clash with others
            LINECREW_HEALTH_INTERVAL="3s",
        )
        self.env = env
        self.url = ""
        self.http: httpx.Client | None = None
        self._containers: dict[str, str] = {}

    # -- compose -------------------------------------------------------------

    def compose_run(self, *args: str, timeout_s: float = 180.0) -> str:
        """``docker compose -p PROJECT -f docker-compose.yml ARGS``; its stdout."""
        cmd = [*self.compose, "-p", self.project, "-f", str(COMPOSE_FILE), *args]
        return run(cmd, timeout_s=timeout_s, env=self.env, cwd=ROOT).stdout

    def up(self) -> None:
        """Start every service (returns once the gateway is healthy: the
        agents depend on it) and open the HTTP client."""
        self.compose_run("up", "-d", timeout_s=300)
        host_port = self.compose_run("port", "gateway", "8080").strip().splitlines()[-1]
        self.url = f"http://{host_port}"
        self.http = httpx.Client(
            base_url=self.url, timeout=10.0, headers={"Authorization": f"Bearer {self.token}"}
        )

    def down(self) -> None:
        """Remove containers, networks and the volume of this project."""
        if self.http is not None:
            self.http.close()
        self.compose_run("down", "-v", "--remove-orphans", "-t", "5", timeout_s=300)

    def logs(self, tail: int = 200) -> str:
        """The last lines of every service's output."""
        try:
            return self.compose_run("logs", "--no-color", "--tail", str(tail), timeout_s=60)
        except (AssertionError, subprocess.TimeoutExpired) as exc:
            return f"(no logs: {exc})"

    def container(self, service: str) -> str:
        """The id of ``service``'s container (asked once: compose is slow to start)."""
        if service not in self._containers:
            self._containers[service] = self.compose_run("ps", "-q", service).strip()
        return self._containers[service]

    @property
    def bus_network(self) -> str:
        return f"{self.project}_bus"

    def disconnect(self, service: str) -> None:
        """Cut ``service`` off the Zenoh network (its MAVLink link stays)."""
        run(["docker", "network", "disconnect", self.bus_network, self.container(service)])

    def connect(self, service: str) -> None:
        """Put ``service`` back on the Zenoh network."""
        cid = self.container(service)
        run(["docker", "network", "connect", "--alias", service, self.bus_network, cid])

    def crash(self, service: str) -> None:
        """SIGKILL the main process of ``service``'s container from the host: a
        crash, not an operator's stop (``docker kill`` would be one, and
        restart policies leave stopped containers alone)."""
        pid = self._inspect(service, "{{.State.Pid}}")
        assert pid.isdigit() and int(pid) > 0, f"{service} is not running ({pid})"
        os.kill(int(pid), signal.SIGKILL)

    def restarts(self, service: str) -> int:
        """How often Docker's restart policy has restarted ``service``."""
        return int(self._inspect(service, "{{.RestartCount}}"))

    def running(self, service: str) -> bool:
        return self._inspect(service, "{{.State.Running}}") == "true"

    def _inspect(self, service: str, template: str) -> str:
        return run(["docker", "inspect", "-f", template, self.container(service)]).stdout.strip()

    # -- gateway ---------------------------------------------------------------

    def call(self, method: str, path: str, **kwargs: Any) -> Any:
        """A REST call; the JSON answer. 5xx raises :class:`GatewayDown`."""
        assert self.http is not None
        response = self.http.request(method, path, **kwargs)
        if response.status_code >= 500:
            raise GatewayDown(f"{method} {path}: {response.status_code} {response.text}")
        assert response.status_code < 400, (method, path, response.status_code, response.text)
        return response.json()

    def healthz(self) -> dict[str, Any]:
        """``GET /healthz``."""
        assert self.http is not None
        return self.http.get("/healthz").json()

    def fleet(self) -> dict[str, dict[str, Any]]:
        """UAV id -> its state record."""
        return {u["uav_id"]: u for u in self.call("GET", "/v1/fleet")}

    def present(self) -> bool:
        """Ground station up and every agent seen (none lost)."""
        return all(u["state"] != "lost" for u in self.fleet().values())

    def actions(self) -> dict[str, dict[str, Any]]:
        """Action id -> its record."""
        return {r["action_id"]: r for r in self.call("GET", "/v1/actions")}

    def assignees(self, action_id: str) -> set[str]:
        """UAVs whose current plan holds a task of ``action_id``."""
        return {
            plan["uav_id"]
            for plan in self.call("GET", "/v1/plan")
            for task in plan["tasks"]
            if task.get("action_id") == action_id
        }

    def events(self, after_seq: int = 0) -> list[dict[str, Any]]:
        """Stored ground-station events after ``after_seq``, from the
        ``/v1/events`` stream's replay (it ends the replay with ``: connected``)."""
        assert self.http is not None
        events: list[dict[str, Any]] = []
        while True:
            page: list[dict[str, Any]] = []
            with self.http.stream(
                "GET", "/v1/events", params={"after_seq": after_seq}, timeout=30.0
            ) as stream:
                assert stream.status_code == 200, stream.status_code
                for line in stream.iter_lines():
                    if line.startswith("data: "):
                        page.append(json.loads(line[6:]))
                    elif line.startswith(": connected"):
                        break
            events += page
            if len(page) < 1000:
                return events
            after_seq = page[-1]["seq"]

    def last_seq(self) -> int:
        """The newest event's sequence number (0 if none)."""
        events = self.events(0)
        return events[-1]["seq"] if events else 0
