"""The runner: speed-up applied consistently, clean start/stop, port mapping."""

from __future__ import annotations

import socket

import pytest

from sim_fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.modes import Mode
from tests.sim_fleet.helpers import command
from tests.sim_fleet.small_world import small_world


def test_tick_advances_simulated_time_by_speedup():
    fleet = Fleet(small_world(1), FleetConfig(speedup=8.0))
    fleet.tick(0.25)
    assert fleet.world.time_s == pytest.approx(2.0)


def test_speedup_scales_motion_energy_and_charging_alike():
    """The same wall time at K=1 and K=10 differs only by K in every quantity."""
    results = []
    for k in (1.0, 10.0):
        fleet = Fleet(small_world(2), FleetConfig(speedup=k))
        w = fleet.world
        v = w.vehicle("uav1")
        command(w, v, 176, 1, Mode.GUIDED)
        command(w, v, 400, 1)
        command(w, v, 22, 0, 0, 0, 0, 0, 0, 30.0)
        w.vehicle("uav2").set_battery_soc(0.5)  # on charging pad C2
        for _ in range(int(2.0 * 20 / k)):  # 2 simulated-equivalent seconds x 20 Hz / K
            fleet.tick(1.0 / 20)
        results.append((w.time_s, v.position[2], v.battery.drawn_wh, w.vehicle("uav2").battery.soc))
    assert results[0] == pytest.approx(results[1], rel=1e-6)


def test_thread_runner_binds_consecutive_ports_and_stops_cleanly():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        base = s.getsockname()[1]
    # the port after a free one is very likely free too; retry once if not
    cfg = FleetConfig(base_port=base, speedup=1.0)
    try:
        runner = FleetThread(Fleet(small_world(3), cfg)).start()
    except OSError:
        pytest.skip("consecutive ports not free")
    ports = runner.fleet.ports
    runner.stop()
    assert ports == {"uav1": base, "uav2": base + 1, "uav3": base + 2}
    assert not runner._thread.is_alive()
    for port in ports.values():  # sockets are closed: the ports can be bound again
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.bind(("127.0.0.1", port))


def test_port_in_use_fails_start():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        taken = s.getsockname()[1]
        with pytest.raises(OSError):
            FleetThread(Fleet(small_world(1), FleetConfig(base_port=taken))).start()


def test_stop_before_start_is_harmless():
    Fleet(small_world(1)).stop()
