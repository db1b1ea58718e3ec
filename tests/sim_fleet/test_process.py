"""The ``linecrew sim`` process over a real router: worker poses (scripted
motion too), fault injection and ground truth over Zenoh, MAVLink endpoints
on predictable ports, clean shutdown."""

from __future__ import annotations

import os
import sys

import msgspec
import pytest

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil

from linecrew_runtime.bus import Bus
from linecrew_runtime.scenarios import load
from proto import (
    BatteryFault,
    FaultApplied,
    GetSimState,
    HumanPose,
    KeySpace,
    Point,
    RequestError,
    Role,
    SimState,
)
from proto.site import TimedPoint
from tests.support.processes import free_port, running, wait_until

PAPER = load("paper")
KEYS = KeySpace(PAPER.site.id)


def climbing_scenario(tmp_path) -> str:
    """The paper's world where W1 climbs T2 during the first 20 simulated seconds."""
    workers = list(PAPER.site.workers)
    climb = [TimedPoint(at_s=20.0, position=Point(x_m=0, y_m=5, z_m=15))]
    workers[0] = msgspec.structs.replace(workers[0], path=climb)
    site = msgspec.structs.replace(PAPER.site, workers=workers)
    path = tmp_path / "climb.json"
    path.write_bytes(msgspec.json.encode(msgspec.structs.replace(PAPER, site=site)))
    return str(path)


@pytest.fixture
def sim(router, bus_config, tmp_path):
    base_port = free_port()
    args = [
        sys.executable,
        "-m",
        "sim_fleet",
        "--connect",
        router,
        "--scenario",
        climbing_scenario(tmp_path),
        "--speedup",
        "5",
        "--base-port",
        str(base_port),
    ]
    with Bus.open(bus_config) as client:
        token = KEYS.alive(Role.SIM, "sim")
        with running(args, "sim", lambda: token in client.alive(token)) as proc:
            yield proc, client, base_port


def test_worker_poses_are_published_and_scripted_workers_move(sim):
    _, client, _ = sim
    poses: dict[str, list[HumanPose]] = {}
    client.subscribe(
        KEYS.all_human_poses(), HumanPose, lambda _k, p: poses.setdefault(p.worker_id, []).append(p)
    )
    wait_until(lambda: set(poses) == {"W1", "W2", "W3"}, 10, "poses of every worker")
    wait_until(lambda: poses["W1"][-1].position.z_m > 10, 20, "W1 climbing the tower")
    assert poses["W2"][-1].position == PAPER.site.worker("W2").position
    assert abs(poses["W1"][-1].geo.lat_deg - PAPER.site.origin.lat_deg) < 0.01


def test_faults_apply_and_show_in_the_ground_truth(sim):
    _, client, _ = sim
    reply = client.query(
        KEYS.sim("fault"), BatteryFault(uav_id="uav-2", fraction=0.3), FaultApplied, 5.0
    )
    assert reply.target == "uav-2" and "30%" in reply.detail
    state = client.query(KEYS.sim("state"), GetSimState(), SimState, 5.0)
    uav2 = next(v for v in state.vehicles if v.uav_id == "uav-2")
    assert uav2.battery_fraction == pytest.approx(0.3, abs=0.01)
    assert state.speedup == 5.0 and state.deliveries == []


def test_bad_faults_get_clear_errors_and_the_sim_keeps_serving(sim):
    proc, client, _ = sim
    with pytest.raises(RequestError) as caught:
        client.query(
            KEYS.sim("fault"), BatteryFault(uav_id="uav-9", fraction=0.3), FaultApplied, 5.0
        )
    assert caught.value.code == "not_found" and "uav-1" in str(caught.value)
    replies = list(client.session.get(KEYS.sim("fault"), payload=b"\xc1", timeout=5.0))
    assert replies[0].err is not None
    assert client.query(KEYS.sim("state"), GetSimState(), SimState, 5.0).vehicles
    assert proc.popen.poll() is None


def test_each_vehicle_speaks_mavlink_on_base_port_plus_index(sim):
    _, _, base_port = sim
    for index in range(len(PAPER.fleet.uavs)):
        link = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{base_port + index}", source_system=255
        )
        try:
            heartbeat = None
            for _ in range(20):
                link.mav.heartbeat_send(6, 8, 0, 0, 0)
                heartbeat = link.recv_match(type="HEARTBEAT", blocking=True, timeout=0.5)
                if heartbeat:
                    break
            assert heartbeat is not None and link.target_system == index + 1
        finally:
            link.close()


def test_sigterm_stops_the_simulator_cleanly(sim):
    proc, _, _ = sim
    assert proc.stop() == 0
    assert "simulator stopped on SIGTERM" in proc.output()


def test_fault_cli_acknowledges_and_reports_errors(sim, router):
    import subprocess

    base = [sys.executable, "-m", "sim_fleet", "fault", "--connect", router]
    ok = subprocess.run(
        [*base, "battery", "uav-3", "0.5"], capture_output=True, text=True, timeout=60
    )
    assert ok.returncode == 0 and "uav-3: battery set to 50%" in ok.stdout
    bad = subprocess.run([*base, "kill", "uav-7"], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 1 and "not_found" in bad.stderr
    invalid = subprocess.run(
        [*base, "battery", "uav-3", "2"], capture_output=True, text=True, timeout=60
    )
    assert invalid.returncode == 2 and "fraction" in invalid.stderr
