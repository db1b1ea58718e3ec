"""``linecrew up --secure``: the paper's scenario end to end with mutual TLS
and access control on the bus (dev certificates generated into the run
directory), a client without a certificate kept out, and MAVLink signed:
a stranger on a vehicle's port is not obeyed."""

from __future__ import annotations

import shutil

import httpx
import pytest

from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew.launch.secure import SecureProfileError, prepare
from linecrew_runtime.bus import Bus, BusConfig
from tests.e2e.test_paper_mission import PAPER, RESERVE, SPEEDUP, LandingWatch, fly
from tests.sim_fleet.mavclient import Client, mavlink

pytestmark = pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl")


def test_the_papers_scenario_completes_on_the_secured_bus(tmp_path):
    options = RunOptions(speedup=SPEEDUP, run_dir=tmp_path / "run", secure=True)
    with LocalRun(PAPER, options) as run:
        assert run.endpoint.startswith("tls/")
        plain = run.endpoint.replace("tls/localhost", "tcp/127.0.0.1")
        with pytest.raises(Exception):  # noqa: B017 - zenoh raises a bare ZError
            Bus.open(BusConfig(connect=(plain,), connect_attempt_ms=500))
        assert (run.run_dir / "tls" / "mavlink" / "uav-1.key").stat().st_mode & 0o077 == 0
        assert run.url.startswith("https://")  # REST over TLS, vouched for by the site CA
        with pytest.raises(httpx.HTTPError):  # a client that does not trust the site CA
            httpx.get(f"{run.url}/healthz", timeout=5.0)
        with pytest.raises(httpx.HTTPError):  # plain HTTP is not answered
            httpx.get(run.url.replace("https://", "http://") + "/healthz", timeout=5.0)
        assert len(run.gateway().call("GET", "/v1/fleet")) == len(PAPER.fleet.uavs)
        stranger = Client(run.mavlink_ports["uav-1"], 1, streams_hz=0)
        try:
            arm = mavlink.MAV_CMD_COMPONENT_ARM_DISARM
            stranger.conn.mav.command_long_send(1, 1, arm, 0, 1, 21196, 0, 0, 0, 0, 0)
            assert stranger.conn.recv_match(blocking=True, timeout=2.0) is None  # not a word
        finally:
            stranger.close()
        watch = LandingWatch(run)
        records, _ = fly(run, lambda _t, _r: watch.sample())
        assert {r["action_id"]: r["state"] for r in records} == {
            a.id: "completed" for a in PAPER.actions
        }, run.run_dir
        assert all(battery >= RESERVE - 0.02 for _, battery in watch.landings), watch.landings
        agents = run.bus.alive(f"{run.keys.prefix}/alive/agent/*", timeout_s=2.0)
        assert len(agents) == len(PAPER.fleet.uavs)


def test_the_profile_needs_uav_numbered_ids(tmp_path):
    with pytest.raises(SecureProfileError, match="uav-1"):
        prepare(tmp_path, ["uav-1", "drone-b"])
