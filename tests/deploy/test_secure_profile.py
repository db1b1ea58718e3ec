"""The secured Zenoh profile (deploy/tls/gen-dev-ca.sh, deploy/zenoh/secure/):
a real router process with mutual TLS and access control, clients with the
generated certificates. Certificates are generated into a temporary
directory with the script itself.

"Not delivered" is asserted deterministically: the forbidden message is sent
over and over while an allowed control message on the same session and the
same subscriber gets through several times; only then do we check that the
forbidden one never arrived (Zenoh keeps per-session order on one link)."""

from __future__ import annotations

import asyncio
import importlib.util
import json
import os
import pathlib
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import pytest

from linecrew_runtime import health
from linecrew_runtime.bus import Bus, BusConfig
from proto.errors import RequestTimeout, Unavailable
from proto.geo import GeoPoint, Point
from proto.keys import KeySpace, Role, UavTopic
from proto.plan import Plan
from proto.rpc import (
    FleetReply,
    GetFleet,
    GetMetrics,
    GetPlans,
    MetricsReply,
    PlansReply,
    UavOpState,
)
from proto.telemetry import AgentState, AgentStatus, HumanPose, OutcomeResult, TaskOutcome
from tests.support.processes import free_port, port_open, running, running_alive, wait_until

ROOT = pathlib.Path(__file__).resolve().parents[2]
GEN = ROOT / "deploy" / "tls" / "gen-dev-ca.sh"
SECURE = ROOT / "deploy" / "zenoh" / "secure"
KEYS = KeySpace()
ROUTER_TOKEN = KEYS.alive(Role.ROUTER, "router")

pytestmark = pytest.mark.skipif(shutil.which("openssl") is None, reason="openssl not installed")


def generate(out: pathlib.Path, uavs: int) -> None:
    subprocess.run(
        ["sh", str(GEN), str(uavs), str(out)],
        check=True,
        capture_output=True,
        env={**os.environ, "PYTHON": sys.executable},
    )


@pytest.fixture(scope="module")
def pki(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    """The dev CA, certificates and rendered configs for uav-1 and uav-2."""
    out = tmp_path_factory.mktemp("tls")
    generate(out, 2)
    return out


@pytest.fixture(scope="module")
def foreign_pki(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    """Certificates with the same names, signed by another CA."""
    out = tmp_path_factory.mktemp("foreign-tls")
    generate(out, 1)
    return out


@pytest.fixture(scope="module")
def endpoint(pki: pathlib.Path) -> Iterator[str]:
    """A secured router on a free port (TLS only, access control on)."""
    port = free_port()
    args = [
        sys.executable,
        "-m",
        "linecrew_runtime.bus.router",
        "--listen",
        f"tls/127.0.0.1:{port}",
        "--zenoh-config",
        str(pki / "zenoh" / "router.json5"),
        "--log-level",
        "warning",
    ]
    with running(args, "secure-router", lambda: port_open(port)):
        yield f"tls/localhost:{port}"


def config(endpoint: str, file: pathlib.Path) -> BusConfig:
    return BusConfig(connect=(endpoint,), config_file=str(file))


def client_config(path: pathlib.Path, **tls: object) -> pathlib.Path:
    """A client config file with these ``transport/link/tls`` settings."""
    values = {
        key: str(value) if isinstance(value, pathlib.Path) else value for key, value in tls.items()
    }
    link = {"protocols": ["tls"], "tls": values}
    path.write_text(json.dumps({"transport": {"link": link}}))
    return path


def open_as(pki: pathlib.Path, endpoint: str, identity: str) -> Bus:
    return Bus.open(config(endpoint, pki / "zenoh" / f"client-{identity}.json5"), wait_s=10)


def status(uav_id: str, epoch: int = 0) -> AgentStatus:
    return AgentStatus(uav_id=uav_id, stamp_s=time.time(), state=AgentState.IDLE, epoch=epoch)


class Inbox:
    """Thread-safe record of (key, message) received by a callback."""

    def __init__(self) -> None:
        self.items: list[tuple[str, object]] = []
        self._lock = threading.Lock()

    def __call__(self, key: str, message: object) -> None:
        with self._lock:
            self.items.append((key, message))

    def received_keys(self) -> list[str]:
        with self._lock:
            return [key for key, _ in self.items]

    def count(self, key: str) -> int:
        return self.received_keys().count(key)


def keep_sending(send_allowed, send_forbidden, received, enough: int = 5) -> None:
    """Send both until the allowed message has been received ``enough`` times."""
    deadline = time.monotonic() + 15
    while received() < enough:
        assert time.monotonic() < deadline, "the allowed message was never delivered"
        send_forbidden()
        send_allowed()
        time.sleep(0.02)
    send_forbidden()  # the last word is the forbidden one, then a last allowed one behind it
    before = received()
    send_allowed()
    wait_until(lambda: received() > before, 5, "the final control message")


# -- joining -------------------------------------------------------------------------------------


def test_valid_certificate_joins_and_publishes_within_its_rights(pki, endpoint):
    with open_as(pki, endpoint, "gs") as gs, open_as(pki, endpoint, "uav-1") as uav:
        inbox = Inbox()
        gs.subscribe(KEYS.all_uavs("status"), AgentStatus, inbox)
        own = KEYS.status("uav-1")
        deadline = time.monotonic() + 10
        while inbox.count(own) < 3:
            assert time.monotonic() < deadline, "uav-1's status never reached the ground station"
            uav.publish(own, status("uav-1"))
            time.sleep(0.05)
        assert set(inbox.received_keys()) == {own}


def test_client_without_certificate_cannot_join(pki, endpoint, tmp_path):
    # trusts the router's CA, but presents no client certificate: mTLS refuses it
    anonymous = client_config(tmp_path / "anonymous.json5", root_ca_certificate=pki / "ca.pem")
    with pytest.raises(Unavailable):
        Bus.open(config(endpoint, anonymous), wait_s=2)


def test_plain_tcp_client_cannot_join_the_tls_port(endpoint):
    port = endpoint.rsplit(":", 1)[1]
    with pytest.raises(Unavailable):
        Bus.open(BusConfig(connect=(f"tcp/127.0.0.1:{port}",)), wait_s=2)


def test_certificate_from_another_ca_cannot_join(pki, foreign_pki, endpoint, tmp_path):
    # a well-formed uav-1 certificate, but not signed by the router's CA; the
    # client itself trusts the real CA, so only the router's check can refuse it
    impostor = client_config(
        tmp_path / "impostor.json5",
        root_ca_certificate=pki / "ca.pem",
        connect_certificate=foreign_pki / "uav-1.pem",
        connect_private_key=foreign_pki / "uav-1.key",
        enable_mtls=True,
    )
    with pytest.raises(Unavailable):
        Bus.open(config(endpoint, impostor), wait_s=2)
    # and the router still serves its own
    with open_as(pki, endpoint, "uav-1") as uav:
        assert uav.session.info.routers_zid()


def test_client_refuses_a_router_outside_its_ca(pki, foreign_pki, endpoint, tmp_path):
    # the other way round: a client of the foreign CA does not trust our router
    stranger = foreign_pki / "zenoh" / "client-uav-1.json5"
    with pytest.raises(Unavailable):
        Bus.open(config(endpoint, stranger), wait_s=2)


# -- access control ------------------------------------------------------------------------------


def test_agent_cannot_publish_as_another_uav(pki, endpoint):
    with open_as(pki, endpoint, "gs") as gs, open_as(pki, endpoint, "uav-1") as uav:
        inbox = Inbox()
        gs.subscribe(KEYS.all_uavs("status"), AgentStatus, inbox)
        gs.subscribe(KEYS.all_uavs("telemetry"), AgentStatus, inbox)
        gs.subscribe(KEYS.all_uavs("outcome"), AgentStatus, inbox)
        own, other = KEYS.status("uav-1"), KEYS.status("uav-2")

        def forbidden() -> None:
            uav.publish(other, status("uav-2"))
            uav.publish(KEYS.telemetry("uav-2"), status("uav-2"))
            uav.publish(KEYS.outcome("uav-2"), status("uav-2"))

        keep_sending(lambda: uav.publish(own, status("uav-1")), forbidden, lambda: inbox.count(own))
        assert not [key for key in inbox.received_keys() if "uav-2" in key]


def test_agent_cannot_declare_another_uavs_liveliness_token(pki, endpoint):
    with open_as(pki, endpoint, "operator") as operator, open_as(pki, endpoint, "uav-1") as uav:
        seen: list[tuple[str, bool]] = []
        operator.watch_liveliness(f"{KEYS.prefix}/alive/**", lambda k, a: seen.append((k, a)))
        # one session, one link: the router handles these in order, so once the
        # last one is seen the first two have been judged
        uav.declare_token(KEYS.alive(Role.AGENT, "uav-2"))
        uav.declare_token(KEYS.alive(Role.GROUND_STATION, "gs"))  # nor pose as the ground station
        uav.declare_token(KEYS.alive(Role.AGENT, "uav-1"))
        mine = KEYS.alive(Role.AGENT, "uav-1")
        wait_until(lambda: (mine, True) in seen, 10, "uav-1's own token")
        assert [item for item in seen if "/router/" not in item[0]] == [(mine, True)]
        # a liveliness query can miss a token just declared: ask until it shows
        wait_until(lambda: operator.alive(f"{KEYS.prefix}/alive/**") == {mine, ROUTER_TOKEN}, 5)


def test_agent_reads_its_own_plan_but_not_another_uavs(pki, endpoint):
    with open_as(pki, endpoint, "gs") as gs, open_as(pki, endpoint, "uav-1") as uav:
        inbox = Inbox()
        uav.subscribe(KEYS.plan("uav-1"), Plan, inbox)
        uav.subscribe(KEYS.plan("uav-2"), Plan, inbox)  # refused by the router
        uav.subscribe(KEYS.all_uavs("plan"), Plan, inbox)  # refused too: broader than its own
        own, other = KEYS.plan("uav-1"), KEYS.plan("uav-2")
        # the ground station's publisher learns of uav-1's subscription asynchronously
        keep_sending(
            lambda: gs.publish(own, Plan(uav_id="uav-1", epoch=1)),
            lambda: gs.publish(other, Plan(uav_id="uav-2", epoch=1)),
            lambda: inbox.count(own),
        )
        assert set(inbox.received_keys()) == {own}
        assert all(message.uav_id == "uav-1" for _, message in inbox.items)


def test_plan_resync_query_and_ground_station_token_under_acl(pki, endpoint):
    """What an agent does when a ground station appears (onboard_agent/comms.py):
    it sees the token, then queries its own plan; another UAV's plan stays out
    of reach."""

    async def scenario(gs: Bus, uav: Bus) -> None:
        plans = {u: Plan(uav_id=u, epoch=7) for u in ("uav-1", "uav-2")}

        def answer(request: GetPlans) -> PlansReply:
            plan = plans.get(request.uav_id or "")
            return PlansReply(plans=[plan] if plan else [])

        # declared in this order on one link: once the token reaches uav-1, the router
        # knows both queryables, so a query that gets nothing was refused
        gs.serve(KEYS.rpc("plans"), GetPlans, lambda _r: PlansReply(plans=list(plans.values())))
        gs.serve(KEYS.all_uavs("plan"), GetPlans, answer)
        gs_token = KEYS.alive(Role.GROUND_STATION, "gs")
        async with uav.watch_liveliness_async(KEYS.all_alive(Role.GROUND_STATION)) as tokens:
            gs.declare_token(gs_token)
            assert await asyncio.wait_for(tokens.get(), 10) == (gs_token, True)
        # an agent that starts later gets the token from the watcher's history
        async with uav.watch_liveliness_async(KEYS.all_alive(Role.GROUND_STATION)) as again:
            assert await asyncio.wait_for(again.get(), 10) == (gs_token, True)

        request = GetPlans(uav_id="uav-1")
        reply = await uav.query_async(KEYS.plan("uav-1"), request, PlansReply, 5.0)
        assert reply.plans == [plans["uav-1"]]
        with pytest.raises(RequestTimeout):
            await uav.query_async(KEYS.plan("uav-2"), GetPlans(uav_id="uav-2"), PlansReply, 1.0)
        # the query API of the ground station is not for agents either
        with pytest.raises(RequestTimeout):
            await uav.query_async(KEYS.rpc("plans"), request, PlansReply, 1.0)

    with open_as(pki, endpoint, "gs") as gs, open_as(pki, endpoint, "uav-1") as uav:
        asyncio.run(scenario(gs, uav))


def test_a_ground_station_drops_what_uav_2_says_about_uav_1_on_its_own_keys(
    pki, endpoint, tmp_path
):
    """The ACL lets uav-2 publish on its own keys only; what it says there
    about uav-1 (an emergency, a completed task) the real ground station
    drops and counts, and uav-1's state does not change."""
    args = [
        sys.executable,
        "-m",
        "ground_station",
        "--connect",
        endpoint,
        "--zenoh-config",
        str(pki / "zenoh" / "client-gs.json5"),
        "--db",
        str(tmp_path / "gs.db"),
    ]
    operator_config = config(endpoint, pki / "zenoh" / "client-operator.json5")
    token = KEYS.alive(Role.GROUND_STATION, "gs")
    outcome = TaskOutcome(uav_id="uav-1", task_id="t1", epoch=1, result=OutcomeResult.COMPLETED)
    emergency = AgentStatus(uav_id="uav-1", stamp_s=time.time(), state=AgentState.EMERGENCY)
    with (
        running_alive(args, "secure-gs", operator_config, token),
        open_as(pki, endpoint, "uav-2") as uav2,
        open_as(pki, endpoint, "operator") as operator,
    ):

        def dropped() -> float:
            uav2.publish(KEYS.outcome("uav-2"), outcome)
            uav2.publish(KEYS.uav("uav-2", UavTopic.STATUS), emergency)
            metrics = operator.query(KEYS.rpc("metrics"), GetMetrics(), MetricsReply, 5.0)
            return metrics.values["bus_identity_mismatch"]

        wait_until(lambda: dropped() >= 2, 20, "the ground station counted uav-2's words")
        fleet = operator.query(KEYS.rpc("fleet"), GetFleet(), FleetReply, 5.0)
        uav1 = next(u for u in fleet.uavs if u.uav_id == "uav-1")
        assert uav1.status is None and uav1.state is not UavOpState.EMERGENCY


def test_gateway_reaches_the_ground_station_but_cannot_write_the_fleet(pki, endpoint):
    async def scenario(gs: Bus, gateway: Bus, uav: Bus) -> None:
        gs.serve(KEYS.rpc("plans"), GetPlans, lambda _r: PlansReply(plans=[]))
        gs_token = KEYS.alive(Role.GROUND_STATION, "gs")
        gs.declare_token(gs_token)
        await asyncio.to_thread(
            wait_until, lambda: gateway.alive(KEYS.all_alive(Role.GROUND_STATION)) == {gs_token}
        )
        # the queryable was declared before the token: the router knows it now
        reply = await gateway.query_async(KEYS.rpc("plans"), GetPlans(), PlansReply, 5.0)
        assert reply == PlansReply(plans=[])

        inbox = Inbox()
        uav.subscribe(KEYS.plan("uav-1"), Plan, inbox)
        own = KEYS.plan("uav-1")
        loop = asyncio.get_running_loop()
        await loop.run_in_executor(
            None,
            lambda: keep_sending(
                lambda: gs.publish(own, Plan(uav_id="uav-1", epoch=1)),
                lambda: gateway.publish(own, Plan(uav_id="uav-1", epoch=666)),
                lambda: inbox.count(own),
            ),
        )
        assert {message.epoch for _, message in inbox.items} == {1}

    with (
        open_as(pki, endpoint, "gs") as gs,
        open_as(pki, endpoint, "gateway") as gateway,
        open_as(pki, endpoint, "uav-1") as uav,
    ):
        asyncio.run(scenario(gs, gateway, uav))


def test_the_gateway_reads_the_workers_poses_and_the_operator_the_uavs_reports(pki, endpoint):
    """What the console's map and the run's flight log need, under the ACL."""
    with (
        open_as(pki, endpoint, "sim") as sim,
        open_as(pki, endpoint, "uav-1") as uav,
        open_as(pki, endpoint, "gateway") as gateway,
        open_as(pki, endpoint, "operator") as operator,
    ):
        poses, reports = Inbox(), Inbox()
        gateway.subscribe(KEYS.all_human_poses(), HumanPose, poses)
        operator.subscribe(KEYS.all_uavs("status"), AgentStatus, reports)
        pose_key, status_key = KEYS.human_pose("W1"), KEYS.status("uav-1")
        pose = HumanPose(
            worker_id="W1", stamp_s=1.0, position=Point(x_m=1.0, y_m=2.0), geo=GeoPoint()
        )
        deadline = time.monotonic() + 10
        while poses.count(pose_key) < 3 or reports.count(status_key) < 3:
            assert time.monotonic() < deadline, (poses.count(pose_key), reports.count(status_key))
            sim.publish(pose_key, pose)
            uav.publish(status_key, status("uav-1"))
            time.sleep(0.05)


# -- the files -----------------------------------------------------------------------------------


def test_generation_is_idempotent_and_extends_the_fleet(tmp_path):
    generate(tmp_path, 1)
    first = {p.name: p.read_bytes() for p in tmp_path.glob("*.pem")}
    generate(tmp_path, 2)
    again = {p.name: p.read_bytes() for p in tmp_path.glob("*.pem")}
    assert {name: again[name] for name in first} == first
    assert set(again) - set(first) == {"uav-2.pem"}
    verify = subprocess.run(
        ["openssl", "verify", "-CAfile", str(tmp_path / "ca.pem"), str(tmp_path / "uav-2.pem")],
        capture_output=True,
        text=True,
    )
    assert verify.returncode == 0, verify.stdout + verify.stderr
    subject = subprocess.run(
        ["openssl", "x509", "-noout", "-subject", "-in", str(tmp_path / "uav-2.pem")],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert "CN = uav-2" in subject or "CN=uav-2" in subject
    assert (tmp_path / "zenoh" / "client-uav-2.json5").exists()


def test_committed_configs_are_the_rendered_ones():
    spec = importlib.util.spec_from_file_location("secure_render", SECURE / "render.py")
    assert spec and spec.loader
    render = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(render)
    uavs = ["uav-1", "uav-2", "uav-3"]
    expected = render.render("deploy/tls/out", uavs, "--tls-dir deploy/tls/out --uavs 3")
    committed = {p.name: p.read_text() for p in SECURE.glob("*.json5")}
    assert committed == expected, "run: python3 deploy/zenoh/secure/render.py " + (
        "--tls-dir deploy/tls/out --uavs 3 --out deploy/zenoh/secure"
    )


@pytest.mark.parametrize(("identity", "role"), [("uav-1", "agent"), ("gs", "gs"), ("sim", "sim")])
def test_healthcheck_runs_with_the_processs_own_identity(pki, endpoint, identity, role):
    """``linecrew health ROLE ID`` as the compose healthchecks run it: same
    identity (LINECREW_ZENOH_CONFIG) as the process it checks."""
    conf = [
        "--connect",
        endpoint,
        "--zenoh-config",
        str(pki / "zenoh" / f"client-{identity}.json5"),
    ]
    with open_as(pki, endpoint, identity) as process:
        process.declare_token(KEYS.alive(Role(role), identity))
        wait_until(lambda: health.main([role, identity, *conf]) == 0, 10, "healthy")
    if identity.startswith("uav-"):  # and only its own
        assert health.main([role, "uav-2", *conf]) == 1
